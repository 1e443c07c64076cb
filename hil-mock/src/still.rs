//! A probe lying still somewhere on the earth, as its sensors see it: the
//! earth rate and normal gravity of `mwd_core::earth` resolved in body axes
//! at a fixed attitude, plus constant biases and white noise at the
//! SCC1300's datasheet densities. The QEMU firmware's alignment runs on it,
//! and the host tests know its truth.
//!
//! The noise is a pure function of (seed, channel, 20 Hz period): every read
//! within one sample period sees the same value, and a run repeats exactly
//! on the host and on the target (libm throughout).

use mwd_core::conventions::{quat_from_euler, Euler, DEG};
use mwd_core::earth::{earth_rate_n, gravity_n, Position};
use mwd_core::sensor_noise::{rate_from_deg_per_hour, ImuNoise};
use mwd_core::sensor_units::STANDARD_GRAVITY;
use mwd_core::timing::SAMPLE_RATE_HZ;

use crate::clock::SAMPLE_PERIOD_NS;
use crate::source::{BodySample, BodySource};

/// A still probe: truth, errors and noise.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StillProbe {
    /// The true attitude (roll, pitch, heading).
    pub attitude: Euler,
    pub position: Position,
    /// Constant gyro biases on body x, y, z (rad/s).
    pub gyro_bias_rad_s: [f32; 3],
    /// Constant accelerometer biases on body x, y, z (m/s^2).
    pub accel_bias_m_s2: [f32; 3],
    /// White noise per sample (1 sigma) of the gyros (rad/s) and of the
    /// accelerometers (m/s^2).
    pub gyro_noise_rad_s: f32,
    pub accel_noise_m_s2: f32,
    pub temperature_degc: f32,
    /// Noise stream: give each part its own.
    pub seed: u64,
    /// The last period's sample: the driver reads a part several times per
    /// period, and the QEMU cycle budget should measure the probe, not the
    /// mock's trigonometry.
    last: Option<(u64, BodySample)>,
    /// [`true_body`](Self::true_body), computed at the first sample (the
    /// fields above are the probe's set-up: change them before that).
    truth: Option<([f64; 3], [f64; 3])>,
}

impl StillProbe {
    /// The MGWD paper's static test: its site, its attitude (the paper's
    /// coarse result: roll -0.8061, pitch 0.5371, azimuth -150.9636 deg),
    /// white noise from the SCC1300 budget at 20 Hz (ARW 0.86 deg/sqrt(h),
    /// VRW 0.052 m/s/sqrt(h)), and residual biases of one budget sigma
    /// (2.1 deg/h, 1 mg) with fixed signs.
    pub fn paper_test(seed: u64) -> Self {
        let noise = ImuNoise::scc1300();
        let per_sample = |density: f64| (density * libm::sqrt(SAMPLE_RATE_HZ)) as f32;
        let gyro_bias = rate_from_deg_per_hour(2.1) as f32;
        let accel_bias = (1e-3 * STANDARD_GRAVITY) as f32;
        Self {
            attitude: Euler::new(-0.8061 * DEG, 0.5371 * DEG, -150.9636 * DEG),
            position: Position::paper_site(),
            gyro_bias_rad_s: [gyro_bias, 0.0, -gyro_bias],
            accel_bias_m_s2: [accel_bias, -accel_bias, 0.5 * accel_bias],
            gyro_noise_rad_s: per_sample(noise.gyro[0].white_density),
            accel_noise_m_s2: per_sample(noise.accel[2].white_density),
            temperature_degc: 25.0,
            seed,
            last: None,
            truth: None,
        }
    }

    /// What the body feels without errors: earth rate and the reaction to
    /// gravity, in body axes (rad/s, m/s^2).
    pub fn true_body(&self) -> ([f64; 3], [f64; 3]) {
        let q = quat_from_euler(&self.attitude);
        let rate = q.inverse_transform_vector(&earth_rate_n(self.position.lat));
        let force = q.inverse_transform_vector(&-gravity_n(&self.position));
        ([rate.x, rate.y, rate.z], [force.x, force.y, force.z])
    }

    /// Standard normal deviate number `channel` of sample period `k`.
    fn gaussian(&self, k: u64, channel: u64) -> f32 {
        let u1 = unit_interval(splitmix64(self.seed ^ (k << 4 | channel)));
        let u2 = unit_interval(splitmix64(!self.seed ^ (k << 4 | channel)));
        // Box-Muller; u1 in (0, 1], so the logarithm is finite.
        libm::sqrtf(-2.0 * libm::logf(u1)) * libm::cosf(core::f32::consts::TAU * u2)
    }
}

impl BodySource for StillProbe {
    fn body_sample(&mut self, time_ns: u64) -> BodySample {
        let k = time_ns / SAMPLE_PERIOD_NS;
        if let Some((period, sample)) = self.last {
            if period == k {
                return sample;
            }
        }
        let (rate, force) = match self.truth {
            Some(truth) => truth,
            None => {
                let truth = self.true_body();
                self.truth = Some(truth);
                truth
            }
        };
        let mut sample = BodySample {
            temperature_degc: self.temperature_degc,
            ..BodySample::default()
        };
        for axis in 0..3 {
            sample.rate_rad_s[axis] = rate[axis] as f32
                + self.gyro_bias_rad_s[axis]
                + self.gyro_noise_rad_s * self.gaussian(k, axis as u64);
            sample.specific_force_m_s2[axis] = force[axis] as f32
                + self.accel_bias_m_s2[axis]
                + self.accel_noise_m_s2 * self.gaussian(k, 3 + axis as u64);
        }
        self.last = Some((k, sample));
        sample
    }
}

/// SplitMix64's output function: a well-mixed 64-bit hash.
fn splitmix64(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// The top 24 bits as a float in (0, 1].
fn unit_interval(x: u64) -> f32 {
    ((x >> 40) as f32 + 1.0) / 16_777_216.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn truth_is_earth_rate_and_gravity_in_body_axes() {
        let probe = StillProbe::paper_test(1);
        let (rate, force) = probe.true_body();
        let norm = |v: [f64; 3]| libm::sqrt(v.iter().map(|x| x * x).sum::<f64>());
        assert!((norm(rate) - mwd_core::earth::EARTH_RATE).abs() < 1e-12);
        let g = mwd_core::earth::normal_gravity(probe.position.lat, probe.position.height);
        assert!((norm(force) - g).abs() < 1e-9);
        // Nearly level: gravity's reaction almost all on body z (up).
        assert!(force[2] > 0.999 * g);
    }

    #[test]
    fn noise_is_repeatable_per_period_and_has_the_stated_spread() {
        let mut probe = StillProbe::paper_test(7);
        let a = probe.body_sample(3 * SAMPLE_PERIOD_NS);
        let b = probe.body_sample(3 * SAMPLE_PERIOD_NS + SAMPLE_PERIOD_NS / 2);
        assert_eq!(a, b, "one period, one sample");
        let (rate, _) = probe.true_body();
        let n = 4000;
        let (mut sum, mut sum_sq) = (0.0f64, 0.0f64);
        for k in 0..n {
            let s = probe.body_sample(k * SAMPLE_PERIOD_NS);
            let e = f64::from(s.rate_rad_s[0]) - rate[0] - f64::from(probe.gyro_bias_rad_s[0]);
            sum += e;
            sum_sq += e * e;
        }
        let mean = sum / n as f64;
        let sigma = libm::sqrt(sum_sq / n as f64 - mean * mean);
        let stated = f64::from(probe.gyro_noise_rad_s);
        // 4000 samples: the sample sigma within 5 %, the mean within 4
        // standard errors.
        assert!((sigma / stated - 1.0).abs() < 0.05, "{sigma} vs {stated}");
        assert!(mean.abs() < 4.0 * stated / libm::sqrt(n as f64), "{mean}");
    }
}
