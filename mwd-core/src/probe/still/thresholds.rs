//! The detector's window and hysteresis, and its thresholds from the
//! noise budget: each quadratic statistic as `c chi^2(nu)` with its
//! moments from the noise's autocorrelation (Satterthwaite), the quantiles
//! by Wilson-Hilferty (module notes of `still`).

use crate::probe_sample::GYRO_AXES;
use crate::protocol::uplink::StillSettings;
use crate::sensor_noise::{AxisNoise, ImuNoise};
use crate::sensor_units::{ACCEL_LSB_PER_G, GYRO_LSB_PER_DEG_S, STANDARD_GRAVITY};
use crate::timing::SAMPLE_INTERVAL_S;

/// Samples in the detector's window: 1 s at 20 Hz.
pub const WINDOW: usize = 20;
/// Consecutive passing epochs (after a full window) before "still".
pub const ENTER_EPOCHS: u32 = 20;
/// Samples from the first still sample to the still decision when no
/// window fails: the detection delay, 1.95 s.
pub const DETECTION_DELAY_SAMPLES: u32 = WINDOW as u32 + ENTER_EPOCHS - 1;
/// Standard normal quantile of the entering tests' false-alarm probability
/// (one-sided 1e-3).
pub const Z_ENTER: f64 = 3.090;
/// Standard normal quantile of the staying tests' false-alarm probability
/// (one-sided 1e-7).
pub const Z_STAY: f64 = 5.199;

/// The detector's hysteresis: the standard normal quantiles of the
/// entering and staying tests' false-alarm probabilities and the passing
/// epochs to enter. The defaults are the constants above; the uplink can
/// set others (`protocol::uplink::StillSettings`, command 0x44).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hysteresis {
    pub z_enter: f64,
    pub z_stay: f64,
    pub enter_epochs: u32,
}

impl Hysteresis {
    pub const DEFAULT: Self = Self {
        z_enter: Z_ENTER,
        z_stay: Z_STAY,
        enter_epochs: ENTER_EPOCHS,
    };

    /// The hysteresis the uplink's settings ask for (their ranges were
    /// checked when decoded: `protocol::uplink::fields`).
    pub fn from_settings(settings: &StillSettings) -> Self {
        Self {
            z_enter: widened_setting(settings.z_enter, Z_ENTER),
            z_stay: widened_setting(settings.z_stay, Z_STAY),
            enter_epochs: u32::from(settings.enter_epochs),
        }
    }
}

/// A setting the wire carries as f32, in f64. The wire's default is the
/// f64 constant rounded to f32 (`config::default_still_settings`); that
/// value stands for the constant itself, so a probe with the default
/// settings computes with exactly the constants (bit-identical to a
/// navigator built without settings: the capture replays and the QEMU
/// drilling test compare bits). Any other value is taken as it is.
pub fn widened_setting(wire: f32, constant: f64) -> f64 {
    if wire == constant as f32 {
        constant
    } else {
        f64::from(wire)
    }
}

/// A statistic's threshold pair and its expected value under stillness.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Threshold {
    pub enter: f64,
    pub stay: f64,
    /// E[T] when still (to normalise the statistic: 1 = noise only).
    pub expected: f64,
}

/// The detector's thresholds, from the noise budget.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StillThresholds {
    /// Rate magnitude statistic (dimensionless).
    pub rate: Threshold,
    /// Force variance statistic (dimensionless).
    pub force: Threshold,
    /// Bound on | |mean f| - g | (m/s^2).
    pub gravity: Threshold,
    /// Per-sample variance of each gyro (body x, z), (rad/s)^2.
    pub rate_variance: [f64; 2],
    /// Per-sample variance of each force axis, (m/s^2)^2.
    pub force_variance: [f64; 3],
    /// The gravity the magnitude is compared with (m/s^2).
    pub gravity_m_s2: f64,
    /// Consecutive passing epochs (after a full window) before "still".
    pub enter_epochs: u32,
}

/// Wilson-Hilferty chi-square quantile at the standard normal quantile z.
pub(super) fn chi_square_quantile(nu: f64, z: f64) -> f64 {
    let a = 2.0 / (9.0 * nu);
    let base = 1.0 - a + z * libm::sqrt(a);
    nu * base * base * base
}

/// Autocovariance of one axis' sample noise at lags 0..WINDOW: white (and
/// rounding) at lag 0, the AR(4) part at every lag. The first four lags
/// come from the model's stationary solution, the rest from the
/// Yule-Walker recursion (paper eq. 24: `ArModel::step` with no
/// innovation), so the Lyapunov solver runs four times per axis, not once
/// per lag (the probe computes this once, at boot, in soft f64).
#[inline(never)]
fn autocovariances(axis: &AxisNoise, rounding: f64) -> [f64; WINDOW] {
    let mut g = [0.0; WINDOW];
    if let Some(ar) = axis.coloured.as_ref() {
        let lead: [Option<f64>; 4] = core::array::from_fn(|k| ar.autocovariance(k));
        if let [Some(a), Some(b), Some(c), Some(d)] = lead {
            let mut window = [a, b, c, d];
            for (k, slot) in g.iter_mut().enumerate() {
                *slot = if k < window.len() {
                    window[k]
                } else {
                    ar.step(&mut window, 0.0)
                };
            }
        }
    }
    g[0] += square(axis.white_density) / SAMPLE_INTERVAL_S + rounding;
    g
}

/// `sum_{j,k < n} rho(j - k)^2` of one axis.
#[inline(never)]
fn correlation_square_sum(g: &[f64; WINDOW]) -> f64 {
    let n = WINDOW;
    let mut sum = n as f64;
    for lag in 1..n {
        let rho = g[lag] / g[0];
        sum += 2.0 * (n - lag) as f64 * rho * rho;
    }
    sum
}

/// `sum_{j,k < n} rho(j - k)` / n^2: the variance of the mean over the
/// per-sample variance.
#[inline(never)]
fn mean_variance_ratio(g: &[f64; WINDOW]) -> f64 {
    let n = WINDOW;
    let mut sum = n as f64;
    for lag in 1..n {
        sum += 2.0 * (n - lag) as f64 * g[lag] / g[0];
    }
    sum / square(n as f64)
}

/// The quantiles of `c chi^2(nu)` with mean `e` and variance `v`, at the
/// hysteresis' normal quantiles.
fn satterthwaite(e: f64, v: f64, h: &Hysteresis) -> Threshold {
    let c = v / (2.0 * e);
    let nu = e / c;
    Threshold {
        enter: c * chi_square_quantile(nu, h.z_enter),
        stay: c * chi_square_quantile(nu, h.z_stay),
        expected: e,
    }
}

impl StillThresholds {
    /// Thresholds for sensors with error budget `noise`, at a site whose
    /// gravity is `gravity_m_s2`, with the default hysteresis.
    pub fn from_budget(noise: &ImuNoise, gravity_m_s2: f64) -> Self {
        Self::with_hysteresis(noise, gravity_m_s2, &Hysteresis::DEFAULT)
    }

    /// The same with hysteresis `h`. Never inlined: it runs once, when the
    /// navigator is built (boot, re-align), never per sample.
    #[inline(never)]
    pub fn with_hysteresis(noise: &ImuNoise, gravity_m_s2: f64, h: &Hysteresis) -> Self {
        let gyro_q = (1.0 / f64::from(GYRO_LSB_PER_DEG_S)).to_radians();
        let accel_q = STANDARD_GRAVITY / f64::from(ACCEL_LSB_PER_G);
        // One part per gyro; both parts' triads averaged per force axis
        // (two independent roundings: half the variance).
        let gyro_rounding = square(gyro_q) / 4.0;
        let accel_rounding = square(accel_q) / 8.0;
        let nf = WINDOW as f64;
        // Body x and z gyros, then the three force axes: one loop, so the
        // probe's code has one copy of each helper (flash is short).
        let axes = [
            (&noise.gyro[GYRO_AXES[0]], gyro_rounding),
            (&noise.gyro[GYRO_AXES[1]], gyro_rounding),
            (&noise.accel[0], accel_rounding),
            (&noise.accel[1], accel_rounding),
            (&noise.accel[2], accel_rounding),
        ];
        let mut variance = [0.0; 5];
        let (mut rate_v, mut force_e, mut force_v, mut mean_var) = (0.0, 0.0, 0.0, 0.0f64);
        for (k, (axis, rounding)) in axes.into_iter().enumerate() {
            let g = autocovariances(axis, rounding);
            variance[k] = g[0];
            let squares = 2.0 * correlation_square_sum(&g);
            if k < 2 {
                rate_v += squares;
            } else {
                // E[sum (x - mean)^2] / s^2 = n (1 - var(mean)/s^2); the
                // variance is the magnitude statistic's scaled by the same
                // ratio (exact for white noise: 2 (n - 1)).
                let ratio = mean_variance_ratio(&g);
                let e = nf * (1.0 - ratio);
                force_e += e;
                force_v += squares * e / nf;
                // |mean f| - g: the noise of the mean along gravity (the
                // largest axis' bounds it).
                mean_var = mean_var.max(g[0] * ratio);
            }
        }
        let rate_e = 2.0 * nf;
        let rate_variance = [variance[0], variance[1]];
        let force_variance = [variance[2], variance[3], variance[4]];
        // ... and the residual bias of calibration.
        let bias = noise
            .accel
            .iter()
            .map(|a| square(a.residual_bias) + square(a.bias_instability))
            .fold(0.0, f64::max);
        let gravity_sigma = libm::sqrt(mean_var + bias);
        Self {
            rate: satterthwaite(rate_e, rate_v, h),
            force: satterthwaite(force_e, force_v, h),
            gravity: Threshold {
                enter: h.z_enter * gravity_sigma,
                stay: h.z_stay * gravity_sigma,
                expected: gravity_sigma,
            },
            rate_variance,
            force_variance,
            gravity_m_s2,
            enter_epochs: h.enter_epochs,
        }
    }
}

pub(super) fn square(v: f64) -> f64 {
    v * v
}
