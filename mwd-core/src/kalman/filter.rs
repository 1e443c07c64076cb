//! The filter itself: its estimate and covariance, the time update and
//! the scalar measurement updates, and the covariance's health check.

use super::measurement::{Measurement, ScalarMeasurement};
use super::numeric::{std_dev_of, FilterScalar};
use super::outcome::{ScalarOutcome, UpdateReport};
use super::scalar;
use super::transition::Transition;
use super::CrossCovariances;
use core::ops::Range;
use nalgebra::{SMatrix, SVector};

/// State estimate and covariance of an error-state filter with `N` states.
#[derive(Debug, Clone, PartialEq)]
pub struct KalmanFilter<T: FilterScalar, const N: usize> {
    /// Error-state estimate (computed - true).
    pub x: SVector<T, N>,
    /// Its covariance.
    pub p: SMatrix<T, N, N>,
    /// Chi-square threshold on `innovation^2 / variance` (1 degree of
    /// freedom), e.g. 9 for 3 sigma; `None` disables gating.
    pub gate: Option<T>,
    /// The state's covariance with snapshots of earlier states, kept
    /// through every time and measurement update here (`cross`).
    pub cross: CrossCovariances<T, N>,
    /// States no measurement updates: their gain is set to zero, the
    /// Schmidt-Kalman "consider" states (Schmidt 1966; Simon, Optimal
    /// State Estimation, 2006, section 7.5). Their estimate and variance
    /// stay as they were, and the Joseph form keeps their covariance with
    /// the updated states right for that gain. Empty: every state learns.
    pub consider: Range<usize>,
}

impl<T: FilterScalar, const N: usize> KalmanFilter<T, N> {
    /// A filter with zero state and the given initial covariance.
    pub fn new(p0: SMatrix<T, N, N>) -> Self {
        Self {
            x: SVector::zeros(),
            p: p0,
            gate: None,
            cross: CrossCovariances::default(),
            consider: 0..0,
        }
    }

    /// A filter with zero state and diagonal initial covariance.
    pub fn from_diagonal(p0_diag: &SVector<T, N>) -> Self {
        Self::new(SMatrix::from_diagonal(p0_diag))
    }

    /// Time update, eq. 17-18: `x <- Phi x`, `P <- Phi P Phi^T + Q` with a
    /// diagonal discrete process noise `q_diag` (Gamma Q Gamma^T of eq. 18
    /// for noise that enters single states).
    pub fn predict<F: Transition<T, N>>(&mut self, phi: &F, q_diag: &SVector<T, N>) {
        phi.apply_to_vector(&mut self.x);
        self.cross.predict(phi);
        self.propagate_covariance(phi, q_diag);
    }

    /// The covariance half of [`predict`](Self::predict), for runs that
    /// only study P (e.g. long static covariance checks).
    pub fn propagate_covariance<F: Transition<T, N>>(&mut self, phi: &F, q_diag: &SVector<T, N>) {
        // Phi P Phi^T is symmetric: its lower triangle is formed (the
        // structured transition skips most of the rest) and mirrored, so P
        // stays exactly symmetric.
        phi.propagate_lower(&mut self.p);
        for i in 0..N {
            self.p[(i, i)] += q_diag[i];
        }
        mirror_lower(&mut self.p);
    }

    /// One scalar measurement (eq. 19-21 with a 1 x N row). Leaves the
    /// filter untouched unless the outcome is `Accepted`.
    pub fn update_scalar(&mut self, m: &ScalarMeasurement<T>) -> ScalarOutcome<T> {
        let outcome = scalar::joseph_update(
            &mut self.x,
            &mut self.p,
            m,
            self.gate,
            &mut self.cross,
            None,
            self.consider.clone(),
        );
        if outcome.is_accepted() {
            mirror_upper(&mut self.p);
        }
        outcome
    }

    /// One scalar whose measurement noise already entered the state:
    /// `noise_cross` is `E[x v]`, the prior error's covariance with it
    /// (`scalar::joseph_update`). Leaves the filter untouched unless the
    /// outcome is `Accepted`.
    pub fn update_scalar_correlated(
        &mut self,
        m: &ScalarMeasurement<T>,
        noise_cross: &[T; N],
    ) -> ScalarOutcome<T> {
        let outcome = scalar::joseph_update(
            &mut self.x,
            &mut self.p,
            m,
            self.gate,
            &mut self.cross,
            Some(noise_cross),
            self.consider.clone(),
        );
        if outcome.is_accepted() {
            mirror_upper(&mut self.p);
        }
        outcome
    }

    /// All scalars of a measurement, one after another (equivalent to the
    /// vector update for uncorrelated measurement noise).
    pub fn update<M: Measurement<T>>(&mut self, m: &M) -> UpdateReport {
        let mut report = UpdateReport::default();
        for k in 0..m.len() {
            let outcome = match m.scalar(k) {
                Some(s) => scalar::joseph_update(
                    &mut self.x,
                    &mut self.p,
                    &s,
                    self.gate,
                    &mut self.cross,
                    None,
                    self.consider.clone(),
                ),
                None => ScalarOutcome::NonFinite,
            };
            report.count(&outcome);
        }
        // The scalar updates kept the upper triangle; restore the rest once.
        if report.accepted > 0 {
            mirror_upper(&mut self.p);
        }
        report
    }

    /// The normalised innovation squared `(z - h x)^2 / (h P h^T + r)` of
    /// one scalar at the current estimate, the filter untouched: for a
    /// consistency test a caller decides on before it uses a measurement
    /// at all (the rate gyrocompass: `probe::navigator`). `None` where it
    /// is not a finite number over a positive variance.
    pub fn normalized_innovation_squared(&self, m: &ScalarMeasurement<T>) -> Option<T> {
        let mut predicted = T::zero();
        let mut variance = m.r;
        for (i, a) in m.h.entries() {
            predicted += a * *self.x.get(i)?;
            for (j, b) in m.h.entries() {
                variance += a * b * *self.p.get((i, j))?;
            }
        }
        let innovation = m.z - predicted;
        let nis = innovation * innovation / variance;
        (variance > T::zero() && nis.is_finite()).then_some(nis)
    }

    /// Trace of P.
    pub fn trace(&self) -> T {
        self.p.trace()
    }

    /// Standard deviation of state `i`: NaN for a negative or NaN
    /// variance (an invalid covariance is never reported as a number),
    /// +inf for an infinite one.
    pub fn std_dev(&self, i: usize) -> T {
        std_dev_of(self.p[(i, i)])
    }

    /// The covariance health check (run by the probe every cycle): every
    /// variance finite, positive and at most `variance_limit` (in the
    /// states' own units squared), and every correlation |P_ij| <=
    /// sqrt(P_ii P_jj) within `CORRELATION_SLACK`, the 2 x 2 minors a
    /// positive semi-definite matrix must have non-negative. Cost: N square
    /// roots, then one multiply and compare per entry of the lower triangle
    /// (~N^2/2).
    // `!(a <= b)`, not `a > b`: a NaN correlation must fail the check.
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    pub fn covariance_is_healthy(&self, variance_limit: T) -> bool {
        let d = &self.p.data.0; // d[column][row]
        let diagonal: [T; N] = core::array::from_fn(|i| d[i][i]);
        if !diagonal
            .iter()
            .all(|&v| v > T::zero() && v <= variance_limit)
        {
            return false;
        }
        // Compared as |P_ij| > sqrt(P_ii) sqrt(P_jj), not P_ij^2 > P_ii P_jj:
        // the squares of the quiet grades' small entries (bias and noise
        // states, 1e-20 and below) fall below f32's smallest normal number,
        // and subnormal products cost x86 a hundred cycles each (the lateral
        // studies spent 18 % of their time in this check). The sigmas'
        // products stay normal down to variances of 1e-38.
        let sigma: [T; N] = core::array::from_fn(|i| diagonal[i].sqrt());
        let slack = (T::one() + T::of(CORRELATION_SLACK)).sqrt();
        // No early exit inside the columns: a healthy covariance (the
        // every-cycle case) reads them all anyway, and without the branch
        // the host's compiler runs the column in SIMD lanes.
        let mut unhealthy = false;
        for (j, column) in d.iter().enumerate() {
            let sj = sigma[j] * slack;
            unhealthy |= column[j + 1..]
                .iter()
                .zip(&sigma[j + 1..])
                .fold(false, |bad, (&pij, &si)| bad | !(pij.abs() <= sj * si));
        }
        !unhealthy
    }
}

/// How far |P_ij|^2 may exceed P_ii P_jj before the covariance counts as
/// not positive semi-definite: a few f32 roundings of the products (the
/// levelling prior puts some tilt-bias correlations at exactly 1).
pub const CORRELATION_SLACK: f64 = 1e-5;

// The triangle loops below are index loops running down the columns (i
// outer): the cheapest form on the M4F (measured, ~4.8 instructions per f32
// entry at N = 33; the iterator forms cost up to 60 % more).

/// Copies the lower triangle of `p` onto its upper triangle.
#[allow(clippy::needless_range_loop)]
fn mirror_lower<T: FilterScalar, const N: usize>(p: &mut SMatrix<T, N, N>) {
    let d = &mut p.data.0; // d[column][row]
    for i in 0..N {
        for j in i + 1..N {
            d[j][i] = d[i][j];
        }
    }
}

/// Copies the upper triangle of `p` onto its lower triangle.
#[allow(clippy::needless_range_loop)]
fn mirror_upper<T: FilterScalar, const N: usize>(p: &mut SMatrix<T, N, N>) {
    let d = &mut p.data.0; // d[column][row]
    for i in 0..N {
        for j in i + 1..N {
            d[i][j] = d[j][i];
        }
    }
}
