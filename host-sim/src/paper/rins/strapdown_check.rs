//! The cross-check of the error-state simulation (`system.rs`) against a
//! full strapdown run: one system's ideal IMU outputs on the scenario's
//! straight route, with its rotation scheme applied and its constant sensor
//! errors added, integrated by `mwd_core::mechanization` (NED), and the
//! solution's errors compared with the error-state propagation of the same
//! errors (ENU, the navigation block of `mwd_core::redundant`) over the
//! same span.
//!
//! Truth: level vehicle at constant latitude and height, constant velocity
//! over the earth, so the navigation frame turns at the constant
//! omega_in^n = omega_ie^n + omega_en^n and the IMU's attitude is
//! C_b^n(t) = C_enu^ned C_vehicle R(t), R the scheme's IMU-to-vehicle
//! rotation. The gyro senses omega_ib^b = R^T (C_enu^ned C_vehicle)^T
//! omega_in^n plus the scheme's own rate; the accelerometers
//! f^b = C_n^b ((2 omega_ie + omega_en) x v - g) (Titterton and Weston,
//! eq. 3.30 with dv/dt = 0). Samples are the integrals of these over the
//! sample interval divided by it (what an integrating IMU delivers; the
//! mechanization's coning and sculling terms then do their job).
//!
//! The vertical channel is held at the truth after every sample (an
//! altitude aid): the error model leaves it out (the paper's choice) and an
//! unaided one diverges with the time constant sqrt(R / 2g) ~ 9.5 min.
//!
//! Why the two cannot agree exactly: the error model is first order
//! (products of errors, e.g. phi x (phi x f), dropped), it is linearised
//! about the true motion with R and g at the true latitude, the error-state
//! run holds each second's forcing at its mid-second orientation (10 deg of
//! turn per second during the rotations), and the mechanization has its
//! own integration error (the error-free run's figures, `floor`).

use super::rotation::{PhasedScheme, RotationScheme, Timing};
use super::system::{Ins, NavErrors, Propagation, Sensors};
use super::Scenario;
use mwd_core::conventions::DEG;
use mwd_core::earth::{normal_gravity, LocalEarth, Position};
use mwd_core::mechanization::{ImuSample, NavState, Strapdown};
use mwd_core::redundant::index::{DV_E, DV_N, D_LAT, D_LON, PHI_E};
use mwd_core::redundant::{navigation_block, Motion};
use nalgebra::{Matrix3, Rotation3, UnitQuaternion, Vector3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::Serialize;

/// Which of the scenario's two systems is checked.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum System {
    /// The single-axis backup (four dwells about the vertical).
    Backup,
    /// The dual-axis master (sixteen 180 deg flips).
    Master,
}

/// What to run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Check {
    pub system: System,
    /// Span (h) and strapdown sample rate (Hz, a whole number of samples
    /// per error-state substep).
    pub hours: f64,
    pub sample_rate_hz: f64,
    /// Initial attitude error, ENU (rad), the same in both runs.
    pub initial_attitude: Vector3<f64>,
    /// With `false` the sensors are perfect and the initial attitude exact:
    /// the strapdown's own error (the error-state run stays at zero).
    pub sensor_errors: bool,
}

impl Check {
    /// The scenario's 1-sigma initial attitude errors as a fixed error
    /// (east and north level, up azimuth), with the sensor errors.
    pub fn new(system: System, hours: f64, sample_rate_hz: f64, s: &Scenario) -> Self {
        let [level, azimuth] = s.initial_attitude;
        Self {
            system,
            hours,
            sample_rate_hz,
            initial_attitude: Vector3::new(level, -level, azimuth),
            sensor_errors: true,
        }
    }
}

/// The agreement of one quantity over the run.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Agreement {
    /// Largest |strapdown - error-state| (norm over the components).
    pub max_difference: f64,
    /// Largest error-state error (norm): the scale of the difference.
    pub max_error: f64,
}

impl Agreement {
    fn new() -> Self {
        Self {
            max_difference: 0.0,
            max_error: 0.0,
        }
    }

    fn add(&mut self, strapdown: &[f64], error_state: &[f64]) {
        let norm = |f: &dyn Fn(usize) -> f64| {
            (0..error_state.len())
                .map(|i| f(i).powi(2))
                .sum::<f64>()
                .sqrt()
        };
        let diff = norm(&|i| strapdown[i] - error_state[i]);
        let scale = norm(&|i| error_state[i]);
        // a NaN (a diverged run) must show, not be skipped by `max`
        let worst = |a: f64, b: f64| {
            if a.is_nan() || b.is_nan() {
                f64::NAN
            } else {
                a.max(b)
            }
        };
        self.max_difference = worst(self.max_difference, diff);
        self.max_error = worst(self.max_error, scale);
    }

    /// max_difference / max_error; NaN when the error-state stays at zero
    /// (nothing to be relative to).
    pub fn relative(&self) -> f64 {
        if self.max_error > 0.0 {
            self.max_difference / self.max_error
        } else {
            f64::NAN
        }
    }
}

/// The comparison: attitude (arcsec), horizontal velocity (m/s),
/// horizontal position (north, east in m), sampled every error-state
/// substep.
#[derive(Debug, Clone, Serialize)]
pub struct Comparison {
    pub system: System,
    pub hours: f64,
    pub sample_rate_hz: f64,
    pub samples: u64,
    pub attitude_arcsec: Agreement,
    pub velocity: Agreement,
    pub position_m: Agreement,
    /// The strapdown's errors at the end, and the error-state's:
    /// attitude E N U (arcsec), velocity E N (m/s), position N E (m).
    pub end_strapdown: [f64; 7],
    pub end_error_state: [f64; 7],
}

/// ENU to NED and back (a proper rotation, its own inverse).
fn enu_ned() -> Matrix3<f64> {
    Matrix3::new(0.0, 1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, -1.0)
}

/// The integral of R(t)^T over [t0, t1] by Simpson's rule, R the scheme's
/// orientation (smooth within a phase; a phase's start or stop inside the
/// interval costs O(dt (rate dt)^2), below 1e-7 of the rate at 100 Hz).
fn integral_of_transpose(
    scheme: &PhasedScheme,
    r0: &Matrix3<f64>,
    t0: f64,
    r1: &Matrix3<f64>,
    dt: f64,
) -> Matrix3<f64> {
    let mid = scheme.orientation(t0 + 0.5 * dt);
    (r0 + mid * 4.0 + r1).transpose() * (dt / 6.0)
}

/// The rotation vector of a rotation by less than 90 deg: the scheme turns
/// about one IMU axis at a time, so the IMU's turn relative to the vehicle
/// over a sample is that of R(t0)^T R(t1). Taken from the skew part,
/// sin(theta) along the axis, which stays finite where the trace formula's
/// acos would see rounding push its argument past 1 (a dwell).
fn rotation_vector(c: &Matrix3<f64>) -> Vector3<f64> {
    let skew = Vector3::new(
        c[(2, 1)] - c[(1, 2)],
        c[(0, 2)] - c[(2, 0)],
        c[(1, 0)] - c[(0, 1)],
    ) * 0.5;
    let sin = skew.norm();
    if sin > 0.0 {
        skew * (sin.min(1.0).asin() / sin)
    } else {
        Vector3::zeros()
    }
}

/// Errors of the strapdown solution against the truth, in the error-state
/// layout (ENU attitude, ENU velocity, latitude and longitude in rad).
fn strapdown_errors(
    computed: &NavState,
    true_attitude: &UnitQuaternion<f64>,
    true_velocity: &Vector3<f64>,
    true_position: &Position,
) -> NavErrors {
    // computed = exp(-phi) truth (the mechanization's convention, its
    // `apply_correction`), so phi = log(truth computed^-1), NED.
    let phi_ned = (true_attitude * computed.attitude.inverse()).scaled_axis();
    let phi = enu_ned() * phi_ned;
    let dv = computed.velocity - true_velocity;
    let mut x = NavErrors::zeros();
    x.fixed_rows_mut::<3>(PHI_E).copy_from(&phi);
    x[DV_E] = dv.y;
    x[DV_N] = dv.x;
    x[D_LAT] = computed.position.lat - true_position.lat;
    x[D_LON] = computed.position.lon - true_position.lon;
    x
}

/// Runs both propagations of `check` over the scenario's route.
pub fn compare(s: &Scenario, check: &Check) -> anyhow::Result<Comparison> {
    s.validate()?;
    let per_substep = check.sample_rate_hz * s.substep;
    if !(check.hours.is_finite() && check.hours > 0.0) {
        anyhow::bail!(
            "the span must be a positive number of hours, got {}",
            check.hours
        );
    }
    if !(per_substep.is_finite()
        && per_substep >= 1.0
        && (per_substep - per_substep.round()).abs() < 1e-9)
    {
        anyhow::bail!(
            "the sample rate must give a whole number of samples per {} s substep, got {} Hz",
            s.substep,
            check.sample_rate_hz
        );
    }
    let course = s.course_deg * DEG;
    let v_north = s.speed * course.cos();
    // The error model is linearised about a constant motion; only an
    // east-west route keeps the latitude (and so the truth) constant.
    if v_north.abs() > 1e-9 {
        anyhow::bail!("the strapdown check needs an east-west route (course 90 or 270 deg)");
    }
    let per_substep = per_substep.round() as usize;
    let dt = s.substep / per_substep as f64;
    let substeps = (check.hours * 3600.0 / s.substep).round() as u64;

    let lat = s.latitude_deg * DEG;
    let start = Position::new(lat, 0.0, 0.0);
    let earth = LocalEarth::at(&start);
    let velocity = Vector3::new(0.0, s.speed * course.sin(), 0.0);
    let omega_ie = earth.earth_rate_n();
    let omega_in = omega_ie + earth.transport_rate_n(&velocity);
    let specific_force =
        (omega_ie * 2.0 + earth.transport_rate_n(&velocity)).cross(&velocity) - earth.gravity_n();
    let lon_rate = velocity.y / (earth.transverse * earth.cos_lat);
    let (sensors, scheme) = match check.system {
        System::Backup => (
            s.backup,
            PhasedScheme::single_axis_four_dwell(Timing::ours()),
        ),
        System::Master => (
            s.master,
            PhasedScheme::dual_axis_sixteen_phase(Timing::ours()),
        ),
    };
    let sensors = if check.sensor_errors {
        Sensors {
            gyro_arw: 0.0,
            accel_vrw: 0.0,
            ..sensors
        }
    } else {
        Sensors {
            gyro_drift: Vector3::zeros(),
            accel_bias: nalgebra::Vector2::zeros(),
            gyro_arw: 0.0,
            accel_vrw: 0.0,
        }
    };
    let initial_phi = if check.sensor_errors {
        check.initial_attitude
    } else {
        Vector3::zeros()
    };
    let gyro_drift = sensors.gyro_drift;
    let accel_bias = Vector3::new(sensors.accel_bias.x, sensors.accel_bias.y, 0.0);

    // Error-state run, as `run.rs` propagates each system (noise off).
    let motion = Motion::uniform(lat, 0.0, s.speed, course, normal_gravity(lat, 0.0));
    let propagation = Propagation::new(&navigation_block::<f64>(&motion), s.substep);
    let mut errors = NavErrors::zeros();
    errors.fixed_rows_mut::<3>(PHI_E).copy_from(&initial_phi);
    let mut ins = Ins { sensors, errors };
    // noise densities are zero: the generator's draws are multiplied by 0
    let mut rng = ChaCha8Rng::seed_from_u64(0);

    // Strapdown run.
    let body_enu = super::run::vehicle(course);
    let body_ned = enu_ned() * body_enu;
    let to_quat = |c: Matrix3<f64>| {
        UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(c))
    };
    let true_attitude = |r: &Matrix3<f64>| to_quat(body_ned * r);
    let mut r0 = scheme.orientation(0.0);
    let erroneous = mwd_core::attitude::quat_from_rotation_vector(&-(enu_ned() * initial_phi))
        * true_attitude(&r0);
    let mut nav = Strapdown::new(
        NavState {
            attitude: erroneous,
            velocity,
            position: start,
        },
        dt,
    );
    let omega_in_vehicle = body_ned.transpose() * omega_in;
    let f_vehicle = body_ned.transpose() * specific_force;

    let mut attitude = Agreement::new();
    let mut vel = Agreement::new();
    let mut pos = Agreement::new();
    let (rn, re_cos) = (earth.meridian, earth.transverse * earth.cos_lat);
    let to_arcsec = 3600.0 / DEG;
    let mut last = (NavErrors::zeros(), NavErrors::zeros());
    let mut samples = 0u64;
    for k in 0..substeps {
        let t_start = k as f64 * s.substep;
        for j in 0..per_substep {
            let t0 = t_start + j as f64 * dt;
            let r1 = scheme.orientation(t0 + dt);
            let mean_transpose = integral_of_transpose(&scheme, &r0, t0, &r1, dt) / dt;
            let turn = rotation_vector(&(r0.transpose() * r1));
            let sample = ImuSample {
                rate: mean_transpose * omega_in_vehicle + turn / dt + gyro_drift,
                specific_force: mean_transpose * f_vehicle + accel_bias,
            };
            nav.step(&sample);
            // hold the vertical channel at the truth (height 0, v_down 0)
            let st = *nav.state();
            nav.apply_correction(
                &Vector3::zeros(),
                &Vector3::new(0.0, 0.0, st.velocity.z),
                // down error = -(height error); `apply_correction` subtracts it
                &Vector3::new(0.0, 0.0, -st.position.height),
            );
            r0 = r1;
            samples += 1;
        }
        let t = t_start + s.substep;
        ins.step(
            &propagation,
            &(body_enu * scheme.orientation(t_start + 0.5 * s.substep)),
            &mut rng,
        );
        let truth_position = Position::new(lat, lon_rate * t, 0.0);
        let x = strapdown_errors(nav.state(), &true_attitude(&r0), &velocity, &truth_position);
        let e = &ins.errors;
        let arcsec = |v: &NavErrors| {
            [
                v[PHI_E] * to_arcsec,
                v[PHI_E + 1] * to_arcsec,
                v[PHI_E + 2] * to_arcsec,
            ]
        };
        let metres = |v: &NavErrors| [v[D_LAT] * rn, v[D_LON] * re_cos];
        attitude.add(&arcsec(&x), &arcsec(e));
        vel.add(&[x[DV_E], x[DV_N]], &[e[DV_E], e[DV_N]]);
        pos.add(&metres(&x), &metres(e));
        last = (x, *e);
    }
    let table = |v: &NavErrors| {
        [
            v[PHI_E] * to_arcsec,
            v[PHI_E + 1] * to_arcsec,
            v[PHI_E + 2] * to_arcsec,
            v[DV_E],
            v[DV_N],
            v[D_LAT] * rn,
            v[D_LON] * re_cos,
        ]
    };
    Ok(Comparison {
        system: check.system,
        hours: check.hours,
        sample_rate_hz: check.sample_rate_hz,
        samples,
        attitude_arcsec: attitude,
        velocity: vel,
        position_m: pos,
        end_strapdown: table(&last.0),
        end_error_state: table(&last.1),
    })
}
