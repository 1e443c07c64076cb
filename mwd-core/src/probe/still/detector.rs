//! The still detector ([`StillDetector`]): the window of the last samples,
//! its three statistics ([`StillStatistics`]) against the thresholds, and
//! the hysteresis between entering and staying still.

use super::thresholds::{Hysteresis, StillThresholds, WINDOW};
use crate::probe_sample::ProbeSample;
use crate::sensor_noise::ImuNoise;

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
    /// The thresholds' per-sample variances as f32 reciprocals: the window's
    /// sums run in f32 on the probe's FPU (in f64 they were software
    /// arithmetic, ~50,000 instructions a sample, a sixth of the probe's
    /// cycle); their 7 digits are far below the statistics' noise.
    weights: Weights,
}

/// [`StillThresholds`] as the window's sums use them, in f32.
#[derive(Debug, Clone, Copy)]
struct Weights {
    inverse_rate_variance: [f32; 2],
    inverse_force_variance: [f32; 3],
    gravity_m_s2: f32,
}

impl Weights {
    /// Not inlined: its software-f64 temporaries would otherwise sit in
    /// the frame of the probe's boot path, its deepest (+730 B of stack
    /// measured by the QEMU probe's stack painting).
    #[inline(never)]
    fn of(t: &StillThresholds) -> Self {
        Self {
            inverse_rate_variance: t.rate_variance.map(|v| (1.0 / v) as f32),
            inverse_force_variance: t.force_variance.map(|v| (1.0 / v) as f32),
            gravity_m_s2: t.gravity_m_s2 as f32,
        }
    }
}

impl StillDetector {
    pub fn new(thresholds: StillThresholds) -> Self {
        Self {
            weights: Weights::of(&thresholds),
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
        let w = &self.weights;
        let mut mean = [0.0f32; 3];
        let mut rate = 0.0f32;
        for s in &self.window {
            rate +=
                s[0] * s[0] * w.inverse_rate_variance[0] + s[1] * s[1] * w.inverse_rate_variance[1];
            for (m, v) in mean.iter_mut().zip(&s[2..]) {
                *m += *v;
            }
        }
        let nf = WINDOW as f32;
        mean.iter_mut().for_each(|m| *m /= nf);
        let mut force = 0.0f32;
        for s in &self.window {
            for ((v, m), inverse) in s[2..].iter().zip(&mean).zip(&w.inverse_force_variance) {
                force += (*v - m) * (*v - m) * inverse;
            }
        }
        // Oldest to newest: the slot after the newest comes first.
        let mut jitter = 0.0f32;
        for k in 1..WINDOW {
            let (a, b) = (
                &self.window[(self.next + k - 1) % WINDOW],
                &self.window[(self.next + k) % WINDOW],
            );
            jitter += (b[2] - a[2]) * (b[2] - a[2]) + (b[4] - a[4]) * (b[4] - a[4]);
        }
        let lateral_jitter = libm::sqrtf(jitter / (4 * (WINDOW - 1)) as f32);
        let magnitude = libm::sqrtf(mean.iter().map(|m| m * m).sum::<f32>());
        let t = &self.thresholds;
        let (rate, force) = (f64::from(rate), f64::from(force));
        let gravity = f64::from(libm::fabsf(magnitude - w.gravity_m_s2));
        self.statistics = StillStatistics {
            rate: (rate / t.rate.expected) as f32,
            force: (force / t.force.expected) as f32,
            gravity: (gravity / t.gravity.expected) as f32,
            lateral_jitter,
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
