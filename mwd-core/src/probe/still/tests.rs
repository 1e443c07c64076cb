extern crate std;
use super::thresholds::chi_square_quantile;
use super::*;
use crate::ar::ArModel;
use crate::probe_sample::ProbeSample;
use crate::protocol::uplink::StillSettings;
use crate::sensor_noise::{AxisNoise, ImuNoise};
use crate::sensor_units::{ACCEL_LSB_PER_G, GYRO_LSB_PER_DEG_S, STANDARD_GRAVITY};
use crate::timing::SAMPLE_INTERVAL_S;
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
