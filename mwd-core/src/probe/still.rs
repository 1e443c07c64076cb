//! Still detection for station surveys while drilling: is the probe at
//! rest (the string in the slips at a connection)?
//!
//! Three tests on the corrected samples (both parts) over a sliding window
//! of [`WINDOW`] samples (1 s), each against a threshold derived from the
//! noise budget ([`ImuNoise::scc1300`]) rather than tuned:
//!
//! 1. **rate magnitude**: `T_w = sum_k sum_i w_ki^2 / s_i^2` over the two
//!    gyros (body x and z). The earth rate (<= 15 deg/h) and the residual
//!    bias after calibration (2.1 deg/h) are left in: against a per-sample
//!    sigma of ~0.07 deg/s they add ~0.5 % to the expected value. A
//!    magnitude test, not a variance test, because a slow steady turn
//!    (1 deg/s) has no variance.
//! 2. **force variance**: `T_f = sum_k sum_i (f_ki - mean_i)^2 / s_i^2`
//!    over the three axes: vibration.
//! 3. **gravity magnitude**: `|mean f| - g`, against the residual
//!    accelerometer bias and the noise of the mean: a sustained
//!    acceleration.
//!
//! Under stillness each quadratic statistic is approximately `c chi^2(nu)`
//! (Satterthwaite's two-moment match; exact for white noise, where
//! `c = 1`): `E[T] = c nu` and `Var[T] = 2 c^2 nu`, with `Var[T] = 2 sum_i
//! sum_jk rho_i(j - k)^2` from the autocorrelation of the budget's noise
//! (white + the paper's AR(4) coloured part, `crate::ar`). The chi-square
//! quantile is the Wilson-Hilferty approximation (Wilson & Hilferty 1931:
//! `chi^2_p(nu) ~ nu (1 - 2/(9 nu) + z_p sqrt(2/(9 nu)))^3`; nu is a few
//! tens here; checked against tables at the 1e-3 quantile of chi^2(40) in
//! the tests, an approximation at 1e-7 whose error only changes how rare
//! a split station is; the moment match is Satterthwaite's, Biometrics
//! Bulletin 2(6), 1946). This is the GLRT ("SHOE") family of zero-velocity
//! detectors (Skog, Handel, Nilsson, Rantakokko, "Zero-velocity
//! detection - an algorithm evaluation", IEEE Trans. Biomed. Eng. 57(11),
//! 2010), split into its rate and force parts, with the thresholds from
//! the budget instead of tuned.
//!
//! Per-sample variances: the white density squared times the sample rate,
//! plus the AR model's stationary variance, plus the counts' rounding. The
//! rounding error is at most half a count, so its variance is at most
//! q^2/4; the uniform q^2/12 holds only when the noise spans several counts,
//! which the z accelerometer's (0.36 counts) does not. The bound is used:
//! the still-failure probabilities below are then upper bounds.
//!
//! Hysteresis (two false-alarm probabilities per test and epoch; these are
//! the defaults, the uplink can set others: [`Hysteresis`]):
//! * enter: all three tests pass at [`Z_ENTER`] (one-sided 1e-3 each) on
//!   [`ENTER_EPOCHS`] consecutive samples after a full window: the minimum
//!   still duration is `WINDOW + ENTER_EPOCHS - 1` samples, 39 (1.95 s),
//!   which is also the **detection delay** of a still probe when no window
//!   fails;
//! * stay: each test at [`Z_STAY`] (one-sided 1e-7: over a 5-minute station,
//!   6000 epochs and three tests, a split station has probability <= 0.2 %
//!   before the windows' correlation lowers it further); the first failing
//!   sample ends the still period (motion at 1 deg/s fails the rate test on
//!   its first sample).
//!
//! What it cannot see: a constant velocity (a string sliding at a steady
//! speed has no acceleration and no rate) looks still to any inertial
//! detector; in the slips the string is held. A turn slower than about
//! 0.1 deg/s passes the stay test (it is integrated by the gyros all the
//! same; the zero-velocity update it allows is still right). Only samples
//! with both parts are judged: with one part out a turn about the missing
//! gyro's axis would not be seen, and the navigator resets the detector.

use crate::probe_sample::{ProbeSample, GYRO_AXES};
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
fn chi_square_quantile(nu: f64, z: f64) -> f64 {
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

/// The statistics of the latest window, each divided by its expected value
/// under stillness (about 1 when still).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct StillStatistics {
    pub rate: f32,
    pub force: f32,
    /// | |mean f| - g | over its 1-sigma.
    pub gravity: f32,
    /// The per-sample jitter of the force across the tool axis (body x
    /// and z), m/s^2: the von Neumann estimate sqrt(mean (f_k - f_k-1)^2
    /// / 2) per axis, root-mean-squared over the two. Successive
    /// differences leave out a smooth change (a toolface turn at 10 deg/s
    /// moves f by 0.085 m/s^2 a sample) and keep white vibration whole.
    pub lateral_jitter: f32,
}

/// The still detector: one sample at a time.
#[derive(Debug, Clone)]
pub struct StillDetector {
    thresholds: StillThresholds,
    /// Rates (x, z) and force (x, y, z) of the last `WINDOW` samples: f32
    /// halves the RAM and keeps 7 digits, far below the noise.
    window: [[f32; 5]; WINDOW],
    next: usize,
    filled: usize,
    passes: u32,
    still: bool,
    statistics: StillStatistics,
}

impl StillDetector {
    pub fn new(thresholds: StillThresholds) -> Self {
        Self {
            thresholds,
            window: [[0.0; 5]; WINDOW],
            next: 0,
            filled: 0,
            passes: 0,
            still: false,
            statistics: StillStatistics::default(),
        }
    }

    /// The SCC1300 budget's detector at a site of gravity `gravity_m_s2`.
    pub fn scc1300(gravity_m_s2: f64) -> Self {
        Self::scc1300_with(gravity_m_s2, &Hysteresis::DEFAULT)
    }

    /// The same with hysteresis `h`.
    pub fn scc1300_with(gravity_m_s2: f64, h: &Hysteresis) -> Self {
        Self::new(StillThresholds::with_hysteresis(
            &ImuNoise::scc1300(),
            gravity_m_s2,
            h,
        ))
    }

    pub fn thresholds(&self) -> &StillThresholds {
        &self.thresholds
    }

    /// Forgets the window: nothing is judged still until a new one is full.
    pub fn reset(&mut self) {
        self.next = 0;
        self.filled = 0;
        self.passes = 0;
        self.still = false;
    }

    pub fn is_still(&self) -> bool {
        self.still
    }

    /// The latest window's normalised statistics.
    pub fn statistics(&self) -> StillStatistics {
        self.statistics
    }

    /// Takes one corrected sample (both parts); returns whether the probe
    /// is still after it.
    pub fn update(&mut self, sample: &ProbeSample) -> bool {
        let f = sample.specific_force;
        let values = [sample.gyro[0], sample.gyro[1], f.x, f.y, f.z].map(|v| v as f32);
        if values.iter().any(|v| !v.is_finite()) {
            self.reset();
            return false;
        }
        if let Some(slot) = self.window.get_mut(self.next) {
            *slot = values;
        }
        self.next = (self.next + 1) % WINDOW;
        self.filled = (self.filled + 1).min(WINDOW);
        if self.filled < WINDOW {
            return false;
        }
        let t = &self.thresholds;
        let mut mean = [0.0f64; 3];
        let mut rate = 0.0f64;
        for s in &self.window {
            rate += square(f64::from(s[0])) / t.rate_variance[0]
                + square(f64::from(s[1])) / t.rate_variance[1];
            for (m, v) in mean.iter_mut().zip(&s[2..]) {
                *m += f64::from(*v);
            }
        }
        let nf = WINDOW as f64;
        mean.iter_mut().for_each(|m| *m /= nf);
        let mut force = 0.0f64;
        for s in &self.window {
            for ((v, m), var) in s[2..].iter().zip(&mean).zip(&t.force_variance) {
                force += square(f64::from(*v) - m) / var;
            }
        }
        // Oldest to newest: the slot after the newest comes first.
        let mut jitter = 0.0f64;
        for k in 1..WINDOW {
            let (a, b) = (
                &self.window[(self.next + k - 1) % WINDOW],
                &self.window[(self.next + k) % WINDOW],
            );
            jitter += square(f64::from(b[2] - a[2])) + square(f64::from(b[4] - a[4]));
        }
        let lateral_jitter = libm::sqrt(jitter / (4.0 * (WINDOW - 1) as f64));
        let magnitude = libm::sqrt(mean.iter().map(|m| m * m).sum::<f64>());
        let gravity = libm::fabs(magnitude - t.gravity_m_s2);
        self.statistics = StillStatistics {
            rate: (rate / t.rate.expected) as f32,
            force: (force / t.force.expected) as f32,
            gravity: (gravity / t.gravity.expected) as f32,
            lateral_jitter: lateral_jitter as f32,
        };
        if self.still {
            self.still = rate <= t.rate.stay && force <= t.force.stay && gravity <= t.gravity.stay;
            if !self.still {
                self.passes = 0;
            }
        } else if rate <= t.rate.enter && force <= t.force.enter && gravity <= t.gravity.enter {
            self.passes += 1;
            self.still = self.passes >= t.enter_epochs;
        } else {
            self.passes = 0;
        }
        self.still
    }
}

fn square(v: f64) -> f64 {
    v * v
}

#[cfg(test)]
pub(crate) mod tests {
    extern crate std;
    use super::*;
    use crate::ar::ArModel;
    use nalgebra::Vector3;

    /// Gaussian samples from xorshift64* and Box-Muller: seeded, no
    /// dependency.
    pub struct Normal(pub u64);

    impl Normal {
        pub fn uniform(&mut self) -> f64 {
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            ((self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 + 0.5) / (1u64 << 53) as f64
        }

        pub fn sample(&mut self) -> f64 {
            let (u, v) = (self.uniform(), self.uniform());
            libm::sqrt(-2.0 * libm::log(u)) * libm::cos(core::f64::consts::TAU * v)
        }
    }

    /// The budget's sensor errors on a true rate and force: white noise,
    /// the AR(4) coloured noise (started at its stationary state by a
    /// 200-sample burn-in), a constant residual bias drawn once, and the
    /// parts' rounding to counts (each force axis read by both parts and
    /// averaged; each gyro by one part).
    pub struct BudgetSensors {
        pub noise: ImuNoise,
        rng: Normal,
        history: [[f64; 4]; 5],
        bias: [f64; 5],
    }

    impl BudgetSensors {
        pub fn new(seed: u64) -> Self {
            let noise = ImuNoise::scc1300();
            let mut rng = Normal(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1);
            let axes = Self::axes(&noise);
            let bias = core::array::from_fn(|i| axes[i].residual_bias * rng.sample());
            let mut sensors = Self {
                noise,
                rng,
                history: [[0.0; 4]; 5],
                bias,
            };
            for _ in 0..200 {
                sensors.coloured();
            }
            sensors
        }

        fn axes(noise: &ImuNoise) -> [AxisNoise; 5] {
            [
                noise.gyro[0],
                noise.gyro[2],
                noise.accel[0],
                noise.accel[1],
                noise.accel[2],
            ]
        }

        fn coloured(&mut self) -> [f64; 5] {
            let axes = Self::axes(&self.noise);
            core::array::from_fn(|i| {
                let ar: ArModel<4> = axes[i].coloured.unwrap();
                let e = libm::sqrt(ar.noise_variance) * self.rng.sample();
                ar.step(&mut self.history[i], e)
            })
        }

        /// The corrected sample the navigator would see for a true body
        /// rate (x, z; rad/s) and specific force (m/s^2).
        pub fn sample(&mut self, rate: [f64; 2], force: Vector3<f64>) -> ProbeSample {
            let axes = Self::axes(&self.noise);
            let coloured = self.coloured();
            let gyro_q = (1.0 / f64::from(GYRO_LSB_PER_DEG_S)).to_radians();
            let accel_q = STANDARD_GRAVITY / f64::from(ACCEL_LSB_PER_G);
            let white = |rng: &mut Normal, a: &AxisNoise| {
                a.white_density / libm::sqrt(SAMPLE_INTERVAL_S) * rng.sample()
            };
            let mut gyro = [0.0; 2];
            for k in 0..2 {
                let v = rate[k] + self.bias[k] + coloured[k] + white(&mut self.rng, &axes[k]);
                gyro[k] = libm::round(v / gyro_q) * gyro_q;
            }
            let mut f = Vector3::zeros();
            for i in 0..3 {
                let common = force[i] + self.bias[2 + i] + coloured[2 + i];
                // Two parts whose white noises average to the budget's.
                let mut sum = 0.0;
                for _ in 0..2 {
                    let v = common + core::f64::consts::SQRT_2 * white(&mut self.rng, &axes[2 + i]);
                    sum += libm::round(v / accel_q) * accel_q;
                }
                f[i] = sum / 2.0;
            }
            ProbeSample::new(gyro[0], gyro[1], f)
        }
    }

    /// Gravity's reaction in body axes for a tool at inclination `inc`
    /// and toolface `tf` (rad): the body y axis is the tool axis.
    fn force_at(inc: f64, tf: f64, g: f64) -> Vector3<f64> {
        crate::conventions::specific_force_at_rest(
            &crate::conventions::Euler::new(tf, inc - core::f64::consts::FRAC_PI_2, 0.0),
            g,
        )
    }

    const G: f64 = STANDARD_GRAVITY;

    #[test]
    fn thresholds_follow_the_budget() {
        let t = StillThresholds::from_budget(&ImuNoise::scc1300(), G);
        // White noise alone: 2 x 20 = 40 degrees of freedom, and the
        // Wilson-Hilferty 1e-3 quantile of chi^2(40) is 73.40 (tables:
        // 73.40).
        let white = chi_square_quantile(40.0, Z_ENTER);
        assert!((white - 73.40).abs() < 0.1, "{white}");
        // The gyros are nearly white: the thresholds stay close to it.
        assert!((t.rate.expected - 40.0).abs() < 1e-9);
        assert!(t.rate.enter > 70.0 && t.rate.enter < 80.0, "{t:?}");
        assert!(t.rate.stay > t.rate.enter && t.force.stay > t.force.enter);
        // Per-sample gyro sigma about 0.064 deg/s plus the rounding.
        let s = libm::sqrt(t.rate_variance[0]).to_degrees();
        assert!(s > 0.064 && s < 0.075, "{s}");
        // |f| - g: the 1 mg residual bias dominates: 3.09 sigma ~ 3.1 mg.
        assert!(t.gravity.enter > 0.025 && t.gravity.enter < 0.05, "{t:?}");
    }

    /// The uplink's default settings give the constants' thresholds to the
    /// bit; a larger z_enter raises every entering threshold and leaves
    /// the staying ones.
    #[test]
    fn the_hysteresis_settings_move_the_thresholds() {
        let noise = ImuNoise::scc1300();
        let defaults = crate::config::default_still_settings();
        let from_settings =
            StillThresholds::with_hysteresis(&noise, G, &Hysteresis::from_settings(&defaults));
        assert_eq!(from_settings, StillThresholds::from_budget(&noise, G));
        let strict = Hysteresis::from_settings(&StillSettings {
            z_enter: 4.0,
            enter_epochs: 7,
            ..defaults
        });
        assert_eq!((strict.z_enter, strict.enter_epochs), (4.0, 7));
        let t = StillThresholds::with_hysteresis(&noise, G, &strict);
        let d = from_settings;
        assert!(t.rate.enter > d.rate.enter && t.force.enter > d.force.enter);
        assert!(t.gravity.enter > d.gravity.enter);
        assert_eq!((t.rate.stay, t.force.stay), (d.rate.stay, d.force.stay));
        assert_eq!(t.enter_epochs, 7);
    }

    /// Still samples from the budget at a few attitudes and seeds: still
    /// is declared within the stated delay (no window failing) or, with
    /// one failing window (probability <= ~2 % per attempt), within twice
    /// it; and stays still for the rest of a 5-minute station.
    #[test]
    fn still_data_is_declared_still_within_the_stated_delay() {
        let mut delays = [0u32; 40];
        let mut drop_outs = 0;
        for (seed, delay) in delays.iter_mut().enumerate() {
            let mut sensors = BudgetSensors::new(seed as u64 + 1);
            let mut detector = StillDetector::scc1300(G);
            let inc = (seed as f64 * 7.0).to_radians();
            let force = force_at(inc, seed as f64, G);
            let mut first = None;
            for n in 1..=6000u32 {
                let still = detector.update(&sensors.sample([0.0; 2], force));
                match (still, first) {
                    (true, None) => first = Some(n),
                    (false, Some(_)) => drop_outs += 1,
                    _ => {}
                }
            }
            *delay = first.unwrap_or(u32::MAX);
        }
        let nominal = delays
            .iter()
            .filter(|d| **d == DETECTION_DELAY_SAMPLES)
            .count();
        assert!(nominal >= 36, "{delays:?}");
        assert!(
            delays.iter().all(|d| *d <= 2 * DETECTION_DELAY_SAMPLES),
            "{delays:?}"
        );
        assert_eq!(drop_outs, 0, "a still period split in 40 x 5 min");
    }

    /// A level tool turning about its axis... the gyros see body x and z:
    /// a slow 1 deg/s turn about each is never taken for still.
    #[test]
    fn a_slow_turn_at_1_deg_s_is_not_still() {
        for axis in 0..2 {
            let mut sensors = BudgetSensors::new(100 + axis as u64);
            let mut detector = StillDetector::scc1300(G);
            let mut rate = [0.0; 2];
            rate[axis] = 1f64.to_radians();
            let force = force_at(0.5, 0.3, G);
            for n in 0..2000 {
                assert!(!detector.update(&sensors.sample(rate, force)), "sample {n}");
            }
        }
    }

    /// Motion ends a still period on its first sample (1 deg/s).
    #[test]
    fn motion_ends_a_still_period_at_once() {
        let mut sensors = BudgetSensors::new(7);
        let mut detector = StillDetector::scc1300(G);
        let force = force_at(1.0, 2.0, G);
        for _ in 0..200 {
            detector.update(&sensors.sample([0.0; 2], force));
        }
        assert!(detector.is_still());
        let turning = [0.0, 1f64.to_radians()];
        assert!(!detector.update(&sensors.sample(turning, force)));
    }

    /// Drilling vibration: bursts of random lateral and axial shocks
    /// (0.05 to 2 m/s^2 RMS, 0.5 to 3 s long) separated by quiet gaps of
    /// 0.2 to 1.9 s (shorter than the minimum still duration, the string
    /// still held moving), with the rates of a wobbling string (RMS 0.2 to
    /// 5 deg/s) during the bursts and none in the gaps. Over 2 hours
    /// (144,000 samples, seeded) the detector declares still on fewer than
    /// 1 in 10,000 samples.
    #[test]
    fn the_false_still_rate_on_vibration_stays_below_1e_4() {
        let mut sensors = BudgetSensors::new(42);
        let mut rng = Normal(0xDEC0_DE5E_ED00_0001);
        let mut detector = StillDetector::scc1300(G);
        let force = force_at(0.8, 1.0, G);
        let (mut total, mut false_still) = (0u32, 0u32);
        while total < 144_000 {
            let burst = 10 + (rng.uniform() * 50.0) as u32;
            let shock = 0.05 + rng.uniform() * 1.95;
            let wobble = (0.2 + rng.uniform() * 4.8f64).to_radians();
            for _ in 0..burst {
                let f = force + Vector3::from_fn(|_, _| shock * rng.sample());
                let r = [wobble * rng.sample(), wobble * rng.sample()];
                false_still += u32::from(detector.update(&sensors.sample(r, f)));
                total += 1;
            }
            let gap = 4 + (rng.uniform() * 34.0) as u32;
            for _ in 0..gap {
                false_still += u32::from(detector.update(&sensors.sample([0.0; 2], force)));
                total += 1;
            }
        }
        let rate = f64::from(false_still) / f64::from(total);
        assert!(rate < 1e-4, "{false_still} of {total}");
    }

    /// A vibration burst inside a still period ends it.
    #[test]
    fn a_vibration_burst_ends_a_still_period() {
        let mut sensors = BudgetSensors::new(9);
        let mut detector = StillDetector::scc1300(G);
        let force = force_at(0.3, 0.0, G);
        for _ in 0..100 {
            detector.update(&sensors.sample([0.0; 2], force));
        }
        assert!(detector.is_still());
        let mut rng = Normal(5);
        let mut ended = false;
        for _ in 0..3 {
            let f = force + Vector3::from_fn(|_, _| 0.1 * rng.sample());
            ended |= !detector.update(&sensors.sample([0.0; 2], f));
        }
        assert!(ended);
    }

    #[test]
    fn a_non_finite_sample_resets_the_window() {
        let mut detector = StillDetector::scc1300(G);
        let force = force_at(0.3, 0.0, G);
        for _ in 0..100 {
            detector.update(&ProbeSample::new(0.0, 0.0, force));
        }
        assert!(detector.is_still());
        assert!(!detector.update(&ProbeSample::new(f64::NAN, 0.0, force)));
        for n in 1..DETECTION_DELAY_SAMPLES {
            assert!(!detector.update(&ProbeSample::new(0.0, 0.0, force)), "{n}");
        }
        assert!(detector.update(&ProbeSample::new(0.0, 0.0, force)));
    }
}
