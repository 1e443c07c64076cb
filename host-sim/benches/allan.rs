//! Allan deviation of the paper's static record length: 8 h 20 min at
//! 20 Hz = 600,000 samples per axis (MGWD paper section 3.2.1), octave taus.
//! `oadev_octave_600k`: one axis; `cli_six_axes_600k`: six axes as
//! `host-sim allan` runs them, one after the other, each scaled to SI,
//! its deviation and its noise fit. Run with
//! `cargo bench -p host-sim --bench allan`.

use criterion::{criterion_group, criterion_main, Criterion};
use host_sim::analysis::allan::{allan_deviation, TauSet};
use host_sim::analysis::allan_fit::fit_noise;
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use std::hint::black_box;
use std::time::Duration;

const SAMPLES: usize = 600_000;

fn bench_allan(c: &mut Criterion) {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1065);
    let noise = Normal::new(0.0, 1e-4).expect("valid normal");
    // Six columns in their file units, like a table the CLI has read.
    let axes: Vec<Vec<f64>> = (0..6)
        .map(|_| (0..SAMPLES).map(|_| noise.sample(&mut rng)).collect())
        .collect();
    let mut group = c.benchmark_group("allan");
    group.sample_size(10);
    group.warm_up_time(Duration::from_millis(500));
    group.measurement_time(Duration::from_secs(5));
    group.bench_function("oadev_octave_600k", |b| {
        b.iter(|| allan_deviation(black_box(&axes[0]), 20.0, TauSet::Octave, |_| {}))
    });
    group.bench_function("cli_six_axes_600k", |b| {
        b.iter(|| {
            axes.iter()
                .map(|column| {
                    let to_si = black_box(1.0);
                    let y: Vec<f64> = column.iter().map(|v| v * to_si).collect();
                    let points = allan_deviation(&y, 20.0, TauSet::Octave, |k| {
                        black_box(k);
                    });
                    let fit = fit_noise(&points);
                    (points, fit)
                })
                .collect::<Vec<_>>()
        })
    });
    group.finish();
}

criterion_group!(benches, bench_allan);
criterion_main!(benches);
