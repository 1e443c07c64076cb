//! The dense textbook filter (eq. 17-21 with full matrices): the reference
//! the structured filter is tested and benchmarked against. Not for the
//! probe's cycle: a dense 33-state propagation is ~2 * 33^3 multiplies.

use super::{FilterScalar, Transition};
use nalgebra::{SMatrix, SVector};

/// A transition held as a full matrix.
#[derive(Debug, Clone, PartialEq)]
pub struct DenseTransition<T: FilterScalar, const N: usize>(pub SMatrix<T, N, N>);

impl<T: FilterScalar, const N: usize> Transition<T, N> for DenseTransition<T, N> {
    fn apply_to_matrix(&self, m: &mut SMatrix<T, N, N>) {
        *m = self.0 * *m;
    }
    fn apply_to_vector(&self, x: &mut SVector<T, N>) {
        *x = self.0 * *x;
    }
}

/// Time update, eq. 17-18: `x <- Phi x`, `P <- Phi P Phi^T + Q`.
pub fn predict<T: FilterScalar, const N: usize>(
    x: &mut SVector<T, N>,
    p: &mut SMatrix<T, N, N>,
    phi: &SMatrix<T, N, N>,
    q: &SMatrix<T, N, N>,
) {
    *x = phi * *x;
    *p = phi * *p * phi.transpose() + q;
}

/// Vector measurement update, eq. 19-21, with the gain from a matrix
/// inverse and the Joseph covariance. Returns false (nothing changed) when
/// `H P H^T + R` is not invertible.
pub fn update<T: FilterScalar, const N: usize, const M: usize>(
    x: &mut SVector<T, N>,
    p: &mut SMatrix<T, N, N>,
    z: &SVector<T, M>,
    h: &SMatrix<T, M, N>,
    r: &SMatrix<T, M, M>,
) -> bool {
    let s = h * *p * h.transpose() + r;
    let Some(s_inv) = s.try_inverse() else {
        return false;
    };
    let k = *p * h.transpose() * s_inv;
    *x += k * (z - h * *x);
    let i_kh = SMatrix::<T, N, N>::identity() - k * h;
    *p = i_kh * *p * i_kh.transpose() + k * r * k.transpose();
    true
}
