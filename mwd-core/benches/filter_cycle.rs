//! One 20 Hz filter cycle (mechanization + time update + ZUPT and
//! zero-position updates + feedback), structured vs dense, f32 vs f64.
//!
//! `cargo bench -p mwd-core --bench filter_cycle`

use criterion::{criterion_group, criterion_main, Criterion};
use mwd_core::conventions::{dcm_from_quat, quat_from_euler, Euler};
use mwd_core::earth::{earth_rate_n, gravity_n, LocalEarth, Position};
use mwd_core::error_model::{AugmentedModel, LinearizationPoint, ProcessNoise, POS, STATES, VEL};
use mwd_core::fine_alignment::{FineAlignment, FineAlignmentConfig};
use mwd_core::kalman::{dense, FilterScalar};
use mwd_core::mechanization::{ImuSample, NavState, Strapdown};
use nalgebra::{SMatrix, SVector};
use std::hint::black_box;

fn setup() -> (NavState, ImuSample) {
    let state = NavState::at_rest(
        quat_from_euler(&Euler::new(-0.014, 0.0094, -2.635)),
        Position::paper_site(),
    );
    let c_nb = dcm_from_quat(&state.attitude).transpose();
    let sample = ImuSample {
        rate: c_nb * earth_rate_n(state.position.lat) + nalgebra::Vector3::new(1e-5, -2e-5, 3e-5),
        specific_force: c_nb * -gravity_n(&state.position)
            + nalgebra::Vector3::new(1e-3, 2e-3, -1e-3),
    };
    (state, sample)
}

fn fast_cycle<T: FilterScalar>(c: &mut Criterion, name: &str) {
    let (state, sample) = setup();
    let mut fa = FineAlignment::<T>::new(
        state,
        state.position,
        FineAlignmentConfig::paper(AugmentedModel::paper()),
    );
    c.bench_function(name, |b| b.iter(|| black_box(fa.step(black_box(&sample)))));
}

/// The textbook cycle: dense Phi P Phi^T + Q, and the 6-vector update
/// with a matrix inverse and full-matrix Joseph form.
struct DenseCycle<T: FilterScalar> {
    strapdown: Strapdown,
    model: AugmentedModel,
    x: SVector<T, STATES>,
    p: SMatrix<T, STATES, STATES>,
    q: SMatrix<T, STATES, STATES>,
    h: SMatrix<T, 6, STATES>,
    r: SMatrix<T, 6, 6>,
    reference: Position,
    /// Geodetic terms cached as in the fast cycle: compare filters, not caches.
    earth: LocalEarth,
}

impl<T: FilterScalar> DenseCycle<T> {
    fn new(state: NavState) -> Self {
        let model = AugmentedModel::paper();
        let mut h = SMatrix::zeros();
        for i in 0..3 {
            h[(i, VEL + i)] = T::one();
            h[(3 + i, POS + i)] = T::one();
        }
        Self {
            strapdown: Strapdown::new(state, model.dt),
            model,
            x: SVector::zeros(),
            p: SMatrix::identity() * T::of(0.01),
            q: SMatrix::from_diagonal(&model.process_noise(&ProcessNoise {
                nav_per_step: [1e-6; 9],
            })),
            h,
            r: SMatrix::identity() * T::of(0.1),
            reference: state.position,
            earth: LocalEarth::at(&state.position),
        }
    }

    fn step(&mut self, sample: &ImuSample) {
        self.strapdown.step(sample);
        let s = *self.strapdown.state();
        let c_bn = s.attitude.to_rotation_matrix().into_inner();
        let lp = LinearizationPoint {
            c_bn,
            velocity_n: s.velocity,
            position: s.position,
            specific_force_n: c_bn * sample.specific_force,
        };
        let phi = self
            .model
            .transition_with::<T, STATES>(&self.earth, &lp)
            .to_dense();
        dense::predict(&mut self.x, &mut self.p, &phi, &self.q);
        let dp = s.position.ned_from(&self.reference);
        let z =
            SVector::<T, 6>::from_fn(|i, _| T::of(if i < 3 { s.velocity[i] } else { dp[i - 3] }));
        dense::update(&mut self.x, &mut self.p, &z, &self.h, &self.r);
        let v = |i: usize| {
            nalgebra::Vector3::new(
                self.x[i].as_f64(),
                self.x[i + 1].as_f64(),
                self.x[i + 2].as_f64(),
            )
        };
        self.strapdown.apply_correction(&v(0), &v(3), &v(6));
        self.x.fixed_rows_mut::<9>(0).fill(T::zero());
    }
}

fn dense_cycle<T: FilterScalar>(c: &mut Criterion, name: &str) {
    let (state, sample) = setup();
    let mut cycle = DenseCycle::<T>::new(state);
    c.bench_function(name, |b| b.iter(|| cycle.step(black_box(&sample))));
}

fn benches(c: &mut Criterion) {
    fast_cycle::<f32>(c, "cycle/fast/f32");
    fast_cycle::<f64>(c, "cycle/fast/f64");
    dense_cycle::<f32>(c, "cycle/dense/f32");
    dense_cycle::<f64>(c, "cycle/dense/f64");
}

criterion_group!(filter, benches);
criterion_main!(filter);
