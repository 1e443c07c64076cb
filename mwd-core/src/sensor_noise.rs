//! The probe's sensor error budget, one description shared by the simulator
//! (which draws errors from it) and the alignment (which turns it into
//! uncertainties). SI units throughout.
//!
//! Default figures, with their sources:
//! * gyro white noise: ARW 0.86 deg/sqrt(h), SCC1300 datasheet (paper Table 1);
//! * gyro bias instability: 2.1 deg/h, the datasheet's offset short-term
//!   instability (paper Table 1);
//! * accelerometer white noise: VRW 0.052257815 m/s/sqrt(h), paper Table 2
//!   (Z accelerometer, the one the paper reports);
//! * accelerometer bias instability: 0.000554625 m/s^2, paper Table 2;
//! * coloured noise: the paper's AR(4) fits, Tables 4-5 (`crate::ar`);
//! * residual bias after calibration (run-to-run repeatability): not given
//!   by the paper; project assumptions, 2.1 deg/h (gyro) and 1 mg
//!   (accelerometer), kept here in one place.
//!
//! Bias instability is modelled as a first-order Gauss-Markov process with
//! the stated figure as its standard deviation and [`BIAS_CORRELATION_TIME`]
//! as its correlation time.
use crate::ar::{Ar4, ACCEL_DEFAULTS, GYRO_DEFAULTS};
use crate::conventions::DEG;
use crate::sensor_units::STANDARD_GRAVITY;
/// Correlation time of the Gauss-Markov bias instability (s): an assumption
/// (the datasheet gives no figure); Allan plots of MEMS gyros of this class
/// reach their floor at tens to hundreds of seconds.
pub const BIAS_CORRELATION_TIME: f64 = 100.0;

/// Convert deg/sqrt(h) to rad/sqrt(s).
pub const fn arw_from_deg_per_sqrt_hour(v: f64) -> f64 {
    v * DEG / 60.0
}

/// Convert deg/h to rad/s.
pub const fn rate_from_deg_per_hour(v: f64) -> f64 {
    v * DEG / 3600.0
}

/// Noise and residual errors of one sensor axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AxisNoise {
    /// White-noise density (rad/sqrt(s) for gyros, m/s/sqrt(s) for
    /// accelerometers): a sample at rate fs has sigma = density sqrt(fs).
    pub white_density: f64,
    /// Coloured noise added on top of the white noise.
    pub coloured: Option<Ar4>,
    /// Standard deviation of the Gauss-Markov bias instability (SI).
    pub bias_instability: f64,
    /// Its correlation time (s).
    pub correlation_time: f64,
    /// 1-sigma residual constant bias left after calibration (SI).
    pub residual_bias: f64,
}

impl AxisNoise {
    /// An error-free axis.
    pub const NONE: AxisNoise = AxisNoise {
        white_density: 0.0,
        coloured: None,
        bias_instability: 0.0,
        correlation_time: BIAS_CORRELATION_TIME,
        residual_bias: 0.0,
    };

    /// Standard deviation of the mean of `n` samples taken `dt` apart, from
    /// the parts that vary within a run (white, coloured, Gauss-Markov); the
    /// residual constant bias is separate because it is common to every
    /// segment of a run. Infinite if the coloured model is not stationary.
    pub fn mean_sigma(&self, n: usize, dt: f64) -> f64 {
        let dt_valid = dt > 0.0; // false for NaN too
        if n == 0 || !dt_valid {
            return f64::INFINITY;
        }
        let nf = n as f64;
        let white = self.white_density * self.white_density / dt / nf;
        let coloured = match self.coloured {
            Some(ar) => ar.variance_of_mean(n).unwrap_or(f64::INFINITY),
            None => 0.0,
        };
        // Variance of the mean of a Gauss-Markov process over T:
        // sigma^2 (2 tau / T) (1 - (tau / T)(1 - exp(-T / tau))).
        let gauss_markov = if self.bias_instability > 0.0 && self.correlation_time > 0.0 {
            let ratio = self.correlation_time / (nf * dt);
            self.bias_instability
                * self.bias_instability
                * 2.0
                * ratio
                * (1.0 - ratio * (1.0 - libm::exp(-1.0 / ratio)))
        } else {
            0.0
        };
        libm::sqrt(white + coloured + gauss_markov)
    }
}

/// The error budget of the probe's sensors: accelerometers and rates in
/// body order x, y, z (the y rate is the accelerometer-derived one).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImuNoise {
    pub accel: [AxisNoise; 3],
    pub gyro: [AxisNoise; 3],
}

impl ImuNoise {
    /// No errors at all.
    pub const NONE: ImuNoise = ImuNoise {
        accel: [AxisNoise::NONE; 3],
        gyro: [AxisNoise::NONE; 3],
    };

    /// The SCC1300-D04 figures listed in the module documentation.
    pub const fn scc1300() -> Self {
        let arw = arw_from_deg_per_sqrt_hour(0.86);
        ImuNoise {
            accel: [
                scc1300_accel(ACCEL_DEFAULTS[0]),
                scc1300_accel(ACCEL_DEFAULTS[1]),
                scc1300_accel(ACCEL_DEFAULTS[2]),
            ],
            // The y rate is derived from accelerometer roll, not a gyro: its
            // noise is the paper's fitted model alone.
            gyro: [
                scc1300_gyro(GYRO_DEFAULTS[0], arw),
                scc1300_gyro(GYRO_DEFAULTS[1], 0.0),
                scc1300_gyro(GYRO_DEFAULTS[2], arw),
            ],
        }
    }
}

/// The SCC1300 budget as a static: what a navigator uses unless told
/// otherwise (`probe::Navigator::set_noise_budget`).
pub static SCC1300_NOISE: ImuNoise = ImuNoise::scc1300();

const fn scc1300_gyro(ar: Ar4, white: f64) -> AxisNoise {
    AxisNoise {
        white_density: white,
        coloured: Some(ar),
        bias_instability: rate_from_deg_per_hour(2.1),
        correlation_time: BIAS_CORRELATION_TIME,
        residual_bias: rate_from_deg_per_hour(2.1),
    }
}

const fn scc1300_accel(ar: Ar4) -> AxisNoise {
    AxisNoise {
        white_density: 0.052_257_815 / 60.0,
        coloured: Some(ar),
        bias_instability: 0.000_554_625,
        correlation_time: BIAS_CORRELATION_TIME,
        residual_bias: 1e-3 * STANDARD_GRAVITY,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn white_noise_of_the_mean_falls_as_one_over_root_n() {
        let axis = AxisNoise {
            white_density: 1e-3,
            ..AxisNoise::NONE
        };
        let dt = 0.05;
        let one = axis.mean_sigma(1, dt);
        assert!((one - 1e-3 / libm::sqrt(dt)).abs() < 1e-15);
        assert!((axis.mean_sigma(100, dt) - one / 10.0).abs() < 1e-15);
    }

    #[test]
    fn gauss_markov_mean_limits() {
        let axis = AxisNoise {
            bias_instability: 2.0,
            correlation_time: 100.0,
            ..AxisNoise::NONE
        };
        // Much shorter than tau: the bias barely moves, the mean keeps sigma.
        assert!((axis.mean_sigma(2, 0.05) - 2.0).abs() < 1e-3);
        // Much longer than tau: variance 2 tau / T sigma^2.
        let long = axis.mean_sigma(2_000_000, 0.05);
        let expected = 2.0 * libm::sqrt(2.0 * 100.0 / 100_000.0);
        assert!((long - expected).abs() < 1e-3 * expected);
    }

    #[test]
    fn default_figures_are_the_stated_ones() {
        let n = ImuNoise::scc1300();
        // 0.86 deg/sqrt(h) = 2.5019e-4 rad/sqrt(s).
        assert!((n.gyro[0].white_density - 2.5019e-4).abs() < 1e-7);
        assert!((n.gyro[2].bias_instability - 1.0181e-5).abs() < 1e-8);
        assert!(n
            .gyro
            .iter()
            .all(|g| g.coloured.is_some_and(|ar| ar.is_stationary())));
        assert!(n.accel[2].mean_sigma(100, 0.05).is_finite());
    }
}
