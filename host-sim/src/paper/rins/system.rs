//! One rotational INS as an error-state simulation: its attitude, velocity
//! and position errors (ENU, the paper's frame) propagated by the
//! navigation block of `mwd_core::redundant` (eq. 12-17), driven by its
//! constant sensor errors and white noise projected through the rotating
//! IMU's orientation C_b^n(t) = C_vehicle C_rot(t).
//!
//! This replaces a full strapdown mechanization of each system at 20 Hz:
//! the errors of a navigation-grade INS stay small enough (arc-seconds,
//! metres) for the linear model to hold over 120 h, and all the rotation
//! does to them is turn the sensor errors with C_b^n. The substep (1 s by
//! default) resolves the rotations (10 deg per step at 10 deg/s); the
//! forcing is taken at mid-step.

use mwd_core::redundant::index::{DV_E, PHI_E};
use nalgebra::{Matrix3, SMatrix, SVector, Vector2, Vector3};
use rand::Rng;
use rand_distr::StandardNormal;

/// Navigation error states: attitude 3, velocity 2, position 2.
pub type NavErrors = SVector<f64, 7>;

/// The constant sensor errors and noise densities of one system (SI).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sensors {
    /// Gyro drift, IMU x y z (rad/s).
    pub gyro_drift: Vector3<f64>,
    /// Horizontal accelerometer bias, IMU x y (m/s^2); the paper gives no
    /// vertical one and neither model has it.
    pub accel_bias: Vector2<f64>,
    /// Angle random walk (rad/sqrt(s)).
    pub gyro_arw: f64,
    /// Velocity random walk (m/s/sqrt(s)).
    pub accel_vrw: f64,
}

/// One system's true errors.
#[derive(Debug, Clone, PartialEq)]
pub struct Ins {
    pub sensors: Sensors,
    pub errors: NavErrors,
}

/// The discrete propagation of the navigation block over one substep:
/// Phi = exp(F dt) and Gamma = integral of exp(F s) ds over the step (for
/// a forcing held constant over it).
#[derive(Debug, Clone)]
pub struct Propagation {
    pub phi: SMatrix<f64, 7, 7>,
    pub gamma: SMatrix<f64, 7, 7>,
    pub dt: f64,
}

impl Propagation {
    pub fn new(f: &SMatrix<f64, 7, 7>, dt: f64) -> Self {
        let phi = mwd_core::redundant::transition(f, dt);
        // Gamma = dt (I + A/2 + A^2/6 + A^3/24 + A^4/120), A = F dt
        let a = f * dt;
        let identity = SMatrix::<f64, 7, 7>::identity();
        let mut sum = identity;
        for k in (2..=5).rev() {
            sum = identity + a * sum / k as f64;
        }
        Self {
            phi,
            gamma: sum * dt,
            dt,
        }
    }
}

impl Ins {
    /// The sensor errors' forcing of the navigation errors for the IMU
    /// orientation `c` (body to ENU): -C eps on the attitude, the east and
    /// north rows of C (nabla_x, nabla_y, 0) on the velocity (eq. 11, 18).
    pub fn forcing(sensors: &Sensors, c: &Matrix3<f64>) -> NavErrors {
        let mut u = NavErrors::zeros();
        u.fixed_rows_mut::<3>(PHI_E)
            .copy_from(&(-c * sensors.gyro_drift));
        let bias = c * Vector3::new(sensors.accel_bias.x, sensors.accel_bias.y, 0.0);
        u[DV_E] = bias.x;
        u[DV_E + 1] = bias.y;
        u
    }

    /// One substep with the orientation `c_mid` at its middle.
    pub fn step<R: Rng>(&mut self, p: &Propagation, c_mid: &Matrix3<f64>, rng: &mut R) {
        let u = Self::forcing(&self.sensors, c_mid);
        let mut w = NavErrors::zeros();
        let sd_g = self.sensors.gyro_arw * p.dt.sqrt();
        let sd_a = self.sensors.accel_vrw * p.dt.sqrt();
        let gyro: Vector3<f64> =
            Vector3::from_fn(|_, _| sd_g * rng.sample::<f64, _>(StandardNormal));
        let accel = Vector3::new(
            sd_a * rng.sample::<f64, _>(StandardNormal),
            sd_a * rng.sample::<f64, _>(StandardNormal),
            0.0,
        );
        w.fixed_rows_mut::<3>(PHI_E).copy_from(&(-c_mid * gyro));
        let a = c_mid * accel;
        w[DV_E] = a.x;
        w[DV_E + 1] = a.y;
        self.errors = p.phi * self.errors + p.gamma * u + w;
    }
}
