//! Gyro-bias update at a station from the vertical earth rate
//! (docs/filter-derivation.md section 4e): a still probe's gyros, projected
//! on the local vertical, see the earth's vertical rate -Omega sin(lat)
//! (NED down component) whatever the azimuth, plus their biases.
//!
//! The probe has gyros on body x and z only. With d = C_n^b e_D (the down
//! direction in body axes) and w = C_n^b omega_ie^n, the two gyros' share of
//! the vertical is m = d_x (g_x - w_x) + d_z (g_z - w_z), where g is what
//! they measure (calibrated). The true w makes m = d_x b_x + d_z b_z + noise:
//! the biases along the vertical's projection on the gyro plane. w's
//! azimuth-dependent part is only the tool axis's: -d_y (t . omega_ie), and
//! d_y = cos(inclination), so at a lateral (inclination ~90 deg) the
//! azimuth hardly enters (below, in R). A new toolface turns d in the x-z
//! plane, so connections that turn the toolface make both biases
//! observable (the MGWD paper's conclusion: rotary in-drilling alignment).
//!
//! The navigator averages m, d over a station's still cycles and makes one
//! update when the station ends: H = (d_x, d_z) on the x and z rate-bias
//! states, R from the noise budget (`VerticalEarthRate::variance`).

use crate::error_model::GYRO_BIAS;
use crate::kalman::{FilterScalar, Measurement, ScalarMeasurement, SparseRow};

/// The station's averaged measurement.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VerticalEarthRate<T> {
    /// Mean of d_x (g_x - w_x) + d_z (g_z - w_z) (rad/s).
    pub vertical_residual: T,
    /// Mean d_x, d_z.
    pub down_in_gyro_plane: [T; 2],
    /// Noise variance, (rad/s)^2.
    pub variance: T,
}

impl<T: FilterScalar> VerticalEarthRate<T> {
    /// The noise of the station mean, (rad/s)^2, as the sum of:
    /// - each gyro's noise over the mean of `samples` samples `dt` apart:
    ///   its long-run (zero-frequency) variance per sample over the count,
    ///   `long_run_variance[a]` (white density^2 / dt plus the AR model's
    ///   sigma_e^2 / (1 + sum a_i)^2), weighted by d_a^2;
    /// - the attitude's share: w is computed at the filter's attitude, whose
    ///   error phi moves w by at most Omega |phi| (|w| = Omega); the tilt
    ///   enters whole, the azimuth through the tool axis's part, d_y
    ///   (t . omega_ie) with d_y = cos(inclination) (module documentation).
    pub fn variance(
        down_in_gyro_plane: [f64; 2],
        long_run_variance: [f64; 2],
        samples: u32,
        tilt_sigma: f64,
        cos_inclination: f64,
        azimuth_sigma: f64,
    ) -> f64 {
        let n = f64::from(samples.max(1));
        let gyro: f64 = (0..2)
            .map(|a| down_in_gyro_plane[a] * down_in_gyro_plane[a] * long_run_variance[a] / n)
            .sum();
        let omega = crate::earth::EARTH_RATE;
        let azimuth = cos_inclination * azimuth_sigma;
        gyro + omega * omega * (tilt_sigma * tilt_sigma + azimuth * azimuth)
    }
}

/// Body axes of the two gyros: x and z.
const GYRO_BODY_AXES: [usize; 2] = [0, 2];

impl<T: FilterScalar> Measurement<T> for VerticalEarthRate<T> {
    fn len(&self) -> usize {
        1
    }
    fn scalar(&self, k: usize) -> Option<ScalarMeasurement<T>> {
        if k != 0 {
            return None;
        }
        let mut h = SparseRow::empty();
        for (d, axis) in self.down_in_gyro_plane.iter().zip(GYRO_BODY_AXES) {
            h.push(GYRO_BIAS + axis, *d);
        }
        Some(ScalarMeasurement {
            z: self.vertical_residual,
            h,
            r: self.variance,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_row_sits_on_the_x_and_z_rate_biases() {
        let m = VerticalEarthRate::<f64> {
            vertical_residual: 1e-5,
            down_in_gyro_plane: [0.6, -0.8],
            variance: 1e-12,
        };
        let s = m.scalar(0).unwrap();
        extern crate std;
        let entries: std::vec::Vec<_> = s.h.entries().collect();
        assert_eq!(entries, [(GYRO_BIAS, 0.6), (GYRO_BIAS + 2, -0.8)]);
        assert!(m.scalar(1).is_none());
    }

    #[test]
    fn the_variance_falls_with_the_samples_and_keeps_the_attitude_share() {
        let v = |n| VerticalEarthRate::<f64>::variance([0.0, 1.0], [1e-6, 1e-6], n, 1e-3, 0.0, 0.1);
        assert!((v(1) - 1e-6 - (7.292115e-5f64 * 1e-3).powi(2)).abs() < 1e-18);
        assert!(v(1000) < v(10));
        assert!(v(u32::MAX) >= (7.292115e-5f64 * 1e-3).powi(2));
    }
}
