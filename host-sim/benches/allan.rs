//! Allan deviation of the paper's static record length: 8 h 20 min at
//! 20 Hz = 600,000 samples per axis (MGWD paper section 3.2.1), octave taus,
//! one axis per iteration (the CLI does six). Run with
//! `cargo bench -p host-sim --bench allan`.

use criterion::{criterion_group, criterion_main, Criterion};
use host_sim::analysis::allan::{allan_deviation, TauSet};
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use std::hint::black_box;

fn bench_allan(c: &mut Criterion) {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1065);
    let noise = Normal::new(0.0, 1e-4).expect("valid normal");
    let y: Vec<f64> = (0..600_000).map(|_| noise.sample(&mut rng)).collect();
    let mut group = c.benchmark_group("allan");
    group.sample_size(10);
    group.bench_function("oadev_octave_600k", |b| {
        b.iter(|| allan_deviation(black_box(&y), 20.0, TauSet::Octave, |_| {}))
    });
    group.finish();
}

criterion_group!(benches, bench_allan);
criterion_main!(benches);
