use super::*;
use crate::kalman::{dense::DenseTransition, Transition};
use nalgebra::{SVector, Vector3};

fn static_point() -> LinearizationPoint {
    let position = Position::paper_site();
    let c_bn = nalgebra::Rotation3::from_euler_angles(0.01, -0.02, 2.6).into_inner();
    LinearizationPoint {
        c_bn,
        velocity_n: Vector3::zeros(),
        position,
        specific_force_n: -crate::earth::gravity_n(&position),
    }
}

#[test]
fn frame_rates_agree_with_the_earth_module() {
    // F11 = -[(omega_ie + omega_en) x] must use the earth module's rates.
    let mut lp = static_point();
    lp.velocity_n = Vector3::new(3.0, -2.0, 0.5);
    let f: nalgebra::SMatrix<f64, 9, 9> = navigation_error_dynamics(&lp);
    let w = crate::earth::earth_rate_n(lp.position.lat)
        + crate::earth::transport_rate_n(&lp.position, &lp.velocity_n);
    let expected = -crate::conventions::skew(&w);
    assert!((f.fixed_view::<3, 3>(ATT, ATT) - expected).amax() < 1e-20);
}

#[test]
fn indices_make_33_states() {
    assert_eq!(STATES, 33);
    assert_eq!(newest_ar_state(ACCEL_AR, 0), 12);
    assert_eq!(newest_ar_state(GYRO_AR, 2), 32);
    assert_eq!((ACCEL_BIAS, GYRO_BIAS, STATES_WITH_BIASES), (33, 36, 39));
}

#[test]
fn bias_states_are_random_constants_driving_velocity_and_attitude() {
    let lp = static_point();
    let model = AugmentedModel::paper();
    let phi = model.transition::<f64, STATES_WITH_BIASES>(&lp).to_dense();
    // The 33-state part is the 33-state transition itself.
    let phi33 = model.transition::<f64, STATES>(&lp).to_dense();
    assert_eq!(phi.fixed_view::<STATES, STATES>(0, 0).into_owned(), phi33);
    for axis in 0..3 {
        for i in 0..3 {
            let g = lp.c_bn[(i, axis)] * model.dt;
            assert_eq!(phi[(VEL + i, ACCEL_BIAS + axis)], g);
            assert_eq!(phi[(ATT + i, GYRO_BIAS + axis)], -g);
        }
    }
    // Bias rows: identity, nothing else.
    let bias_rows = phi.fixed_view::<6, STATES_WITH_BIASES>(ACCEL_BIAS, 0);
    assert_eq!(
        bias_rows.columns(ACCEL_BIAS, 6),
        nalgebra::SMatrix::<f64, 6, 6>::identity()
    );
    assert_eq!(bias_rows.columns(0, ACCEL_BIAS).amax(), 0.0);
    // Statistics from the budget: 1 mg and 2.1 deg/h residual with the
    // Gauss-Markov instability root-sum-squared; a small random walk.
    let p = model.initial_covariance::<f64, STATES_WITH_BIASES>(&[1e-4; NAV_STATES]);
    let budget = crate::sensor_noise::ImuNoise::scc1300();
    let a = budget.accel[0];
    let expected = a.residual_bias.powi(2) + a.bias_instability.powi(2);
    assert!((p[(ACCEL_BIAS, ACCEL_BIAS)] - expected).abs() < 1e-12 * expected);
    let q = model.process_noise::<f64, STATES_WITH_BIASES>(&ProcessNoise {
        nav_per_step: [0.0; NAV_STATES],
    });
    let g = budget.gyro[2];
    let walk = q[GYRO_BIAS + 2];
    assert!(walk > 0.0 && walk < 2.0 * g.bias_instability.powi(2) * model.dt / 100.0);
}

#[test]
fn static_error_dynamics_are_the_textbook_psi_model() {
    let lp = static_point();
    let f = navigation_error_dynamics::<f64>(&lp);
    let w = crate::earth::earth_rate_n(lp.position.lat);
    let g = crate::earth::normal_gravity(lp.position.lat, lp.position.height);
    // phi' = -w_ie x phi: phiE' = -wD phiN + wN phiD.
    assert_eq!(f[(ATT + 1, ATT)], -w.z);
    assert_eq!(f[(ATT + 1, ATT + 2)], w.x);
    assert_eq!(f[(ATT, ATT + 1)], w.z);
    // dv' = f^n x phi with f^n = (0, 0, -g): dvN' = g phiE, dvE' = -g phiN.
    assert!((f[(VEL, ATT + 1)] - g).abs() < 1e-12);
    assert!((f[(VEL + 1, ATT)] + g).abs() < 1e-12);
    // dp' = dv, and a positive down-position error raises gravity's error:
    // the vertical channel's instability, about 2 g / R.
    assert_eq!(f[(POS + 2, VEL + 2)], 1.0);
    let vertical = f[(VEL + 2, POS + 2)];
    assert!((vertical - 3.08e-6).abs() < 0.05e-6, "{vertical}");
}

/// The error model must predict how a perturbed solution diverges from the
/// true one: compare F against a numerical derivative of the NED kinematics
/// for the velocity-to-attitude and velocity-to-position couplings.
#[test]
fn transport_rate_terms_match_a_finite_difference() {
    let mut lp = static_point();
    lp.velocity_n = Vector3::new(3.0, -2.0, 0.5);
    let f = navigation_error_dynamics::<f64>(&lp);
    let wen = |v: &Vector3<f64>, p: &Position| crate::earth::transport_rate_n(p, v);
    let h = 1e-3;
    for k in 0..3 {
        let mut dv = Vector3::zeros();
        dv[k] = h;
        let d = (wen(&(lp.velocity_n + dv), &lp.position) - wen(&lp.velocity_n, &lp.position)) / h;
        for i in 0..3 {
            assert!((f[(ATT + i, VEL + k)] - d[i]).abs() < 1e-12, "{i} {k}");
        }
    }
}

#[test]
fn structured_transition_equals_its_dense_form() {
    let mut lp = static_point();
    lp.velocity_n = Vector3::new(0.3, 0.1, -0.05);
    for coupling in [
        Coupling::SensorErrorsDriveNavigation,
        Coupling::BlockDiagonalAsPublished,
    ] {
        let model = AugmentedModel {
            coupling,
            ..AugmentedModel::paper()
        };
        fast_equals_dense::<STATES>(&model, &lp);
        fast_equals_dense::<STATES_WITH_BIASES>(&model, &lp);
    }
}

fn fast_equals_dense<const N: usize>(model: &AugmentedModel, lp: &LinearizationPoint) {
    let phi = model.transition::<f64, N>(lp);
    let dense = DenseTransition(phi.to_dense());
    let mut m = nalgebra::SMatrix::<f64, N, N>::from_fn(|i, j| libm::sin((i * 37 + j * 11) as f64));
    let mut m2 = m;
    phi.apply_to_matrix(&mut m);
    dense.apply_to_matrix(&mut m2);
    assert!((m - m2).amax() < 1e-14);
    let mut x = SVector::<f64, N>::from_fn(|i, _| libm::cos(i as f64));
    let mut x2 = x;
    phi.apply_to_vector(&mut x);
    dense.apply_to_vector(&mut x2);
    assert!((x - x2).amax() < 1e-14);
}

#[test]
fn coupling_puts_sensor_errors_into_velocity_and_attitude() {
    let lp = static_point();
    let phi = AugmentedModel::paper()
        .transition::<f64, STATES>(&lp)
        .to_dense();
    // A body-x accelerometer error moves the velocity error along C_b^n's
    // first column; a body-x rate error turns phi along minus that column.
    for i in 0..3 {
        assert!(
            (phi[(VEL + i, newest_ar_state(ACCEL_AR, 0))] - lp.c_bn[(i, 0)] * 0.05).abs() < 1e-15
        );
        assert!(
            (phi[(ATT + i, newest_ar_state(GYRO_AR, 0))] + lp.c_bn[(i, 0)] * 0.05).abs() < 1e-15
        );
    }
    let published = AugmentedModel {
        coupling: Coupling::BlockDiagonalAsPublished,
        ..AugmentedModel::paper()
    };
    let phi = published.transition::<f64, STATES>(&lp).to_dense();
    assert!(phi.fixed_view::<9, 24>(0, 9).amax() == 0.0);
}

#[test]
fn initial_covariance_holds_the_stationary_ar_blocks() {
    let model = AugmentedModel::paper();
    let p = model.initial_covariance::<f64, STATES>(&[1e-4; NAV_STATES]);
    let s = model.gyro[2].stationary_state_covariance().unwrap();
    let b = GYRO_AR + 2 * AR_ORDER;
    assert_eq!(p.fixed_view::<4, 4>(b, b).into_owned(), s);
    let q = model.process_noise::<f64, STATES>(&ProcessNoise {
        nav_per_step: [0.0; NAV_STATES],
    });
    assert_eq!(
        q[newest_ar_state(ACCEL_AR, 1)],
        model.accel[1].noise_variance
    );
    assert_eq!(q[ACCEL_AR], 0.0);
}
