//! The time update's transition Phi (eq. 15), applied from the left.

use super::FilterScalar;
use nalgebra::{SMatrix, SVector};

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
