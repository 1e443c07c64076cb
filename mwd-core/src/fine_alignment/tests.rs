use super::*;
use crate::conventions::{dcm_from_quat, euler_from_quat, quat_from_euler, DEG};
use crate::earth::{earth_rate_n, gravity_n, LocalEarth, Position};
use crate::error_model::{
    AugmentedModel, AugmentedTransition, LinearizationPoint, ACCEL_BIAS, ATT, GYRO_BIAS, STATES,
    STATES_WITH_BIASES, VEL,
};
use crate::kalman::KalmanFilter;
use crate::mechanization::{ImuSample, NavState};
use crate::sensor_noise::ImuNoise;
use linearization::COS_HALF_MAX_LINEARIZATION_TURN;
use nalgebra::{SMatrix, SVector, UnitQuaternion, Vector3};

/// A negative or NaN attitude variance gives NaN Euler sigmas, never
/// the 0 the old `max(0.0)` made of it.
#[test]
fn an_invalid_attitude_variance_gives_nan_euler_sigmas() {
    let site = Position::paper_site();
    let config = FineAlignmentConfig::<STATES>::physical(
        AugmentedModel::paper(),
        &ImuNoise::scc1300(),
        &[0.01, 0.01, 0.1],
        site.lat,
    );
    let mut fa = FineAlignment::<f32, STATES>::new(
        NavState::at_rest(UnitQuaternion::identity(), site),
        site,
        config,
    );
    assert!(fa.euler_std().iter().all(|s| s.is_finite() && *s > 0.0));
    // The level tool's tilt errors are phiN and phiE (roll and pitch in
    // some order): a negative variance of either reaches one of them.
    fa.filter.p[(ATT, ATT)] = -1e-4;
    fa.filter.p[(ATT + 1, ATT + 1)] = -1e-4;
    let std = fa.euler_std();
    assert!(std.x.is_nan() && std.y.is_nan(), "{std:?}");
    fa.filter.p[(ATT, ATT)] = f32::NAN;
    assert!(fa.euler_std().iter().all(|s| s.is_nan()));
}

/// The held-axis time update (structured product plus rank-2
/// correction) equals the dense M P M^T + (I - e e^T) Q (I - e e^T),
/// M = Phi - e w^T (Q with different attitude entries), and leaves the
/// attitude error about the axis where it was, variance and all.
#[test]
fn holding_an_axis_matches_the_dense_transition() {
    let model = AugmentedModel::paper();
    let position = Position::paper_site();
    let c_bn = nalgebra::Rotation3::from_euler_angles(0.3, 1.2, 2.0).into_inner();
    let lp = LinearizationPoint {
        c_bn,
        velocity_n: Vector3::new(0.01, -0.02, 0.0),
        position,
        specific_force_n: -gravity_n(&position),
    };
    let phi: AugmentedTransition<f64, STATES_WITH_BIASES> =
        model.transition_with(&LocalEarth::at(&position), &lp);
    let n = STATES_WITH_BIASES;
    let l = SMatrix::<f64, STATES_WITH_BIASES, STATES_WITH_BIASES>::from_fn(|i, j| {
        if j <= i {
            1e-3 * (1.0 + ((i * 7 + j * 3) % 11) as f64) / (1.0 + (i + j) as f64)
        } else {
            0.0
        }
    });
    let p0 = l * l.transpose();
    let q = SVector::<f64, STATES_WITH_BIASES>::from_fn(|i, _| 1e-9 * (1 + i % 5) as f64);
    let x0 = SVector::<f64, STATES_WITH_BIASES>::from_fn(|i, _| 1e-4 * (i as f64 - 17.0));
    let axis = c_bn.column(1).into_owned();
    let mut e = SVector::<f64, STATES_WITH_BIASES>::zeros();
    for i in 0..3 {
        e[ATT + i] = axis[i];
    }
    let dense = phi.to_dense();
    let w = dense.transpose() * e - e;
    let m = dense - e * w.transpose();
    let hold =
        SMatrix::<f64, STATES_WITH_BIASES, STATES_WITH_BIASES>::identity() - e * e.transpose();
    let want_p = m * p0 * m.transpose() + hold * SMatrix::from_diagonal(&q) * hold;
    let want_x = m * x0;
    let mut filter = KalmanFilter::new(p0);
    filter.x = x0;
    predict_holding_axis(&mut filter, &phi, &q, &axis);
    for i in 0..n {
        assert!((filter.x[i] - want_x[i]).abs() <= 1e-12, "x[{i}]");
        for j in 0..n {
            let tol = 1e-12 * (want_p[(i, i)] * want_p[(j, j)]).sqrt().max(1e-12);
            assert!(
                (filter.p[(i, j)] - want_p[(i, j)]).abs() <= tol,
                "P[{i},{j}]"
            );
        }
    }
    // Along the axis the attitude error is carried unchanged, with no
    // process noise: its variance does not grow.
    let along = |p: &SMatrix<f64, STATES_WITH_BIASES, STATES_WITH_BIASES>| {
        (0..3)
            .flat_map(|a| (0..3).map(move |b| (a, b)))
            .map(|(a, b)| axis[a] * axis[b] * p[(ATT + a, ATT + b)])
            .sum::<f64>()
    };
    assert!((along(&filter.p) - along(&p0)).abs() <= 1e-15);
}

/// A level 39-state filter at the paper's site with `noise` and
/// `coarse_sigma` (`configure` edits its configuration first), and the
/// sample of a still, perfect probe there.
fn level_filter_at_rest(
    noise: &ImuNoise,
    coarse_sigma: &[f64; 3],
    configure: impl FnOnce(&mut FineAlignmentConfig<STATES_WITH_BIASES>),
) -> (FineAlignment<f64, STATES_WITH_BIASES>, ImuSample) {
    let site = Position::paper_site();
    let mut config = FineAlignmentConfig::<STATES_WITH_BIASES>::physical(
        AugmentedModel::paper(),
        noise,
        coarse_sigma,
        site.lat,
    );
    configure(&mut config);
    let filter = FineAlignment::new(
        NavState::at_rest(UnitQuaternion::identity(), site),
        site,
        config,
    );
    let at_rest = ImuSample {
        rate: earth_rate_n(site.lat),
        specific_force: -gravity_n(&site),
    };
    (filter, at_rest)
}

/// With the linearisation fixed, a step's covariance does not depend
/// on where the estimate has moved the attitude since (a 0.5-deg roll
/// correction here); unfixed it does, through C_b^n in Phi. Fixing again
/// keeps the first attitude while the estimate stays within
/// `MAX_LINEARIZATION_TURN_RAD` of it and takes the new one beyond;
/// unfixing goes back to each step's.
#[test]
fn a_fixed_linearization_does_not_follow_the_estimate() {
    let noise = ImuNoise::scc1300();
    let (mut start, at_rest) = level_filter_at_rest(&noise, &[0.01, 0.01, 0.1], |_| {});
    start.step(&at_rest);
    start.hold_tool_axis(true);
    let covariance_after = |fix: bool, turn: f64| {
        let mut fa = start.clone();
        fa.fix_linearization(fix);
        let roll = euler_from_quat(&fa.state().attitude).roll;
        fa.set_roll(roll + turn);
        fa.fix_linearization(fix);
        fa.step(&at_rest);
        fa.filter.p
    };
    let largest_change =
        |a: &SMatrix<f64, STATES_WITH_BIASES, STATES_WITH_BIASES>,
         b: &SMatrix<f64, STATES_WITH_BIASES, STATES_WITH_BIASES>| {
            (0..STATES_WITH_BIASES)
                .flat_map(|i| (0..STATES_WITH_BIASES).map(move |j| (i, j)))
                .map(|(i, j)| (a[(i, j)] - b[(i, j)]).abs() / (a[(i, i)] * a[(j, j)]).sqrt())
                .fold(0.0, f64::max)
        };
    let turn = 0.5 * DEG;
    let fixed = largest_change(&covariance_after(true, 0.0), &covariance_after(true, turn));
    let free = largest_change(
        &covariance_after(false, 0.0),
        &covariance_after(false, turn),
    );
    // What is left fixed is the velocity's share of Phi (Coriolis and
    // transport terms at the step's computed velocity).
    assert!(fixed < 1e-7, "fixed: {fixed:e}");
    assert!(free > 1e-4, "free: {free:e}");
    assert!(fixed < 1e-3 * free, "fixed {fixed:e}, free {free:e}");
    let mut fa = start.clone();
    fa.fix_linearization(true);
    let first = fa.linearization_attitude;
    let roll = euler_from_quat(&fa.state().attitude).roll;
    // within the turn allowed: the first attitude is kept
    fa.set_roll(roll + 0.9 * MAX_LINEARIZATION_TURN_RAD);
    fa.fix_linearization(true);
    assert_eq!(fa.linearization_attitude, first);
    assert_eq!(Some(fa.linearization_attitude()), first);
    assert_ne!(fa.linearization_attitude(), fa.state().attitude);
    // beyond it (a heading re-found by degrees): taken again
    fa.set_roll(roll + 1.1 * MAX_LINEARIZATION_TURN_RAD);
    fa.fix_linearization(true);
    assert_ne!(fa.linearization_attitude, first);
    assert_eq!(fa.linearization_attitude, Some(fa.state().attitude));
    fa.fix_linearization(false);
    assert_eq!(fa.linearization_attitude, None);
    assert_eq!(fa.linearization_attitude(), fa.state().attitude);
    extern crate std;
    let cos_half = std::primitive::f64::cos(0.5 * MAX_LINEARIZATION_TURN_RAD);
    assert!((COS_HALF_MAX_LINEARIZATION_TURN - cos_half).abs() < 1e-15);
}

/// A fixed point follows the estimate's heading about the vertical
/// (beyond `MAX_LINEARIZATION_HEADING_LAG_RAD`), keeping its own tilt
/// and roll, and turns the navigation-frame attitude and velocity
/// covariance with it: P <- T P T^T, the body-frame states untouched.
#[test]
fn a_fixed_linearization_follows_the_heading_and_turns_the_covariance() {
    let noise = ImuNoise::scc1300();
    let (mut fa, at_rest) = level_filter_at_rest(&noise, &[0.01, 0.01, 0.1], |_| {});
    for _ in 0..50 {
        fa.step(&at_rest);
    }
    fa.hold_tool_axis(true);
    fa.fix_linearization(true);
    let first = fa.linearization_attitude();
    let set_heading = |fa: &mut FineAlignment<f64, STATES_WITH_BIASES>, heading: f64, roll: f64| {
        let mut state = *fa.state();
        let mut e = euler_from_quat(&state.attitude);
        e.heading = heading;
        e.roll = roll;
        state.attitude = quat_from_euler(&e);
        fa.strapdown.reset(state);
    };
    let e0 = euler_from_quat(&first);
    // within the lag: nothing moves
    let p0 = fa.filter.p;
    set_heading(
        &mut fa,
        e0.heading + 0.9 * MAX_LINEARIZATION_HEADING_LAG_RAD,
        e0.roll,
    );
    fa.fix_linearization(true);
    assert_eq!(fa.linearization_attitude(), first);
    assert_eq!(fa.filter.p, p0);
    // 3 deg of heading and 0.3 deg of roll: the heading is taken, the
    // roll (within MAX_LINEARIZATION_TURN_RAD) is not
    let turn = 3.0 * DEG;
    set_heading(&mut fa, e0.heading + turn, e0.roll + 0.3 * DEG);
    fa.fix_linearization(true);
    let e1 = euler_from_quat(&fa.linearization_attitude());
    assert!((e1.heading - (e0.heading + turn)).abs() < 1e-9, "{e1:?}");
    assert!((e1.roll - e0.roll).abs() < 1e-9 && (e1.pitch - e0.pitch).abs() < 1e-9);
    let r = dcm_from_quat(&fa.linearization_attitude()) * dcm_from_quat(&first).transpose();
    let rz = nalgebra::Rotation3::from_axis_angle(&Vector3::z_axis(), turn).into_inner();
    assert!((r - rz).abs().max() < 1e-12, "{r}");
    let mut t = SMatrix::<f64, STATES_WITH_BIASES, STATES_WITH_BIASES>::identity();
    t.fixed_view_mut::<3, 3>(ATT, ATT).copy_from(&rz);
    t.fixed_view_mut::<3, 3>(VEL, VEL).copy_from(&rz);
    let expected = t * p0 * t.transpose();
    let p = fa.filter.p;
    for i in 0..STATES_WITH_BIASES {
        for j in 0..STATES_WITH_BIASES {
            let scale = (p0[(i, i)] * p0[(j, j)]).sqrt().max(1e-300);
            assert!(
                (p[(i, j)] - expected[(i, j)]).abs() <= 1e-12 * scale,
                "({i}, {j})"
            );
            assert_eq!(p[(i, j)], p[(j, i)]);
        }
    }
    // the body-frame blocks are the same numbers
    for i in ACCEL_BIAS..STATES_WITH_BIASES {
        assert_eq!(p[(i, i)], p0[(i, i)]);
    }
}

/// Accelerometer biases that are not learned (a moving tool): no
/// measurement moves their estimate or shrinks their variance, and
/// their walk adds up to the instability's largest change, 2 sigma^2
/// (an hour's walk would be 72), however long they are held; learned
/// again, the next update moves them.
#[test]
fn unlearned_accelerometer_biases_hold_and_walk_up_to_the_instabilitys_largest_change() {
    let noise = ImuNoise::scc1300();
    let (mut fa, at_rest) = level_filter_at_rest(&noise, &[0.01, 0.01, 0.1], |_| {});
    fa.step(&at_rest);
    let estimate = fa.filter.x[ACCEL_BIAS + 1];
    let variance = fa.filter.p[(ACCEL_BIAS + 1, ACCEL_BIAS + 1)];
    fa.learn_accel_bias(false);
    assert!(!fa.learns_accel_bias());
    let sigma = noise.accel[1].bias_instability;
    let per_step = fa.config.model.biases.accel[1].variance_per_step;
    let steps_per_sigma_sq = (sigma * sigma / per_step) as usize;
    // 3 sigma^2 worth of steps: the cap stops it at 2
    for _ in 0..3 * steps_per_sigma_sq {
        fa.step(&at_rest);
    }
    assert_eq!(fa.filter.x[ACCEL_BIAS + 1], estimate, "a held bias moved");
    let grown = fa.filter.p[(ACCEL_BIAS + 1, ACCEL_BIAS + 1)] - variance;
    assert!(
        (grown / (2.0 * sigma * sigma) - 1.0).abs() < 1e-6,
        "{grown} against {}",
        2.0 * sigma * sigma
    );
    // the held bias stays correlated with the tilt the updates learned
    assert!(fa.filter.p[(ACCEL_BIAS + 1, 0)].abs() + fa.filter.p[(ACCEL_BIAS + 1, 1)].abs() > 0.0);
    // a force the bias could explain: held, the estimate does not move;
    // learned, it does
    let mut pushed = at_rest;
    pushed.specific_force.y += 0.01;
    fa.step(&pushed);
    assert_eq!(fa.filter.x[ACCEL_BIAS + 1], estimate);
    fa.learn_accel_bias(true);
    fa.step(&pushed);
    assert_ne!(fa.filter.x[ACCEL_BIAS + 1], estimate);
}

#[test]
fn navigation_keeps_the_gyro_bias_constant_and_adds_the_instability_as_rate_noise() {
    // The instability alone drives the heading: no white or AR gyro
    // noise, a small heading sigma (its large-angle drift term off).
    let mut noise = ImuNoise::scc1300();
    for g in &mut noise.gyro {
        g.white_density = 0.0;
    }
    let (mut fa, at_rest) = level_filter_at_rest(&noise, &[0.01, 0.01, 0.01], |config| {
        config.zero_velocity_variance = None;
        config.zero_position_variance = None;
        config.ar_noise_scale = 0.0;
    });
    let dt = fa.config.model.dt;
    let p = |fa: &FineAlignment<f64, STATES_WITH_BIASES>, i: usize, j: usize| fa.filter.p[(i, j)];
    fa.step(&at_rest);
    let before = [GYRO_BIAS, GYRO_BIAS + 1, GYRO_BIAS + 2].map(|i| p(&fa, i, i));
    fa.set_bias_walk(BiasWalk::InstabilityAsRateNoise);
    let sigma = noise.gyro[2].bias_instability;
    // A filter that has run: the absorbed instability, once.
    let switched = p(&fa, GYRO_BIAS + 2, GYRO_BIAS + 2);
    assert!((switched - before[2] - sigma * sigma).abs() < 1e-9 * sigma * sigma);
    fa.set_bias_walk(BiasWalk::InstabilityAsRateNoise);
    assert_eq!(p(&fa, GYRO_BIAS + 2, GYRO_BIAS + 2), switched);

    let psi = ATT + 2;
    let (h0, c0) = (p(&fa, psi, psi), p(&fa, psi, GYRO_BIAS + 2));
    let steps = 600;
    for _ in 0..steps {
        fa.step(&at_rest);
    }
    // The x and z biases are constants now; the tool-axis rate's walks.
    let relative = |a: f64, b: f64| (a / b - 1.0).abs();
    assert!(relative(p(&fa, GYRO_BIAS, GYRO_BIAS), before[0] + sigma * sigma) < 1e-9);
    assert!(relative(p(&fa, GYRO_BIAS + 2, GYRO_BIAS + 2), switched) < 1e-9);
    let y_walk = fa.config.model.biases.gyro[1].variance_per_step;
    assert!(p(&fa, GYRO_BIAS + 1, GYRO_BIAS + 1) > before[1] + 0.9 * steps as f64 * y_walk);
    // Level tool, body z down: psi' = -b_z + w, w the instability as
    // white noise of density 2 sigma^2 tau, so over t the heading
    // variance grows by t^2 P_bb - 2 t P_psi,b + 2 sigma^2 tau t.
    let tau = noise.gyro[2].correlation_time;
    let t = steps as f64 * dt;
    let white = 2.0 * sigma * sigma * tau * t;
    let expected = t * t * switched - 2.0 * t * c0 + white;
    let grown = p(&fa, psi, psi) - h0;
    assert!(
        relative(grown, expected) < 0.02,
        "{grown} vs {expected} (white {white})"
    );
}

/// A heading correction fed back while the model follows each step's
/// estimate turns the navigation-frame errors' covariance with the
/// estimate's heading (the reset's heading part): P <- T P T^T, T = R_z on
/// the attitude and velocity blocks. Corrections under the 0.1-deg lag
/// are summed until they pass it. The expected turn is the estimate's
/// own heading change, not the correction's convention.
#[test]
fn heading_corrections_turn_the_navigation_covariance_with_the_estimate() {
    let noise = ImuNoise::scc1300();
    let (mut fa, _) = level_filter_at_rest(&noise, &[0.01, 0.01, 0.1], |_| {});
    let p = &mut fa.filter.p;
    p.fill(0.0);
    for (i, v) in [
        (ATT, 4e-6),
        (ATT + 1, 1e-6),
        (ATT + 2, 9e-4),
        (VEL, 2e-4),
        (VEL + 1, 1e-4),
    ] {
        p[(i, i)] = v;
    }
    p[(ATT, ACCEL_BIAS + 1)] = 1e-8;
    p[(ACCEL_BIAS + 1, ATT)] = 1e-8;
    let before = fa.filter.p;
    let heading = |fa: &FineAlignment<f64, STATES_WITH_BIASES>| {
        euler_from_quat(&fa.strapdown.state().attitude).heading
    };
    let start = heading(&fa);
    // aligning (the paper's filter): no turn at all
    fa.filter.x[ATT + 2] = 0.5 * DEG;
    fa.feed_back();
    assert_eq!(fa.filter.p, before);
    assert!((heading(&fa) - start - 0.5 * DEG).abs() < 1e-9);
    // navigating (the turn only, not the rest of `start_navigation`)
    fa.unturned_correction = Some((1.0, 0.0));
    let start = heading(&fa);
    // 0.06 deg: under the lag, nothing turns yet
    fa.filter.x[ATT + 2] = 0.06 * DEG;
    fa.feed_back();
    assert_eq!(fa.filter.p, before);
    // twice: 0.12 deg in all, turned whole
    fa.filter.x[ATT + 2] = 0.06 * DEG;
    fa.feed_back();
    let turn = heading(&fa) - start;
    assert!((turn.abs() - 0.12 * DEG).abs() < 1e-9, "{}", turn / DEG);
    let r = nalgebra::Rotation3::from_axis_angle(&Vector3::z_axis(), turn).into_inner();
    let mut t = SMatrix::<f64, STATES_WITH_BIASES, STATES_WITH_BIASES>::identity();
    for first in [ATT, VEL] {
        t.fixed_view_mut::<3, 3>(first, first).copy_from(&r);
    }
    let expected = t * before * t.transpose();
    for i in 0..STATES_WITH_BIASES {
        for j in 0..STATES_WITH_BIASES {
            assert!(
                (fa.filter.p[(i, j)] - expected[(i, j)]).abs() < 1e-13,
                "P[{i},{j}]"
            );
        }
    }
    // with a fixed point, the point's own heading follow does it instead
    fa.fix_linearization(true);
    let fixed = fa.filter.p;
    fa.filter.x[ATT + 2] = 0.5 * DEG;
    fa.feed_back();
    assert_eq!(fa.filter.p, fixed);
}
