//! The probe's sensor sample in the body frame: the one type that says the
//! probe has gyros across the tool axis only.
//!
//! Each SCC1300 part has one gyro (one part senses body x, the other body
//! z) and one accelerometer triad. Nothing senses the rate about the tool
//! axis (body y): the coarse alignment works with the two rates there are,
//! and the mechanization takes the tool-axis rate from the accelerometer
//! roll or, at rest, from the earth's rotation
//! (`crate::mechanization::ProbeInput`).

use nalgebra::Vector3;

/// The body axes that have a gyro, in the order of [`ProbeSample::gyro`]:
/// x (index 0) and z (index 2).
pub const GYRO_AXES: [usize; 2] = [0, 2];

/// One calibrated sample of the probe's sensors, body frame.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct ProbeSample {
    /// Angular rates omega_ib about the body axes of [`GYRO_AXES`] (x, z),
    /// rad/s.
    pub gyro: [f64; 2],
    /// Specific force f_ib^b (m/s^2): both parts' triads averaged.
    pub specific_force: Vector3<f64>,
}

impl ProbeSample {
    pub fn new(rate_x: f64, rate_z: f64, specific_force: Vector3<f64>) -> Self {
        Self {
            gyro: [rate_x, rate_z],
            specific_force,
        }
    }

    /// Rate about body x (rad/s).
    pub fn rate_x(&self) -> f64 {
        self.gyro[0]
    }

    /// Rate about body z (rad/s).
    pub fn rate_z(&self) -> f64 {
        self.gyro[1]
    }

    /// The body-frame rate vector with `tool_axis_rate` about y.
    pub fn rate_with_tool_axis(&self, tool_axis_rate: f64) -> Vector3<f64> {
        Vector3::new(self.gyro[0], tool_axis_rate, self.gyro[1])
    }

    /// True when every value is finite.
    pub fn is_finite(&self) -> bool {
        self.gyro
            .iter()
            .chain(self.specific_force.iter())
            .all(|v| v.is_finite())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_gyros_sit_on_body_x_and_z() {
        let s = ProbeSample::new(1.0, 3.0, Vector3::new(0.1, 0.2, 9.8));
        let rate = s.rate_with_tool_axis(2.0);
        assert_eq!(rate, Vector3::new(1.0, 2.0, 3.0));
        for (k, axis) in GYRO_AXES.into_iter().enumerate() {
            assert_eq!(rate[axis], s.gyro[k]);
        }
        assert!(s.is_finite());
        let bad = ProbeSample::new(f64::NAN, 0.0, Vector3::zeros());
        assert!(!bad.is_finite());
    }
}
