//! The redundant-RINS paper's semi-physical simulation (section 4.1)
//! reproduced: a dual-axis master and a single-axis backup over 120 h, the
//! reduced and the full filter learning the backup's azimuth drift from
//! their difference, the master failing at hour 16, the backup compensated
//! by the prediction model after that (`host-sim paper rins`). The model
//! and the equations are `mwd_core::redundant`'s; `docs/redundant-rins.md`
//! has the whole account.

pub mod filters;
pub mod plot;
pub mod rotation;
mod run;
pub mod strapdown_check;
pub mod system;

pub use run::{run, Record, Results, Summary};

use mwd_core::conventions::DEG;
use nalgebra::{Vector2, Vector3};
use system::Sensors;

/// One g for the micro-g figures (the paper's unit; standard gravity).
const G0: f64 = 9.806_65;

/// The scenario; [`Scenario::paper`] has the paper's figures and our
/// choices where it gives none.
#[derive(Debug, Clone, PartialEq)]
pub struct Scenario {
    /// Length of the run and the master's failure (h).
    pub hours: f64,
    pub failure_hour: f64,
    /// Simulation substep and filter step (s); the filter step is a whole
    /// number of substeps.
    pub substep: f64,
    pub filter_step: f64,
    /// Latitude (deg), speed (m/s) and course (deg) of the vehicle's uniform
    /// motion (the paper's observability case). Course 90 deg (east) keeps
    /// the latitude and so the model constant.
    pub latitude_deg: f64,
    pub speed: f64,
    pub course_deg: f64,
    /// Backup (single-axis) and master (dual-axis) sensors.
    pub backup: Sensors,
    pub master: Sensors,
    /// Initial attitude error of each system, 1 sigma, level and azimuth
    /// (rad).
    pub initial_attitude: [f64; 2],
    /// Measurement noise of the difference, velocity (m/s) and position
    /// (m).
    pub velocity_sigma: f64,
    pub position_sigma_m: f64,
    /// Seed of the noise and the initial errors.
    pub seed: u64,
    /// Seconds between recorded points.
    pub record_every: f64,
}

/// A gyro drift in deg/h as rad/s.
pub fn deg_per_hour(x: f64) -> f64 {
    x * DEG / 3600.0
}

impl Scenario {
    /// Section 4.1: ARW 0.001 deg/sqrt(h), accelerometer noise 20 ug/sqrt(Hz)
    /// (the paper's upper bounds, used as the values), drifts and biases as
    /// printed, 120 h, failure at hour 16. Ours: 32 deg N, 5 m/s due east,
    /// 1 s substeps, 10 s filter steps, initial attitude errors 5 arcsec
    /// level and 20 arcsec azimuth, measurement noise 0.01 m/s and 1 m.
    pub fn paper() -> Self {
        let arw = 0.001 * DEG / 60.0; // deg/sqrt(h) -> rad/sqrt(s)
        let vrw = 20e-6 * G0; // ug/sqrt(Hz) -> m/s/sqrt(s)
        let sensors = |drift: [f64; 3], bias: [f64; 2]| Sensors {
            gyro_drift: Vector3::from(drift.map(deg_per_hour)),
            accel_bias: Vector2::from(bias.map(|b| b * 1e-6 * G0)),
            gyro_arw: arw,
            accel_vrw: vrw,
        };
        Self {
            hours: 120.0,
            failure_hour: 16.0,
            substep: 1.0,
            filter_step: 10.0,
            latitude_deg: 32.0,
            speed: 5.0,
            course_deg: 90.0,
            backup: sensors([0.003, -0.002, 0.0003], [20.0, -40.0]),
            master: sensors([0.004, -0.005, 0.003], [20.0, -30.0]),
            initial_attitude: [5.0 * DEG / 3600.0, 20.0 * DEG / 3600.0],
            velocity_sigma: 0.01,
            position_sigma_m: 1.0,
            seed: 1,
            record_every: 600.0,
        }
    }

    /// Checks the numbers a user can set; the error says which is wrong.
    pub fn validate(&self) -> anyhow::Result<()> {
        let positive = [
            ("hours", self.hours),
            ("substep", self.substep),
            ("filter step", self.filter_step),
            ("record interval", self.record_every),
        ];
        for (name, v) in positive {
            if !(v.is_finite() && v > 0.0) {
                anyhow::bail!("{name} must be a positive number, got {v}");
            }
        }
        if !(self.failure_hour.is_finite()
            && self.failure_hour >= 0.0
            && self.failure_hour <= self.hours)
        {
            anyhow::bail!(
                "the failure hour must lie within the run (0 to {} h), got {}",
                self.hours,
                self.failure_hour
            );
        }
        let ratio = self.filter_step / self.substep;
        if (ratio - ratio.round()).abs() > 1e-9 || ratio < 1.0 {
            anyhow::bail!("the filter step must be a whole number of substeps");
        }
        // NaN fails the range check too
        if !(-85.0..85.0).contains(&self.latitude_deg) {
            anyhow::bail!(
                "latitude must be within +-85 deg (the model's tan L), got {}",
                self.latitude_deg
            );
        }
        if !(self.speed.is_finite() && self.speed >= 0.0 && self.course_deg.is_finite()) {
            anyhow::bail!("speed must be a non-negative number and the course finite");
        }
        Ok(())
    }
}
