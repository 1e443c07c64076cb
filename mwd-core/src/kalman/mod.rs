//! Error-state Kalman filter, fixed size, no heap, generic over the scalar
//! (f32 on the probe, f64 on the host; paper section 2.4).
//!
//! - Time update (eq. 17-18) through a [`Transition`], which applies the
//!   discrete transition Phi (eq. 15) to a matrix from the left and forms
//!   the lower triangle of Phi P Phi^T, mirrored so P stays exactly
//!   symmetric. The structured 33- and 39-state transition of
//!   `error_model` does that in a fraction of the dense cost;
//!   [`dense::DenseTransition`] is the textbook reference.
//! - Measurement update (eq. 19-21) one scalar at a time with a sparse
//!   measurement row, the Joseph covariance (eq. 21) expanded to
//!   P - k c^T - c k^T + s k k^T, computed on the upper triangle and
//!   mirrored so P stays exactly symmetric.
//! - Every scalar is checked before it touches the filter: non-finite data
//!   or a non-positive innovation variance is rejected, and an optional
//!   chi-square gate on the normalised innovation squared rejects outliers.

mod cross;
pub mod dense;
mod measurement;
mod scalar;

pub use cross::{CrossCovariances, LINKED, SNAPSHOTS};
pub use measurement::{Measurement, ScalarMeasurement, SparseRow, Stacked, MAX_ROW_NONZEROS};
use nalgebra::{RealField, SMatrix, SVector};

/// The filter's scalar: f32 or f64.
pub trait FilterScalar: RealField + Copy {
    fn of(x: f64) -> Self;
    fn as_f64(self) -> f64;
}

impl FilterScalar for f32 {
    fn of(x: f64) -> Self {
        x as f32
    }
    fn as_f64(self) -> f64 {
        self as f64
    }
}

impl FilterScalar for f64 {
    fn of(x: f64) -> Self {
        x
    }
    fn as_f64(self) -> f64 {
        self
    }
}

/// A discrete state transition Phi that can be applied from the left.
pub trait Transition<T: FilterScalar, const N: usize> {
    /// `m <- Phi m`.
    fn apply_to_matrix(&self, m: &mut SMatrix<T, N, N>);
    /// `p <- Phi p Phi^T` for a symmetric `p`, of which only the lower
    /// triangle (row >= column) is used afterwards: an implementation may
    /// leave anything in the strict upper triangle. The default is
    /// Phi (Phi p)^T (p symmetric) with one transpose and two left products.
    fn propagate_lower(&self, p: &mut SMatrix<T, N, N>) {
        self.apply_to_matrix(p);
        p.transpose_mut();
        self.apply_to_matrix(p);
    }
    /// `x <- Phi x`.
    fn apply_to_vector(&self, x: &mut SVector<T, N>);
    /// `x <- Phi x` for each of `columns` (the snapshots' cross-covariances,
    /// `cross`). The default goes through [`apply_to_vector`]
    /// (Self::apply_to_vector) with a copy each way; a transition that can
    /// work in place does so.
    fn apply_to_columns<'a>(&self, columns: impl Iterator<Item = &'a mut [T; N]>)
    where
        T: 'a,
    {
        for column in columns {
            let mut v = SVector::<T, N>::from_column_slice(column);
            self.apply_to_vector(&mut v);
            column.copy_from_slice(v.as_slice());
        }
    }
}

/// What happened to one scalar measurement.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ScalarOutcome<T> {
    /// Used: innovation `z - h x` and its variance `h P h^T + r`.
    Accepted { innovation: T, variance: T },
    /// The normalised innovation squared exceeded the gate; not used.
    Gated { innovation: T, variance: T },
    /// Measurement value, row or variance not finite; not used.
    NonFinite,
    /// Innovation variance not positive (or not finite after the product);
    /// not used.
    Degenerate,
}

impl<T> ScalarOutcome<T> {
    pub fn is_accepted(&self) -> bool {
        matches!(self, ScalarOutcome::Accepted { .. })
    }
}

/// Counts of the outcomes of a (vector) measurement's scalars.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct UpdateReport {
    pub accepted: u8,
    pub gated: u8,
    pub non_finite: u8,
    pub degenerate: u8,
}

impl UpdateReport {
    pub fn all_accepted(&self) -> bool {
        self.gated == 0 && self.non_finite == 0 && self.degenerate == 0
    }

    pub(crate) fn count<T>(&mut self, outcome: &ScalarOutcome<T>) {
        let slot = match outcome {
            ScalarOutcome::Accepted { .. } => &mut self.accepted,
            ScalarOutcome::Gated { .. } => &mut self.gated,
            ScalarOutcome::NonFinite => &mut self.non_finite,
            ScalarOutcome::Degenerate => &mut self.degenerate,
        };
        *slot = slot.saturating_add(1);
    }
}

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
}

impl<T: FilterScalar, const N: usize> KalmanFilter<T, N> {
    /// A filter with zero state and the given initial covariance.
    pub fn new(p0: SMatrix<T, N, N>) -> Self {
        Self {
            x: SVector::zeros(),
            p: p0,
            gate: None,
            cross: CrossCovariances::default(),
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

/// sqrt of a variance: NaN for a negative or NaN one, +inf for +inf.
pub fn std_dev_of<T: FilterScalar>(variance: T) -> T {
    if variance >= T::zero() {
        variance.sqrt()
    } else {
        T::zero() / T::zero()
    }
}

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
