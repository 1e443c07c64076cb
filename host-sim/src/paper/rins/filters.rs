//! The two filters of the paper's Fig. 6 on the same data: the reduced
//! 8-state one and the full augmented 17-state one, both the generic
//! `mwd_core::kalman` filter (dense time update, scalar measurement
//! updates), both with the models of `mwd_core::redundant`.

use mwd_core::kalman::{dense, std_dev_of, KalmanFilter, UpdateReport};
use mwd_core::redundant::index::{DRIFT_Z, EPS_1, NABLA_1, NABLA_2};
use mwd_core::redundant::{
    full_dynamics, full_noise_input, reduced_dynamics, reduced_noise_input, transition,
    DifferenceMeasurement, Motion, FULL_STATES, NOISE_INPUTS, REDUCED_STATES,
};
use nalgebra::{Matrix3, SMatrix, SVector};
use std::time::{Duration, Instant};

/// Initial 1-sigma of the filters' states (SI) and the noise densities.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tuning {
    /// Attitude-error difference, level and azimuth (rad).
    pub attitude: [f64; 2],
    /// Backup azimuth drift (rad/s).
    pub drift: f64,
    /// The full filter's other gyro drifts (rad/s) and accelerometer biases
    /// (m/s^2).
    pub other_drift: f64,
    pub accel_bias: f64,
    /// Gyro ARW (rad/sqrt(s)) and accelerometer VRW (m/s/sqrt(s)), each
    /// system.
    pub gyro_arw: f64,
    pub accel_vrw: f64,
    /// Measurement noise, velocity (m/s) and position (rad).
    pub velocity_sigma: f64,
    pub position_sigma: f64,
}

/// Which of the two filters.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Order {
    Reduced,
    Full,
}

/// A filter with its running cost.
#[derive(Debug, Clone)]
pub struct DriftFilter<const N: usize> {
    pub kf: KalmanFilter<f64, N>,
    pub order: Order,
    /// Time spent in predict + update, and the steps counted.
    pub busy: Duration,
    pub steps: u64,
}

fn noise_density(t: &Tuning) -> SMatrix<f64, NOISE_INPUTS, NOISE_INPUTS> {
    let (g, a) = (t.gyro_arw.powi(2), t.accel_vrw.powi(2));
    SMatrix::from_diagonal(&SVector::from([g, g, g, g, g, g, a, a, a, a]))
}

fn initial_diagonal<const N: usize>(t: &Tuning) -> SVector<f64, N> {
    let mut d = SVector::<f64, N>::zeros();
    // attitude differences of two independent systems: twice one's variance
    d[0] = 2.0 * t.attitude[0].powi(2);
    d[1] = d[0];
    d[2] = 2.0 * t.attitude[1].powi(2);
    // velocity and position differences start from a common fix: tiny
    for i in 3..7 {
        d[i] = if i < 5 { 1e-8 } else { 1e-18 };
    }
    if N == REDUCED_STATES {
        d[DRIFT_Z] = t.drift.powi(2);
    } else {
        // both systems' gyro drifts (EPS_1 .. EPS_2 + 3)
        for i in EPS_1..NABLA_1 {
            d[i] = t.other_drift.powi(2);
        }
        d[EPS_1 + 2] = t.drift.powi(2);
        for i in NABLA_1..NABLA_2 + 2 {
            d[i] = t.accel_bias.powi(2);
        }
    }
    d
}

impl<const N: usize> DriftFilter<N> {
    fn with(order: Order, t: &Tuning) -> Self {
        Self {
            kf: KalmanFilter::from_diagonal(&initial_diagonal::<N>(t)),
            order,
            busy: Duration::ZERO,
            steps: 0,
        }
    }

    /// Index of the backup's azimuth drift in this filter's state.
    pub fn drift_index(&self) -> usize {
        match self.order {
            Order::Reduced => DRIFT_Z,
            Order::Full => EPS_1 + 2,
        }
    }

    /// Estimate and 1-sigma of the backup's azimuth drift (rad/s); the
    /// sigma is NaN for an invalid variance.
    pub fn drift(&self) -> (f64, f64) {
        let i = self.drift_index();
        (self.kf.x[i], std_dev_of(self.kf.p[(i, i)]))
    }

    /// Measurement update with the difference of the two outputs (eq. 23).
    pub fn update(&mut self, z: &DifferenceMeasurement<f64>) -> UpdateReport {
        let start = Instant::now();
        let report = self.kf.update(z);
        self.busy += start.elapsed();
        report
    }
}

impl DriftFilter<REDUCED_STATES> {
    pub fn reduced(t: &Tuning) -> Self {
        Self::with(Order::Reduced, t)
    }

    /// Time update over `dt` with the backup's mean orientation over the
    /// step and the orientations at its middle (for Q).
    pub fn predict(
        &mut self,
        m: &Motion,
        c1: &Matrix3<f64>,
        mid: [&Matrix3<f64>; 2],
        dt: f64,
        t: &Tuning,
    ) {
        let start = Instant::now();
        let phi = transition(&reduced_dynamics(m, c1), dt);
        let g = reduced_noise_input(mid[0], mid[1]);
        let q = g * noise_density(t) * g.transpose() * dt;
        dense::predict(&mut self.kf.x, &mut self.kf.p, &phi, &q);
        self.busy += start.elapsed();
        self.steps += 1;
    }
}

impl DriftFilter<FULL_STATES> {
    pub fn full(t: &Tuning) -> Self {
        Self::with(Order::Full, t)
    }

    /// Time update of the full model: both systems' mean orientations over
    /// the step (the exact integral of a constant bias's forcing, to first
    /// order) and the orientations at its middle (for Q).
    pub fn predict(
        &mut self,
        m: &Motion,
        c: [&Matrix3<f64>; 2],
        mid: [&Matrix3<f64>; 2],
        dt: f64,
        t: &Tuning,
    ) {
        let start = Instant::now();
        let phi = transition(&full_dynamics(m, c[0], c[1]), dt);
        let g = full_noise_input(mid[0], mid[1]);
        let q = g * noise_density(t) * g.transpose() * dt;
        dense::predict(&mut self.kf.x, &mut self.kf.p, &phi, &q);
        self.busy += start.elapsed();
        self.steps += 1;
    }
}

/// Mean cost of one step (predict + update when there was one), in
/// microseconds; NaN before the first step.
pub fn micros_per_step<const N: usize>(f: &DriftFilter<N>) -> f64 {
    if f.steps == 0 {
        return f64::NAN;
    }
    f.busy.as_secs_f64() * 1e6 / f.steps as f64
}
