//! Noise-coefficient recovery from simulated rate data with known angle
//! random walk N and bias instability B (IEEE Std 952 definitions).
//!
//! Flicker (bias-instability) noise is synthesised as a sum of first-order
//! Gauss-Markov processes with correlation times spaced by a factor r: each
//! of variance c has the one-sided PSD 4 c T / (1 + (2 pi f T)^2), and the
//! sum approximates c / (f ln r) between the extreme corner frequencies.
//! IEEE 952's S(f) = B^2 / (2 pi f) is two-sided, i.e. B^2 / (pi f)
//! one-sided, so c = B^2 ln r / pi gives the floor 0.664 B.

use host_sim::analysis::allan::{allan_deviation, TauSet};
use host_sim::analysis::allan_fit::fit_noise;
use rand::SeedableRng;
use rand_distr::{Distribution, StandardNormal};

fn simulate(seed: u64, n: usize, rate: f64, arw: f64, bias_instability: f64) -> Vec<f64> {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let dt = 1.0 / rate;
    let ratio: f64 = 4.0;
    let corr_times: Vec<f64> = (0..8).map(|k| 0.5 * ratio.powi(k)).collect();
    let c = bias_instability * bias_instability * ratio.ln() / std::f64::consts::PI;
    let mut states: Vec<f64> = corr_times
        .iter()
        .map(|_| c.sqrt() * Distribution::<f64>::sample(&StandardNormal, &mut rng))
        .collect();
    let white_sd = arw / dt.sqrt();
    (0..n)
        .map(|_| {
            let mut sum = 0.0;
            for (s, t) in states.iter_mut().zip(&corr_times) {
                let phi = (-dt / t).exp();
                let w: f64 = StandardNormal.sample(&mut rng);
                *s = phi * *s + (c * (1.0 - phi * phi)).sqrt() * w;
                sum += *s;
            }
            let w: f64 = StandardNormal.sample(&mut rng);
            sum + white_sd * w
        })
        .collect()
}

#[test]
fn recovers_random_walk_and_bias_instability() {
    // Units are arbitrary (think rad/s): N = 0.01 u sqrt(s), B = 0.005 u,
    // so the white-noise line meets the floor near tau = 9 s.
    let (arw, bi) = (0.01, 0.005);
    for seed in [1u64, 2, 3, 4] {
        let y = simulate(seed, 200_000, 10.0, arw, bi);
        let points = allan_deviation(&y, 10.0, TauSet::Octave, |_| {});
        let fit = fit_noise(&points);
        let arw_err = fit.random_walk / arw - 1.0;
        let bi_err = fit.bias_instability / bi - 1.0;
        println!(
            "seed {seed}: ARW {:+.1} %, BI {:+.1} %",
            100.0 * arw_err,
            100.0 * bi_err
        );
        assert!(
            arw_err.abs() < 0.10,
            "seed {seed}: ARW off by {arw_err:+.3} ({fit:?})"
        );
        assert!(
            bi_err.abs() < 0.25,
            "seed {seed}: BI off by {bi_err:+.3} ({fit:?})"
        );
    }
}

/// The 1-sigma intervals from the equivalent degrees of freedom must cover
/// the true deviation of white noise, sigma / sqrt(m), about 68 % of the
/// time: pooled over seeds and octave taus, between 55 % and 82 %.
#[test]
fn confidence_intervals_cover_white_noise_truth() {
    let (mut inside, mut total) = (0usize, 0usize);
    for seed in 20u64..40 {
        let y = simulate(seed, 4096, 1.0, 1.0, 0.0);
        for p in allan_deviation(&y, 1.0, TauSet::Octave, |_| {}) {
            let truth = 1.0 / (p.m as f64).sqrt();
            inside += usize::from(p.ci_low <= truth && truth <= p.ci_high);
            total += 1;
        }
    }
    let coverage = inside as f64 / total as f64;
    println!(
        "1-sigma coverage {:.1} % over {total} intervals",
        100.0 * coverage
    );
    assert!((0.55..0.82).contains(&coverage), "coverage {coverage}");
}
