//! What the filter's integration tests share.
#![allow(dead_code)] // each test file uses its own part of it

use mwd_core::ar::Ar4;
use mwd_core::sensor_noise::AxisNoise;
use mwd_core::timing::SAMPLE_INTERVAL_S;

/// Gaussian samples from xorshift64* and Box-Muller: no dependency, seeded.
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

/// One sensor channel: AR(4) noise + constant residual bias + first-order
/// Gauss-Markov bias instability (the budget of `ImuNoise::scc1300`),
/// started in its stationary state.
pub struct Channel {
    ar: Ar4,
    history: [f64; 4],
    residual_bias: f64,
    gauss_markov: f64,
    budget: AxisNoise,
}

impl Channel {
    pub fn new(ar: Ar4, budget: AxisNoise, rng: &mut Normal) -> Self {
        let mut c = Self {
            ar,
            history: [0.0; 4],
            residual_bias: budget.residual_bias * rng.sample(),
            gauss_markov: budget.bias_instability * rng.sample(),
            budget,
        };
        for _ in 0..200 {
            c.next(rng); // AR noise into its stationary state
        }
        c
    }

    /// The channel's error at the next sample.
    pub fn next(&mut self, rng: &mut Normal) -> f64 {
        let a = libm::exp(-SAMPLE_INTERVAL_S / self.budget.correlation_time);
        let gm_step = libm::sqrt(1.0 - a * a) * self.budget.bias_instability;
        self.gauss_markov = a * self.gauss_markov + gm_step * rng.sample();
        let e = rng.sample() * libm::sqrt(self.ar.noise_variance);
        self.residual_bias + self.gauss_markov + self.ar.step(&mut self.history, e)
    }
}
