//! Sensor-bias states of the 39-state model (derivation section 3b).
//!
//! The AR(4) states of the paper forget within a few samples; a residual
//! constant bias left after calibration (and the slow Gauss-Markov bias
//! instability) does not. At rest a 1 mg accelerometer bias is
//! indistinguishable from ~0.057 deg of tilt (dv' = f^n x phi + C_b^n b = 0
//! for phiN = (C_b^n b)_E / g, phiE = -(C_b^n b)_N / g), so a filter
//! without bias states reports tilt sigmas it cannot have.
//!
//! Each bias is one state per body axis: a random constant (transition I)
//! with a small random walk standing in for the Gauss-Markov instability.
//! One state cannot hold both exactly (constant + first-order GM is a
//! second-order process); the random walk with the GM's one-step increment
//! variance 2 sigma^2 (1 - exp(-dt/tau)) over-states the GM's drift over
//! T by 2 sigma^2 (T/tau - (1 - exp(-T/tau))) - conservative, and small over
//! an alignment of about a minute against tau = 100 s. Two states per axis
//! (45 in all) would be exact and cost about 30 % more in the time update.
//!
//! Over hours (a drilling probe between stations) the random walk would
//! grow without bound, while the Gauss-Markov process stays within sigma:
//! navigating, the gyro bias states keep the residual constant only and
//! the instability is white rate noise at its zero-frequency density
//! `instability_density` = 2 sigma^2 tau, which bounds its spectrum
//! (`fine_alignment::BiasWalk::InstabilityAsRateNoise`, derivation section
//! 4h).

use crate::sensor_noise::{AxisNoise, ImuNoise};

/// Statistics of one bias state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BiasState {
    /// Initial 1-sigma: residual constant bias and the Gauss-Markov
    /// instability's stationary sigma, root-sum-squared (SI units).
    pub initial_sigma: f64,
    /// Random-walk variance added per step (SI units squared).
    pub variance_per_step: f64,
    /// The Gauss-Markov instability's stationary sigma (SI units).
    pub instability_sigma: f64,
    /// Its spectral density at zero frequency, 2 sigma^2 tau (SI units
    /// squared times seconds): the white noise whose spectrum bounds the
    /// instability's at every frequency.
    pub instability_density: f64,
}

impl BiasState {
    /// From one axis of the error budget at sample interval `dt`.
    pub fn from_axis(axis: &AxisNoise, dt: f64) -> Self {
        let gm = axis.bias_instability;
        let step_correlation = if axis.correlation_time > 0.0 {
            libm::exp(-dt / axis.correlation_time)
        } else {
            1.0
        };
        // Var(b(t + dt) - b(t)) of a stationary first-order GM process.
        let step_increment = 2.0 * gm * gm * (1.0 - step_correlation);
        Self {
            initial_sigma: libm::sqrt(axis.residual_bias * axis.residual_bias + gm * gm),
            variance_per_step: step_increment,
            instability_sigma: gm,
            instability_density: 2.0 * gm * gm * axis.correlation_time.max(0.0),
        }
    }
}

/// The six bias states: accelerometers and rates, body x, y, z.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SensorBiases {
    pub accel: [BiasState; 3],
    pub gyro: [BiasState; 3],
}

impl SensorBiases {
    /// From the project's error budget (`sensor_noise`).
    pub fn from_noise(noise: &ImuNoise, dt: f64) -> Self {
        Self {
            accel: noise.accel.map(|a| BiasState::from_axis(&a, dt)),
            gyro: noise.gyro.map(|g| BiasState::from_axis(&g, dt)),
        }
    }
}
