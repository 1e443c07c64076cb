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

/// Two measurements made at the same solution, taken in one update: `A`'s
/// scalars, then `B`'s. Each scalar is compared with the estimate the ones
/// before it left (the filter's state still holds their correction), which
/// two updates with a feedback between them would not do for a `B` built
/// before the feedback: its value would be read against the corrected
/// solution as if nothing had moved (the drilling constraints,
/// `probe::navigator`). One update also mirrors the covariance once.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stacked<A, B>(pub A, pub B);

impl<T: FilterScalar, A: Measurement<T>, B: Measurement<T>> Measurement<T> for Stacked<A, B> {
    fn len(&self) -> usize {
        self.0.len() + self.1.len()
    }
    fn scalar(&self, k: usize) -> Option<ScalarMeasurement<T>> {
        match k.checked_sub(self.0.len()) {
            None => self.0.scalar(k),
            Some(j) => self.1.scalar(j),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kalman::KalmanFilter;
    use nalgebra::{SMatrix, SVector};

    /// One scalar: `z = x[i]` with variance `r`.
    struct Select(usize, f64, f64);

    impl Measurement<f64> for Select {
        fn len(&self) -> usize {
            1
        }
        fn scalar(&self, k: usize) -> Option<ScalarMeasurement<f64>> {
            (k == 0).then(|| ScalarMeasurement {
                z: self.1,
                h: SparseRow::select(self.0),
                r: self.2,
            })
        }
    }

    #[test]
    fn stacked_scalars_come_in_order_and_end_where_both_end() {
        let m = Stacked(
            Select(0, 1.0, 2.0),
            Stacked(Select(1, 3.0, 4.0), Select(2, 5.0, 6.0)),
        );
        assert_eq!(m.len(), 3);
        let z: [f64; 3] = core::array::from_fn(|k| m.scalar(k).map_or(f64::NAN, |s| s.z));
        assert_eq!(z, [1.0, 3.0, 5.0]);
        assert!(m.scalar(3).is_none());
    }

    /// Stacked, the same as the two updates one after the other without a
    /// feedback between them (the filter's state carries the first's
    /// correction into the second's innovation).
    #[test]
    fn a_stacked_update_is_the_two_updates_in_turn() {
        let p0 = SMatrix::<f64, 3, 3>::new(4.0, 1.0, 0.5, 1.0, 3.0, -0.7, 0.5, -0.7, 2.0);
        let mut stacked = KalmanFilter::new(p0);
        let mut in_turn = KalmanFilter::new(p0);
        let (a, b) = (Select(0, 1.5, 0.5), Select(1, -0.8, 0.25));
        let report = stacked.update(&Stacked(Select(0, 1.5, 0.5), Select(1, -0.8, 0.25)));
        in_turn.update(&a);
        in_turn.update(&b);
        assert_eq!(report.accepted, 2);
        assert!((stacked.x - in_turn.x).norm() < 1e-15);
        assert!((stacked.p - in_turn.p).norm() < 1e-15);
        // and not what a second update built at the first's prior gives
        // once the first's correction has left the state (a feedback)
        let mut fed_back = KalmanFilter::new(p0);
        fed_back.update(&a);
        let moved = fed_back.x[1];
        fed_back.x = SVector::zeros();
        fed_back.update(&b);
        assert!(moved.abs() > 0.1);
        assert!((fed_back.x[1] + moved - in_turn.x[1]).abs() > 0.05);
    }
}
