//! The error model against the mechanization it describes: perturb a true
//! state by small errors (the project's convention, computed - true), run
//! both through `Strapdown` on the same sensor data, and compare the
//! divergence with what the discrete transition predicts. Checks signs and
//! couplings of F (eq. 12 restated) and of the AR coupling (errata 2-3).

use mwd_core::attitude::quat_from_rotation_vector;
use mwd_core::conventions::{dcm_from_quat, quat_from_euler, Euler};
use mwd_core::earth::{earth_rate_n, gravity_n, Position};
use mwd_core::error_model::{
    navigation_error_dynamics, LinearizationPoint, ATT, NAV_STATES, POS, VEL,
};
use mwd_core::mechanization::{ImuSample, NavState, Strapdown};
use nalgebra::{SMatrix, SVector, Vector3};

const DT: f64 = mwd_core::timing::SAMPLE_INTERVAL_S;
const SUBSTEPS: usize = 20;

fn truth() -> NavState {
    let attitude = quat_from_euler(&Euler::new(0.02, -0.03, 2.6));
    NavState::at_rest(attitude, Position::paper_site())
}

fn ideal_sample(state: &NavState) -> ImuSample {
    let c_nb = dcm_from_quat(&state.attitude).transpose();
    ImuSample {
        rate: c_nb * earth_rate_n(state.position.lat),
        specific_force: c_nb * -gravity_n(&state.position),
    }
}

fn perturbed(t: &NavState, dx: &SVector<f64, NAV_STATES>) -> NavState {
    let phi = Vector3::new(dx[ATT], dx[ATT + 1], dx[ATT + 2]);
    NavState {
        // C_computed = (I - [phi x]) C_true, i.e. q_true = q(phi) q_computed.
        attitude: quat_from_rotation_vector(&-phi) * t.attitude,
        velocity: t.velocity + Vector3::new(dx[VEL], dx[VEL + 1], dx[VEL + 2]),
        position: t
            .position
            .displaced(&Vector3::new(dx[POS], dx[POS + 1], dx[POS + 2])),
    }
}

fn error_of(computed: &NavState, t: &NavState) -> SVector<f64, NAV_STATES> {
    let phi = (t.attitude * computed.attitude.inverse()).scaled_axis();
    let dv = computed.velocity - t.velocity;
    let dp = computed.position.ned_from(&t.position);
    SVector::from_iterator(phi.iter().chain(dv.iter()).chain(dp.iter()).copied())
}

/// Runs truth and the perturbed solution `steps` samples, with an extra
/// sensor error on the computed side, and returns the final error.
fn run(
    dx0: &SVector<f64, NAV_STATES>,
    gyro_err: Vector3<f64>,
    accel_err: Vector3<f64>,
    steps: usize,
) -> SVector<f64, NAV_STATES> {
    let t0 = truth();
    let mut t = Strapdown::new(t0, DT);
    let mut c = Strapdown::new(perturbed(&t0, dx0), DT);
    for _ in 0..steps {
        let s = ideal_sample(t.state());
        t.step(&s);
        c.step(&ImuSample {
            rate: s.rate + gyro_err,
            specific_force: s.specific_force + accel_err,
        });
    }
    error_of(c.state(), t.state())
}

fn predicted(
    dx0: &SVector<f64, NAV_STATES>,
    forcing: &SVector<f64, NAV_STATES>,
    steps: usize,
) -> SVector<f64, NAV_STATES> {
    let t0 = truth();
    let lp = LinearizationPoint {
        c_bn: dcm_from_quat(&t0.attitude),
        velocity_n: t0.velocity,
        position: t0.position,
        specific_force_n: -gravity_n(&t0.position),
    };
    // Integrate the continuous model finely (eq. 15 with dt / 20) so the
    // comparison tests F itself, not the first-order discretisation.
    let h = DT / SUBSTEPS as f64;
    let phi = SMatrix::<f64, 9, 9>::identity() + navigation_error_dynamics::<f64>(&lp) * h;
    let mut dx = *dx0;
    for _ in 0..steps * SUBSTEPS {
        dx = phi * dx + forcing * h;
    }
    dx
}

/// Compares the change of the error over the run, relative to its size.
fn assert_close(
    actual: &SVector<f64, NAV_STATES>,
    predicted: &SVector<f64, NAV_STATES>,
    dx0: &SVector<f64, NAV_STATES>,
    scale: &SVector<f64, NAV_STATES>,
) {
    for i in 0..NAV_STATES {
        let change = predicted[i] - dx0[i];
        let miss = (actual[i] - predicted[i]).abs();
        // The strapdown steps the position with each interval's starting
        // velocity (the first-order transition's own step): against the
        // continuous model it lags by dt/2 times the velocity error's
        // change (docs/filter-derivation.md section 5c).
        let lag = if (POS..POS + 3).contains(&i) {
            0.5 * DT * (predicted[VEL + i - POS] - dx0[VEL + i - POS]).abs()
        } else {
            0.0
        };
        assert!(
            miss <= 0.05 * change.abs() + scale[i] + 1.1 * lag,
            "state {i}: actual {:e} predicted {:e} start {:e}",
            actual[i],
            predicted[i],
            dx0[i]
        );
    }
}

// Tolerance floors: second-order terms of the chosen perturbations (a
// tilt of 3.7e-3 rad loses g phi^2 / 2 = 2.5e-5 m/s^2 of vertical force)
// and the mechanization's own integration rules.
fn floors() -> SVector<f64, NAV_STATES> {
    SVector::from_column_slice(&[1e-9, 1e-9, 1e-9, 1e-5, 1e-5, 5e-5, 1e-4, 1e-4, 1e-4])
}

#[test]
fn attitude_and_velocity_errors_propagate_as_modelled() {
    let dx0 = SVector::from_column_slice(&[1e-3, -2e-3, 3e-3, 0.01, -0.02, 0.005, 0.0, 0.0, 0.0]);
    let actual = run(&dx0, Vector3::zeros(), Vector3::zeros(), 20);
    let pred = predicted(&dx0, &SVector::zeros(), 20);
    assert_close(&actual, &pred, &dx0, &floors());
    // The tilt errors really did couple into velocity (not a vacuous check).
    assert!((actual[VEL] - dx0[VEL]).abs() > 0.01);
}

#[test]
fn position_errors_propagate_as_modelled() {
    let dx0 = SVector::from_column_slice(&[0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 50.0, -40.0, 3.0]);
    let actual = run(&dx0, Vector3::zeros(), Vector3::zeros(), 20);
    let pred = predicted(&dx0, &SVector::zeros(), 20);
    assert_close(&actual, &pred, &dx0, &floors());
}

#[test]
fn sensor_errors_enter_through_plus_and_minus_c_bn() {
    let t0 = truth();
    let c = dcm_from_quat(&t0.attitude);
    let gyro = Vector3::new(2e-4, -1e-4, 3e-4);
    let accel = Vector3::new(0.02, -0.01, 0.03);
    let dx0 = SVector::zeros();
    let actual = run(&dx0, gyro, accel, 20);
    // The AR coupling of the augmented model: phi' += -C gyro, dv' += C accel.
    let mut forcing = SVector::<f64, NAV_STATES>::zeros();
    forcing.fixed_rows_mut::<3>(ATT).copy_from(&(-c * gyro));
    forcing.fixed_rows_mut::<3>(VEL).copy_from(&(c * accel));
    let pred = predicted(&dx0, &forcing, 20);
    assert_close(&actual, &pred, &dx0, &floors());
    assert!(actual.fixed_rows::<3>(ATT).norm() > 1e-4);
}
