//! The structured filter against the dense textbook form (eq. 17-21), for
//! the 33-state model and the 39-state one with sensor biases, and the
//! rejection paths of the measurement update.

use mwd_core::aid_sources::{ZeroPosition, ZeroVelocity};
use mwd_core::ar::ArModel;
use mwd_core::earth::{gravity_n, Position};
use mwd_core::error_model::{
    AugmentedModel, BiasState, Coupling, LinearizationPoint, ProcessNoise, POS, STATES,
    STATES_WITH_BIASES, VEL,
};
use mwd_core::kalman::{dense, KalmanFilter, ScalarOutcome, Transition};
use mwd_core::kalman::{Measurement, ScalarMeasurement, SparseRow};
use nalgebra::{Rotation3, SMatrix, SVector, Vector3};
use proptest::prelude::*;

/// A stationary AR(4) from reflection coefficients in (-1, 1), by the
/// step-up (Levinson) recursion: every such model is stationary.
fn ar_from_reflections(k: [f64; 4], variance: f64) -> ArModel<4> {
    let mut a = [0.0; 4];
    for m in 0..4 {
        let prev = a;
        for i in 0..m {
            a[i] = prev[i] + k[m] * prev[m - 1 - i];
        }
        a[m] = k[m];
    }
    ArModel::new(a, variance)
}

prop_compose! {
    fn arb_model()(
        ks in prop::array::uniform6(prop::array::uniform4(-0.9f64..0.9)),
        vars in prop::array::uniform6(1e-8f64..1e-2),
        bias_sigmas in prop::array::uniform6(1e-6f64..1e-1),
        bias_walks in prop::array::uniform6(0.0f64..1e-6),
        coupled in any::<bool>(),
    ) -> AugmentedModel {
        let mut m = AugmentedModel::paper();
        for axis in 0..3 {
            m.accel[axis] = ar_from_reflections(ks[axis], vars[axis]);
            m.gyro[axis] = ar_from_reflections(ks[axis + 3], vars[axis + 3]);
            let bias = |k: usize| BiasState { initial_sigma: bias_sigmas[k], variance_per_step: bias_walks[k], instability_sigma: 0.0, instability_density: 0.0 };
            m.biases.accel[axis] = bias(axis);
            m.biases.gyro[axis] = bias(axis + 3);
        }
        m.coupling = if coupled { Coupling::SensorErrorsDriveNavigation } else { Coupling::BlockDiagonalAsPublished };
        m
    }
}

prop_compose! {
    fn arb_point()(
        euler in prop::array::uniform3(-3.0f64..3.0),
        v in prop::array::uniform3(-5.0f64..5.0),
        lat in -1.2f64..1.2,
        height in -3000.0f64..3000.0,
    ) -> LinearizationPoint {
        let position = Position::new(lat, 0.3, height);
        let c_bn = Rotation3::from_euler_angles(euler[0], euler[1], euler[2]).into_inner();
        LinearizationPoint {
            c_bn,
            velocity_n: Vector3::from(v),
            position,
            specific_force_n: -gravity_n(&position) + Vector3::new(0.1, -0.2, 0.05),
        }
    }
}

/// A random covariance: L L^T + 1e-6 I with entries of mixed size.
fn arb_covariance<const N: usize>() -> impl Strategy<Value = SMatrix<f64, N, N>> {
    prop::collection::vec(-0.3f64..0.3, N * N).prop_map(|l| {
        let l = SMatrix::<f64, N, N>::from_column_slice(&l);
        l * l.transpose() + SMatrix::identity() * 1e-6
    })
}

fn rel_diff<const N: usize>(a: &SMatrix<f64, N, N>, b: &SMatrix<f64, N, N>) -> f64 {
    (a - b).amax() / b.amax().max(1e-300)
}

/// Inputs of one fast-vs-dense comparison.
struct Cycle {
    x0: [f64; 9],
    zv: [f64; 3],
    zp: [f64; 3],
    rv: f64,
    rp: f64,
    q: [f64; 9],
}

/// Two cycles (time update, ZUPT, zero-position update) of the structured
/// filter and of the dense textbook form from the same start: they must
/// agree to 1e-9 relative, with `N` = 33 or 39 states.
fn fast_matches_dense<const N: usize>(
    model: &AugmentedModel,
    lp: &LinearizationPoint,
    p0: SMatrix<f64, N, N>,
    c: &Cycle,
) -> Result<(), TestCaseError> {
    let phi = model.transition::<f64, N>(lp);
    let q_diag = model.process_noise::<f64, N>(&ProcessNoise { nav_per_step: c.q });
    let mut fast = KalmanFilter::<f64, N>::new(p0);
    fast.x.fixed_rows_mut::<9>(0).copy_from_slice(&c.x0);
    let mut x = fast.x;
    let mut p = p0;
    let mut h = SMatrix::<f64, 6, N>::zeros();
    for i in 0..3 {
        h[(i, VEL + i)] = 1.0;
        h[(3 + i, POS + i)] = 1.0;
    }
    let (zv, zp, rv, rp) = (c.zv, c.zp, c.rv, c.rp);
    let z = SVector::<f64, 6>::from_column_slice(&[zv[0], zv[1], zv[2], zp[0], zp[1], zp[2]]);
    let r =
        SMatrix::<f64, 6, 6>::from_diagonal(&SVector::from_column_slice(&[rv, rv, rv, rp, rp, rp]));
    for _ in 0..2 {
        fast.predict(&phi, &q_diag);
        let report_v = fast.update(&ZeroVelocity {
            velocity_n: zv,
            variance: rv,
        });
        let report_p = fast.update(&ZeroPosition {
            position_error_ned_m: zp,
            variance: rp,
        });
        prop_assert!(report_v.all_accepted() && report_p.all_accepted());
        dense::predict(
            &mut x,
            &mut p,
            &phi.to_dense(),
            &SMatrix::from_diagonal(&q_diag),
        );
        prop_assert!(dense::update(&mut x, &mut p, &z, &h, &r));
    }
    let dp = rel_diff(&fast.p, &p);
    let dx = (fast.x - x).amax() / x.amax().max(1e-12);
    prop_assert!(dp < 1e-9, "P differs by {dp:e}");
    prop_assert!(dx < 1e-9, "x differs by {dx:e}");
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn fast_and_dense_filters_agree(
        model in arb_model(),
        lp in arb_point(),
        p0 in arb_covariance::<STATES>(),
        x0 in prop::array::uniform9(-0.1f64..0.1),
        zv in prop::array::uniform3(-0.05f64..0.05),
        zp in prop::array::uniform3(-0.5f64..0.5),
        rv in 1e-4f64..1.0,
        rp in 1e-4f64..1.0,
        q in prop::array::uniform9(0.0f64..1e-3),
    ) {
        fast_matches_dense(&model, &lp, p0, &Cycle { x0, zv, zp, rv, rp, q })?;
    }

    #[test]
    fn fast_and_dense_filters_agree_with_bias_states(
        model in arb_model(),
        lp in arb_point(),
        p0 in arb_covariance::<STATES_WITH_BIASES>(),
        x0 in prop::array::uniform9(-0.1f64..0.1),
        zv in prop::array::uniform3(-0.05f64..0.05),
        zp in prop::array::uniform3(-0.5f64..0.5),
        rv in 1e-4f64..1.0,
        rp in 1e-4f64..1.0,
        q in prop::array::uniform9(0.0f64..1e-3),
    ) {
        fast_matches_dense(&model, &lp, p0, &Cycle { x0, zv, zp, rv, rp, q })?;
    }

    #[test]
    fn structured_transition_matches_dense_on_random_inputs(
        model in arb_model(), lp in arb_point(), p0 in arb_covariance::<STATES>(),
    ) {
        let phi = model.transition::<f64, STATES>(&lp);
        let mut m = p0;
        phi.apply_to_matrix(&mut m);
        let reference = phi.to_dense() * p0;
        prop_assert!(rel_diff(&m, &reference) < 1e-14);
    }

    #[test]
    fn structured_39_state_transition_matches_dense_on_random_inputs(
        model in arb_model(), lp in arb_point(), p0 in arb_covariance::<STATES_WITH_BIASES>(),
        x0 in prop::collection::vec(-1.0f64..1.0, STATES_WITH_BIASES),
    ) {
        let phi = model.transition::<f64, STATES_WITH_BIASES>(&lp);
        let mut m = p0;
        phi.apply_to_matrix(&mut m);
        let reference = phi.to_dense() * p0;
        prop_assert!(rel_diff(&m, &reference) < 1e-14);
        let mut x = SVector::<f64, STATES_WITH_BIASES>::from_column_slice(&x0);
        phi.apply_to_vector(&mut x);
        let x_ref = phi.to_dense() * SVector::<f64, STATES_WITH_BIASES>::from_column_slice(&x0);
        prop_assert!((x - x_ref).amax() <= 1e-14 * x_ref.amax().max(1e-300));
    }

    #[test]
    fn general_sparse_row_matches_dense_update(
        p0 in arb_covariance::<STATES>(),
        coefs in prop::array::uniform4(-2.0f64..2.0),
        z in -1.0f64..1.0,
        r in 1e-3f64..1.0,
    ) {
        // A row like a heading or constraint measurement: several states.
        let idx = [0usize, 2, 4, 30];
        let mut row = SparseRow::empty();
        let mut h = SMatrix::<f64, 1, STATES>::zeros();
        for (i, c) in idx.iter().zip(coefs) {
            prop_assert!(row.push(*i, c));
            h[(0, *i)] = c;
        }
        let mut f = KalmanFilter::<f64, STATES>::new(p0);
        let outcome = f.update_scalar(&ScalarMeasurement { z, h: row, r });
        prop_assert!(outcome.is_accepted());
        let mut x = SVector::zeros();
        let mut p = p0;
        prop_assert!(dense::update(&mut x, &mut p, &SVector::<f64, 1>::new(z), &h, &SMatrix::<f64, 1, 1>::new(r)));
        prop_assert!(rel_diff(&f.p, &p) < 1e-9);
        prop_assert!((f.x - x).amax() <= 1e-9 * x.amax().max(1e-12));
    }
}

fn filter() -> KalmanFilter<f32, STATES> {
    let model = AugmentedModel::paper();
    KalmanFilter::new(model.initial_covariance::<f32, STATES>(&[1e-4; 9]))
}

#[test]
fn nan_and_infinite_measurements_leave_the_filter_untouched() {
    let mut f = filter();
    f.x[VEL] = 0.01;
    let before = f.clone();
    let bad = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY];
    for v in bad {
        let report = f.update(&ZeroVelocity {
            velocity_n: [0.0, v, 0.0],
            variance: 0.01,
        });
        assert_eq!(report.non_finite, 1);
        assert_eq!(report.accepted, 2);
        let only_bad = ScalarMeasurement {
            z: v,
            h: SparseRow::select(VEL),
            r: 0.01,
        };
        let mut g = before.clone();
        assert_eq!(g.update_scalar(&only_bad), ScalarOutcome::NonFinite);
        assert_eq!(g, before);
        let bad_variance = ScalarMeasurement {
            z: 0.0,
            h: SparseRow::select(VEL),
            r: v,
        };
        assert_eq!(g.update_scalar(&bad_variance), ScalarOutcome::NonFinite);
        let mut bad_row = SparseRow::empty();
        bad_row.push(VEL, v);
        let bad_row = ScalarMeasurement {
            z: 0.0,
            h: bad_row,
            r: 0.01,
        };
        assert_eq!(g.update_scalar(&bad_row), ScalarOutcome::NonFinite);
        assert_eq!(g, before);
    }
}

#[test]
fn degenerate_and_out_of_range_rows_are_rejected() {
    let mut f = filter();
    let before = f.clone();
    // A state with zero variance measured with zero noise: S = 0.
    f.p[(POS, POS)] = 0.0;
    let before_zero = f.clone();
    let m = ScalarMeasurement {
        z: 1.0,
        h: SparseRow::select(POS),
        r: 0.0,
    };
    assert_eq!(f.update_scalar(&m), ScalarOutcome::Degenerate);
    assert_eq!(f, before_zero);
    // Index beyond the state.
    let mut g = before.clone();
    let mut row = SparseRow::empty();
    assert!(row.push(STATES, 1.0));
    assert_eq!(
        g.update_scalar(&ScalarMeasurement {
            z: 0.0,
            h: row,
            r: 1.0
        }),
        ScalarOutcome::NonFinite
    );
    assert_eq!(g, before);
    assert!(ZeroVelocity {
        velocity_n: [0.0f32; 3],
        variance: 1.0
    }
    .scalar(3)
    .is_none());
}

#[test]
fn chi_square_gate_rejects_outliers_and_passes_ordinary_data() {
    let mut f = filter();
    f.gate = Some(9.0);
    let before = f.clone();
    let s = f.p[(VEL, VEL)] + 0.01;
    let outlier = ScalarMeasurement {
        z: 4.0 * s.sqrt(),
        h: SparseRow::select(VEL),
        r: 0.01,
    };
    assert!(matches!(
        f.update_scalar(&outlier),
        ScalarOutcome::Gated { .. }
    ));
    assert_eq!(f, before);
    let ordinary = ScalarMeasurement {
        z: 2.0 * s.sqrt(),
        h: SparseRow::select(VEL),
        r: 0.01,
    };
    assert!(f.update_scalar(&ordinary).is_accepted());
    assert!(f.p[(VEL, VEL)] < before.p[(VEL, VEL)]);
}

/// The innovation test a caller makes before using a measurement: the
/// gate's own quantity, with the row's cross terms, the filter untouched.
#[test]
fn the_normalized_innovation_squared_is_the_gates_quantity() {
    let mut f = filter();
    f.x[VEL] = 0.02;
    f.p[(VEL, VEL + 1)] = 0.3 * (f.p[(VEL, VEL)] * f.p[(VEL + 1, VEL + 1)]).sqrt();
    f.p[(VEL + 1, VEL)] = f.p[(VEL, VEL + 1)];
    let mut h = SparseRow::empty();
    h.push(VEL, 1.0);
    h.push(VEL + 1, -2.0);
    let m = ScalarMeasurement { z: 0.5, h, r: 0.01 };
    let (a, b, c) = (
        f.p[(VEL, VEL)],
        f.p[(VEL + 1, VEL + 1)],
        f.p[(VEL, VEL + 1)],
    );
    let variance = a + 4.0 * b - 4.0 * c + 0.01;
    let innovation = 0.5 - (0.02 - 2.0 * f.x[VEL + 1]);
    let before = f.clone();
    let nis = f.normalized_innovation_squared(&m).expect("finite");
    assert!(
        (nis / (innovation * innovation / variance) - 1.0).abs() < 1e-5,
        "{nis}"
    );
    assert_eq!(f, before);
    // Just past it the gate rejects the scalar, just short of it accepts.
    f.gate = Some(nis * 1.001);
    assert!(f.clone().update_scalar(&m).is_accepted());
    f.gate = Some(nis * 0.999);
    assert!(matches!(f.update_scalar(&m), ScalarOutcome::Gated { .. }));
    // Not a number, or no positive variance: none.
    let nan = ScalarMeasurement { z: f32::NAN, ..m };
    assert_eq!(before.normalized_innovation_squared(&nan), None);
    let mut singular = before.clone();
    singular.p[(POS, POS)] = 0.0;
    let exact = ScalarMeasurement {
        z: 1.0,
        h: SparseRow::select(POS),
        r: 0.0,
    };
    assert_eq!(singular.normalized_innovation_squared(&exact), None);
}

/// An invalid variance is never reported as a number: the old
/// `std_dev` turned a negative or NaN variance into 0, the most confident
/// sigma there is.
#[test]
fn an_invalid_variance_gives_a_nan_sigma_and_fails_the_health_check() {
    let mut kf = KalmanFilter::<f32, 3>::from_diagonal(&SVector::from([4.0, 1.0, 9.0]));
    assert_eq!(kf.std_dev(0), 2.0);
    assert!(kf.covariance_is_healthy(1e6));
    kf.p[(1, 1)] = -1e-3;
    assert!(kf.std_dev(1).is_nan());
    assert!(!kf.covariance_is_healthy(1e6));
    kf.p[(1, 1)] = f32::NAN;
    assert!(kf.std_dev(1).is_nan());
    assert!(!kf.covariance_is_healthy(1e6));
    kf.p[(1, 1)] = f32::INFINITY;
    assert_eq!(kf.std_dev(1), f32::INFINITY);
    assert!(!kf.covariance_is_healthy(1e6));
    // Positive variances, but a correlation beyond 1: not positive
    // semi-definite (a 2 x 2 minor is negative).
    kf.p[(1, 1)] = 1.0;
    kf.p[(0, 2)] = 6.1;
    kf.p[(2, 0)] = 6.1;
    assert!(!kf.covariance_is_healthy(1e6));
    kf.p[(0, 2)] = 5.9;
    kf.p[(2, 0)] = 5.9;
    assert!(kf.covariance_is_healthy(1e6));
    // Growth beyond the bound.
    assert!(!kf.covariance_is_healthy(8.0));
    // A NaN correlation is not a healthy one.
    kf.p[(0, 2)] = f32::NAN;
    kf.p[(2, 0)] = f32::NAN;
    assert!(!kf.covariance_is_healthy(1e6));
}

/// A quiet gyro's states have variances of 1e-20 and below, whose
/// products are below f32's smallest normal number: the check must still
/// tell a correlation beyond 1 from one within it.
#[test]
fn the_health_check_judges_tiny_variances_as_it_judges_large_ones() {
    let mut kf = KalmanFilter::<f32, 3>::from_diagonal(&SVector::from([1e-22, 4e-24, 1.0]));
    // sqrt(1e-22) sqrt(4e-24); the product of the variances, 4e-46, is 0
    // in f32, and so is the square of any such correlation.
    let bound = 1e-11f32 * 2e-12;
    kf.p[(0, 1)] = 0.999 * bound;
    kf.p[(1, 0)] = 0.999 * bound;
    assert!(kf.covariance_is_healthy(1e6));
    kf.p[(0, 1)] = -1.01 * bound;
    kf.p[(1, 0)] = -1.01 * bound;
    assert!(!kf.covariance_is_healthy(1e6));
}
