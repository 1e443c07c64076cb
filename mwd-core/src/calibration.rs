//! The probe-side sensor correction step: deterministic errors found by the
//! host's six-position calibration (paper section 3.2, Table 3) or by the TLS
//! decoupling (TLS paper eq. 20-23) are removed from every raw sample here.
//!
//! One type serves the host calibration, the simulator and the probe, so
//! that a calibration file means the same thing everywhere. No heap, no
//! transcendental functions: the correction is an affine map.

use crate::probe_sample::ProbeSample;
use nalgebra::Vector3;

/// Correction of one accelerometer triad: `corrected = M (raw - bias)`.
///
/// `bias` is in the sensor's output units (m/s^2 for accelerometers);
/// `correction` is the inverse of the scale-factor-and-misalignment matrix
/// `K` of the error model `raw = K true + bias`, so that `M K = I`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriadCalibration {
    /// Zero offset of each axis (raw units).
    pub bias: [f64; 3],
    /// Row-major `M = K^-1`: undoes scale factor and misalignment.
    pub correction: [[f64; 3]; 3],
}

impl TriadCalibration {
    /// No correction at all: `apply` returns its input unchanged.
    pub const IDENTITY: Self = Self {
        bias: [0.0; 3],
        correction: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
    };

    /// Corrected triad reading `M (raw - bias)`.
    pub fn apply(&self, raw: [f64; 3]) -> [f64; 3] {
        let d = [
            raw[0] - self.bias[0],
            raw[1] - self.bias[1],
            raw[2] - self.bias[2],
        ];
        let mut out = [0.0; 3];
        for (o, row) in out.iter_mut().zip(self.correction.iter()) {
            *o = row[0] * d[0] + row[1] * d[1] + row[2] * d[2];
        }
        out
    }

    /// Single-precision entry for the probe's f32 filter path; the
    /// arithmetic is done in f64 so both paths agree to f32 rounding.
    pub fn apply_f32(&self, raw: [f32; 3]) -> [f32; 3] {
        let c = self.apply([raw[0] as f64, raw[1] as f64, raw[2] as f64]);
        [c[0] as f32, c[1] as f32, c[2] as f32]
    }
}

impl Default for TriadCalibration {
    fn default() -> Self {
        Self::IDENTITY
    }
}

/// Correction of one single-axis gyro: `corrected = (raw - bias) / scale`.
/// The SCC1300 gyro is single-axis; its misalignment is not separable from
/// a static six-position test and is left to the filter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GyroCalibration {
    /// Zero-rate offset (rad/s).
    pub bias: f64,
    /// Scale factor (dimensionless, 1 = nominal).
    pub scale: f64,
}

impl GyroCalibration {
    /// No correction.
    pub const IDENTITY: Self = Self {
        bias: 0.0,
        scale: 1.0,
    };

    /// Corrected rate; a zero scale (a corrupt calibration) leaves the
    /// reading uncorrected for scale rather than dividing by zero.
    pub fn apply(&self, raw: f64) -> f64 {
        let d = raw - self.bias;
        if self.scale == 0.0 || !self.scale.is_finite() {
            d
        } else {
            d / self.scale
        }
    }
}

impl Default for GyroCalibration {
    fn default() -> Self {
        Self::IDENTITY
    }
}

/// Everything the probe corrects: the two SCC1300 parts, each with one gyro
/// (sensing body x on the pitch board, body z on the azimuth board) and one
/// accelerometer triad.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct ProbeCalibration {
    /// Accelerometer triads of the two parts, in the order [x-gyro part, z-gyro part].
    pub accel: [TriadCalibration; 2],
    /// Gyros sensing body x and body z.
    pub gyro: [GyroCalibration; 2],
}

impl ProbeCalibration {
    /// The probe's sample from its readings in body axes: the x and z gyro
    /// rates and each part's accelerometer triad. Each is corrected with
    /// its own calibration (fitted in body axes); both triads feel the same
    /// body force, so they are then averaged. The probe and the host's
    /// tools all go through here.
    pub fn correct(&self, rate_x: f64, rate_z: f64, accel_body: &[[f64; 3]; 2]) -> ProbeSample {
        let mut force = Vector3::zeros();
        for (triad, calibration) in accel_body.iter().zip(&self.accel) {
            force += 0.5 * Vector3::from(calibration.apply(*triad));
        }
        ProbeSample::new(
            self.gyro[0].apply(rate_x),
            self.gyro[1].apply(rate_z),
            force,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn identity_leaves_input_unchanged() {
        let raw = [0.1, -9.8, 3.25];
        assert_eq!(TriadCalibration::default().apply(raw), raw);
        assert_eq!(GyroCalibration::default().apply(1.5e-4), 1.5e-4);
    }

    #[test]
    fn undoes_a_known_error_model() {
        // raw = K true + b with a small misalignment and scale error.
        let k = [
            [1.002, 0.001, -0.0005],
            [0.0007, 0.998, 0.0012],
            [-0.0003, 0.0009, 1.001],
        ];
        let b = [0.007, -0.02, 0.0024];
        // M = K^-1 by the adjugate (3x3 only, exact enough for a test).
        let det = k[0][0] * (k[1][1] * k[2][2] - k[1][2] * k[2][1])
            - k[0][1] * (k[1][0] * k[2][2] - k[1][2] * k[2][0])
            + k[0][2] * (k[1][0] * k[2][1] - k[1][1] * k[2][0]);
        let mut m = [[0.0; 3]; 3];
        for (i, row) in m.iter_mut().enumerate() {
            for (j, v) in row.iter_mut().enumerate() {
                let (r0, r1) = ((j + 1) % 3, (j + 2) % 3);
                let (c0, c1) = ((i + 1) % 3, (i + 2) % 3);
                *v = (k[r0][c0] * k[r1][c1] - k[r0][c1] * k[r1][c0]) / det;
            }
        }
        let cal = TriadCalibration {
            bias: b,
            correction: m,
        };
        let truth = [0.3, -9.7, 1.2];
        let mut raw = b;
        for (r, row) in raw.iter_mut().zip(k.iter()) {
            *r += row[0] * truth[0] + row[1] * truth[1] + row[2] * truth[2];
        }
        let c = cal.apply(raw);
        for (ci, ti) in c.iter().zip(truth.iter()) {
            assert!((ci - ti).abs() < 1e-12, "{c:?} vs {truth:?}");
        }
        let c32 = cal.apply_f32([raw[0] as f32, raw[1] as f32, raw[2] as f32]);
        for (ci, ti) in c32.iter().zip(truth.iter()) {
            assert!((*ci as f64 - ti).abs() < 1e-5);
        }
    }

    #[test]
    fn gyro_bias_and_scale() {
        let g = GyroCalibration {
            bias: -3.7e-4,
            scale: 1.01,
        };
        assert!((g.apply(1.01 * 2e-4 - 3.7e-4) - 2e-4).abs() < 1e-15);
        let broken = GyroCalibration {
            bias: 1e-4,
            scale: 0.0,
        };
        assert!((broken.apply(3e-4) - 2e-4).abs() < 1e-18);
    }
}
