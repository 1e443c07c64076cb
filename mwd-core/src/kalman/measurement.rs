//! What the filter takes as a measurement (paper eq. 19-21): a few
//! scalars, each `z = h^T x + v` with a sparse row `h` and noise variance
//! `r`. Adding an aiding source (non-holonomic constraint, measured depth,
//! external heading) means one small type in `crate::aid_sources` that
//! implements [`Measurement`]; the filter needs nothing else.

use super::FilterScalar;

/// Most non-zeros in one measurement row: enough for an attitude-and-
/// velocity constraint (3 + 3) with room to spare.
pub const MAX_ROW_NONZEROS: usize = 8;

/// A sparse measurement row: `h^T x = sum coef[k] * x[index[k]]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SparseRow<T> {
    index: [u8; MAX_ROW_NONZEROS],
    coef: [T; MAX_ROW_NONZEROS],
    len: u8,
}

impl<T: FilterScalar> SparseRow<T> {
    /// The unit row selecting state `i` (the selection matrices of eq. 48).
    pub fn select(i: usize) -> Self {
        let mut row = Self::empty();
        row.push(i, T::one());
        row
    }

    pub fn empty() -> Self {
        Self {
            index: [0; MAX_ROW_NONZEROS],
            coef: [T::zero(); MAX_ROW_NONZEROS],
            len: 0,
        }
    }

    /// Adds `coef * x[i]`; returns false (row unchanged) when full or `i`
    /// does not fit the index type.
    pub fn push(&mut self, i: usize, coef: T) -> bool {
        let n = self.len as usize;
        match u8::try_from(i) {
            Ok(i) if n < MAX_ROW_NONZEROS => {
                self.index[n] = i;
                self.coef[n] = coef;
                self.len += 1;
                true
            }
            _ => false,
        }
    }

    /// The (state index, coefficient) pairs.
    pub fn entries(&self) -> impl Iterator<Item = (usize, T)> + '_ {
        self.index
            .iter()
            .zip(self.coef.iter())
            .take(self.len as usize)
            .map(|(&i, &c)| (i as usize, c))
    }
}

/// One scalar measurement: value `z`, row `h`, noise variance `r`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScalarMeasurement<T> {
    pub z: T,
    pub h: SparseRow<T>,
    pub r: T,
}

/// A measurement made of `len()` scalars with uncorrelated noise.
pub trait Measurement<T: FilterScalar> {
    fn len(&self) -> usize;
    /// Scalar `k < len()`; `None` if `k` is out of range.
    fn scalar(&self, k: usize) -> Option<ScalarMeasurement<T>>;
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
}
