//! The rate gyrocompass at a station (docs/filter-derivation.md section
//! 4e): a still probe's gyros see the earth's rotation C_n^b omega_ie^n
//! plus their biases, so each gyro's block mean against the earth rate
//! computed at the filter's attitude measures its bias and the attitude
//! error together.
//!
//! The probe has gyros on body x and z only. For each, a in {x, z}, with g_a
//! what it measures (calibrated) and w = C~_n^b omega_ie^n at the computed
//! attitude, the residual r_a = g_a - w_a is (section 1's conventions,
//! C~_b^n = (I - [phi x]) C_b^n, so C~_n^b = C_n^b (I + [phi x]))
//!
//!   r_a = b_a + n_a - c_a . (phi x omega) = b_a + n_a + (c_a x omega) . phi
//!
//! with c_a = C_b^n e_a the gyro's axis in the navigation frame: H is
//! c_a x omega_ie^n on phi and 1 on the rate-bias state a. Both shares of
//! the earth rate are in it: the vertical one (the bias, whatever the
//! azimuth) and the horizontal one, Omega cos(lat) times the sine or cosine
//! of the azimuth for a gyro across the tool axis and horizontal (the
//! heading, directly from the gyros instead of through the tilt they
//! drive).
//!
//! The attitude error is a state here, not noise: the old vertical-only
//! update put Omega^2 sigma_phi^2 into each block's R as if independent
//! from block to block, which it is not (one attitude error per station).
//!
//! Two scalar rows, x and z, not the down/horizontal pair: each row's noise
//! is one gyro's, and the two parts' noises are independent, so R is
//! diagonal and the sequential scalar updates are exact; rotated to
//! down/horizontal the noises mix (the x and z gyros' budgets differ) and
//! would need decorrelating first, for the same information at the same
//! two scalar updates.

use crate::error_model::{ATT, GYRO_BIAS};
use crate::kalman::{FilterScalar, Measurement, ScalarMeasurement, SparseRow};
use crate::probe_sample::GYRO_AXES;
use crate::sensor_noise::AxisNoise;
use nalgebra::{Matrix3, Vector3};

/// One block's rate gyrocompass: per gyro (x, z) a scalar.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EarthRate<T> {
    /// Block means of g_a - w_a (rad/s), w at the attitude the filter's
    /// error phi refers to (the current estimate).
    pub residual: [T; 2],
    /// d r_a / d phi = c_a x omega_ie^n (nav frame; s^-1).
    pub attitude_row: [[T; 3]; 2],
    /// Noise variance of each block mean, (rad/s)^2.
    pub variance: [T; 2],
}

impl EarthRate<f64> {
    /// The block's measurement from the gyros' block means `gyro_mean`
    /// (x, z; rad/s) over `samples` still samples, the current attitude
    /// `c_bn` (the residual's), the attitude `linearized_c_bn` the
    /// filter's error model is linearised at (H's), the earth rate
    /// `omega_n` (NED, rad/s) and each gyro's long-run variance per sample
    /// ([`long_run_variance`]). The residual is computed once, at the
    /// attitude of the update: the tool is still, so its true rate is the
    /// same in every sample of the block and the mean's error is the
    /// attitude error of now, not a mixture of the block's estimates.
    pub fn from_block(
        gyro_mean: [f64; 2],
        samples: u32,
        c_bn: &Matrix3<f64>,
        linearized_c_bn: &Matrix3<f64>,
        omega_n: &Vector3<f64>,
        long_run_variance: [f64; 2],
    ) -> Self {
        let n = f64::from(samples.max(1));
        let w = predicted_rates(c_bn, omega_n);
        let rows = attitude_rows(linearized_c_bn, omega_n);
        Self {
            residual: [gyro_mean[0] - w[0], gyro_mean[1] - w[1]],
            attitude_row: rows.map(|r| [r.x, r.y, r.z]),
            variance: long_run_variance.map(|v| v / n),
        }
    }

    /// The same in the filter's scalar.
    pub fn cast<T: FilterScalar>(&self) -> EarthRate<T> {
        EarthRate {
            residual: self.residual.map(T::of),
            attitude_row: self.attitude_row.map(|r| r.map(T::of)),
            variance: self.variance.map(T::of),
        }
    }
}

/// The earth rate the x and z gyros of a still tool at attitude `c_bn` see:
/// (C_n^b omega_ie^n)_a = c_a . omega_ie^n.
pub fn predicted_rates(c_bn: &Matrix3<f64>, omega_n: &Vector3<f64>) -> [f64; 2] {
    GYRO_AXES.map(|a| c_bn.column(a).dot(omega_n))
}

/// d r_a / d phi for the x and z gyros: c_a x omega_ie^n (module
/// documentation).
pub fn attitude_rows(c_bn: &Matrix3<f64>, omega_n: &Vector3<f64>) -> [Vector3<f64>; 2] {
    GYRO_AXES.map(|a| c_bn.column(a).cross(omega_n))
}

/// A gyro's long-run variance per sample, (rad/s)^2, `dt` apart: white
/// density^2 / dt, its AR model's zero-frequency share sigma_e^2 / (1 +
/// sum a_i)^2, and the bias instability's 2 sigma^2 tau / dt (the variance
/// of an n-sample mean is this over n for large n). The instability is in
/// because navigating the filter's rate-bias states are the constant part
/// only (`fine_alignment::BiasWalk::InstabilityAsRateNoise`, derivation
/// section 4h), and a block's mean holds its value of the moment.
pub fn long_run_variance(noise: &AxisNoise, dt: f64) -> f64 {
    let white = noise.white_density * noise.white_density / dt;
    let coloured = noise.coloured.map_or(0.0, |ar| {
        let gain = 1.0 + ar.coefficients.iter().sum::<f64>();
        ar.noise_variance / (gain * gain)
    });
    let instability =
        2.0 * noise.bias_instability * noise.bias_instability * noise.correlation_time / dt;
    white + coloured + instability
}

impl<T: FilterScalar> Measurement<T> for EarthRate<T> {
    fn len(&self) -> usize {
        2
    }
    fn scalar(&self, k: usize) -> Option<ScalarMeasurement<T>> {
        let axis = *GYRO_AXES.get(k)?;
        let mut h = SparseRow::empty();
        for (i, coef) in self.attitude_row[k].iter().enumerate() {
            h.push(ATT + i, *coef);
        }
        h.push(GYRO_BIAS + axis, T::one());
        Some(ScalarMeasurement {
            z: self.residual[k],
            h,
            r: self.variance[k],
        })
    }
}

#[cfg(test)]
#[path = "earth_rate_tests.rs"]
mod tests;
