//! Cross-covariances of the state with snapshots of an earlier state.
//!
//! A snapshot is `LINKED` linear combinations `z = L x` of the error
//! state at some earlier time (a station's azimuth error and the gyro
//! biases, `probe::navigator_station`). Its covariance with the state of
//! now, `G = cov(x, z)` (N x LINKED), starts as `P L^T` and then follows
//! the state's own linear updates, with nothing added (the snapshot has
//! no dynamics and no noise):
//! - time update `x <- Phi x + w`: `G <- Phi G`;
//! - scalar measurement `x <- x + k (y - h^T x)`: `G <- G - k (h^T G)`;
//! - a state replaced by one independent of everything (a tie-in heading,
//!   a restored bias): its rows of G become 0.
//!
//! Each costs one column product per snapshot column: O(N) per scalar
//! update against the O(N^2) of P's. The filter keeps up to
//! `SNAPSHOTS` snapshots; empty ones cost nothing. Checked against a
//! filter whose state is augmented with the snapshot (tests below).

use super::{FilterScalar, SparseRow, Transition};
use nalgebra::SMatrix;

/// Combinations per snapshot.
pub const LINKED: usize = 3;
/// Snapshots kept at once: the station links' three
/// (`probe::station_link`) and the station block's gyro noise
/// (`probe::navigator_station`, [`CrossCovariances::start_zero`]).
pub const SNAPSHOTS: usize = 4;

/// One snapshot's `G = cov(x, z)`, column by column.
pub type Columns<T, const N: usize> = [[T; N]; LINKED];

/// Up to [`SNAPSHOTS`] cross-covariances, each present or not.
#[derive(Debug, Clone, PartialEq)]
pub struct CrossCovariances<T: FilterScalar, const N: usize> {
    slots: [Option<Columns<T, N>>; SNAPSHOTS],
}

impl<T: FilterScalar, const N: usize> Default for CrossCovariances<T, N> {
    fn default() -> Self {
        Self {
            slots: [None; SNAPSHOTS],
        }
    }
}

impl<T: FilterScalar, const N: usize> CrossCovariances<T, N> {
    /// Starts snapshot `slot` of `z = L x` now: `G = P L^T`, `l` holding
    /// L's rows (sparse: N multiplies per non-zero). An index out of range
    /// does nothing.
    pub fn start(&mut self, slot: usize, p: &SMatrix<T, N, N>, l: &[SparseRow<T>; LINKED]) {
        if let Some(s) = self.slots.get_mut(slot) {
            *s = Some(core::array::from_fn(|c| {
                let mut column = [T::zero(); N];
                for (j, coef) in l[c].entries() {
                    for (g, pij) in column.iter_mut().zip(p.column(j).iter()) {
                        *g += *pij * coef;
                    }
                }
                column
            }));
        }
    }

    /// Starts slot `slot` as zero columns: a quantity not yet correlated
    /// with the state, such as the sum of sensor noise still to come,
    /// which its owner then adds to ([`column_mut`](Self::column_mut))
    /// as the noise enters the state. An index out of range does nothing.
    pub fn start_zero(&mut self, slot: usize) {
        if let Some(s) = self.slots.get_mut(slot) {
            *s = Some([[T::zero(); N]; LINKED]);
        }
    }

    /// Column `column` of slot `slot`, if the slot is set.
    pub fn column(&self, slot: usize, column: usize) -> Option<&[T; N]> {
        self.slots.get(slot)?.as_ref()?.get(column)
    }

    /// The same, to write.
    pub fn column_mut(&mut self, slot: usize, column: usize) -> Option<&mut [T; N]> {
        self.slots.get_mut(slot)?.as_mut()?.get_mut(column)
    }

    /// `cov(L x, z_slot)` now (LINKED x LINKED, row = L's combination),
    /// or `None` for an empty slot.
    pub fn with(&self, slot: usize, l: &[SparseRow<T>; LINKED]) -> Option<[[T; LINKED]; LINKED]> {
        let g = self.slots.get(slot)?.as_ref()?;
        Some(core::array::from_fn(|r| {
            core::array::from_fn(|c| {
                l[r].entries()
                    .fold(T::zero(), |acc, (i, coef)| acc + coef * g[c][i])
            })
        }))
    }

    /// Moves snapshot `from` into slot `to` (emptying `from`).
    pub fn move_to(&mut self, from: usize, to: usize) {
        if from < SNAPSHOTS && to < SNAPSHOTS && from != to {
            self.slots[to] = self.slots[from].take();
        }
    }

    /// Empties slot `slot`.
    pub fn clear(&mut self, slot: usize) {
        if let Some(s) = self.slots.get_mut(slot) {
            *s = None;
        }
    }

    /// Empties every slot.
    pub fn clear_all(&mut self) {
        self.slots = [None; SNAPSHOTS];
    }

    /// Whether slot `slot` holds a snapshot.
    pub fn is_set(&self, slot: usize) -> bool {
        self.slots.get(slot).is_some_and(|s| s.is_some())
    }

    /// Every present column, for an update written by its caller.
    pub fn columns_mut(&mut self) -> impl Iterator<Item = &mut [T; N]> {
        self.slots.iter_mut().flatten().flat_map(|g| g.iter_mut())
    }

    /// Time update: `G <- Phi G`.
    pub fn predict<F: Transition<T, N>>(&mut self, phi: &F) {
        phi.apply_to_columns(self.columns_mut());
    }

    /// A scalar update with gain `k` and row `h`: `G <- G - k (h^T G)`.
    pub fn update(&mut self, k: &[T; N], h: &SparseRow<T>) {
        for column in self.columns_mut() {
            let hg = h
                .entries()
                .fold(T::zero(), |acc, (i, coef)| acc + coef * column[i]);
            for (g, ki) in column.iter_mut().zip(k) {
                *g -= *ki * hg;
            }
        }
    }

    /// States `first..first + count` replaced by values independent of
    /// every earlier one: their rows become 0.
    pub fn forget_states(&mut self, first: usize, count: usize) {
        for column in self.columns_mut() {
            for g in column.iter_mut().skip(first).take(count) {
                *g = T::zero();
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::dense::DenseTransition;
    use super::super::{KalmanFilter, ScalarMeasurement};
    use super::*;
    use nalgebra::SVector;

    const N: usize = 5;
    const A: usize = N + LINKED;

    /// The fast cross-covariance equals the corresponding block of a
    /// filter whose state is augmented with the snapshot z = L x (constant,
    /// noise-free), through time updates and scalar measurements.
    #[test]
    #[allow(clippy::needless_range_loop)] // (i, c) as in the matrices
    fn the_cross_covariance_follows_an_augmented_filter() {
        let value = |i: usize, j: usize| ((i * 7 + j * 3) % 11) as f64 * 0.1 - 0.5;
        let mut p0 = SMatrix::<f64, N, N>::from_fn(|i, j| value(i, j) * 0.3);
        p0 = p0 * p0.transpose() + SMatrix::identity();
        let l: [SparseRow<f64>; LINKED] = core::array::from_fn(|r| {
            let mut row = SparseRow::empty();
            for i in 0..N {
                row.push(i, value(r + 2, i));
            }
            row
        });
        let dense = |r: usize, i: usize| l[r].entries().find(|e| e.0 == i).map_or(0.0, |e| e.1);
        let mut fast = KalmanFilter::<f64, N>::new(p0);
        fast.cross.start(1, &fast.p, &l);
        // augmented state (x, z): P_aug = [[P, P L^T], [L P, L P L^T]]
        let lm = SMatrix::<f64, LINKED, N>::from_fn(dense);
        let mut pa = SMatrix::<f64, A, A>::zeros();
        pa.fixed_view_mut::<N, N>(0, 0).copy_from(&p0);
        pa.fixed_view_mut::<N, LINKED>(0, N)
            .copy_from(&(p0 * lm.transpose()));
        pa.fixed_view_mut::<LINKED, N>(N, 0).copy_from(&(lm * p0));
        pa.fixed_view_mut::<LINKED, LINKED>(N, N)
            .copy_from(&(lm * p0 * lm.transpose()));
        let mut slow = KalmanFilter::<f64, A>::new(pa);
        let phi =
            SMatrix::<f64, N, N>::from_fn(|i, j| if i == j { 1.0 } else { 0.05 * value(i, j) });
        let mut phi_a = SMatrix::<f64, A, A>::identity();
        phi_a.fixed_view_mut::<N, N>(0, 0).copy_from(&phi);
        let q = SVector::<f64, N>::from_fn(|i, _| 0.01 * (i + 1) as f64);
        let qa = SVector::<f64, A>::from_fn(|i, _| if i < N { q[i] } else { 0.0 });
        for step in 0..20 {
            fast.predict(&DenseTransition(phi), &q);
            slow.predict(&DenseTransition(phi_a), &qa);
            let i = step % N;
            let j = (step * 3 + 1) % N;
            let mut h = SparseRow::select(i);
            h.push(j, 0.5);
            let m = ScalarMeasurement {
                z: 0.1 * step as f64,
                h,
                r: 0.2,
            };
            assert!(fast.update_scalar(&m).is_accepted());
            assert!(slow.update_scalar(&m).is_accepted());
        }
        let cross = fast.cross.with(1, &l).unwrap();
        let g = fast.cross.slots[1].unwrap();
        for c in 0..LINKED {
            for i in 0..N {
                let want = slow.p[(i, N + c)];
                assert!((g[c][i] - want).abs() < 1e-12, "G[{i}][{c}]");
            }
            for r in 0..LINKED {
                let want: f64 = (0..N).map(|i| dense(r, i) * slow.p[(i, N + c)]).sum();
                assert!((cross[r][c] - want).abs() < 1e-12);
            }
        }
        assert!(fast.cross.with(0, &l).is_none(), "an empty slot has none");
        // the snapshot did not stay where it started
        assert!((g[0][0] - (p0 * lm.transpose())[(0, 0)]).abs() > 1e-3);
    }

    #[test]
    fn forgotten_states_have_no_cross_covariance_and_slots_move() {
        let p = SMatrix::<f64, N, N>::identity();
        let l: [SparseRow<f64>; LINKED] = core::array::from_fn(|r| {
            let mut row = SparseRow::empty();
            for i in 0..N {
                row.push(i, r as f64 + 1.0);
            }
            row
        });
        let mut c = CrossCovariances::<f64, N>::default();
        c.start(0, &p, &l);
        c.forget_states(1, 2);
        let g = c.slots[0].unwrap();
        assert_eq!(g[2], [3.0, 0.0, 0.0, 3.0, 3.0]);
        c.move_to(0, 2);
        assert!(!c.is_set(0) && c.is_set(2));
        c.clear_all();
        assert!(!c.is_set(2));
    }
}
