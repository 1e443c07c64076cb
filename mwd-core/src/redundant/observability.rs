//! Observability of the reduced model (eq. 25-27): the stripped
//! observability matrix of a piece-wise constant system (Goshen-Meskin and
//! Bar-Itzhack [GMBI]) and its numerical rank.
//!
//! The paper's eq. 26 stops the powers of F_r at j - 1 (segment index);
//! the stripped matrix needs them up to n - 1 = 7 in every segment
//! (erratum RINS-5), so each segment contributes 4 x 8 = 32 rows.
//!
//! The raw matrix cannot be ranked as it stands: its entries run from
//! f_U ~ 10 m/s^2 to (Schuler rate)^7 ~ 1e-20, and a singular-value cut-off
//! relative to the largest would declare the drift column unobservable.
//! The rank is invariant under non-singular row and column scaling, so it is
//! taken of the dimensionless system: time in units of tau = sqrt(R / g)
//! (1 / Schuler rate, ~806 s), velocity in g tau, position (rad) as is,
//! drift in 1 / tau. Then every coupling of F tau is of order one or the
//! earth rate times tau (~0.06).

use super::measurement::measurement_matrix;
use super::model::REDUCED_STATES as N;
use crate::kalman::FilterScalar;
use nalgebra::{SMatrix, SVector};

/// Rows of one segment's block: 4 measurements times n = 8 powers.
pub const BLOCK_ROWS: usize = 4 * N;

/// State scales of the dimensionless system: (attitude 1, velocity g tau,
/// position 1, drift 1 / tau), and tau, for gravity `g` and earth radius
/// `radius`.
fn scales(g: f64, radius: f64) -> (SVector<f64, N>, f64) {
    let tau = libm::sqrt(radius / g);
    let v = g * tau;
    (
        SVector::from([1.0, 1.0, 1.0, v, v, 1.0, 1.0, 1.0 / tau]),
        tau,
    )
}

/// The dimensionless (F', H') = (tau D^-1 F D, D_z^-1 H D) of a reduced
/// model F_r and the measurements of eq. 24 (see the module notes).
pub fn nondimensional<T: FilterScalar>(
    f: &SMatrix<T, N, N>,
    g: f64,
    radius: f64,
) -> (SMatrix<T, N, N>, SMatrix<T, 4, N>) {
    let (d, tau) = scales(g, radius);
    let f = SMatrix::from_fn(|i, j| f[(i, j)] * T::of(tau * d[j] / d[i]));
    let dz = [d[3], d[4], 1.0, 1.0];
    let h0 = measurement_matrix::<T, N>();
    let h = SMatrix::from_fn(|i, j| h0[(i, j)] * T::of(d[j] / dz[i]));
    (f, h)
}

/// One segment's observability matrix O_j = [H; H F; ...; H F^7] (eq. 26
/// with erratum RINS-5).
pub fn observability_block<T: FilterScalar>(
    f: &SMatrix<T, N, N>,
    h: &SMatrix<T, 4, N>,
) -> SMatrix<T, BLOCK_ROWS, N> {
    let mut o = SMatrix::<T, BLOCK_ROWS, N>::zeros();
    let mut power = *h;
    for k in 0..N {
        o.fixed_view_mut::<4, N>(4 * k, 0).copy_from(&power);
        power *= f;
    }
    o
}

/// Rank of the stripped observability matrix O(m) = [O_1; ...; O_m]
/// (eq. 25) of the segments' reduced models F_r (in SI units; made
/// dimensionless here with gravity `g` and earth radius `radius`). The
/// stacked matrix is never formed: its rows are folded into the 8 x 8
/// triangular factor of a QR decomposition one segment at a time (the rank
/// of [R; O_j] is that of everything so far), so any number of segments
/// costs no memory. Singular values at most `relative_tolerance` times the
/// largest count as zero. No segments: rank 0.
pub fn stripped_rank<T: FilterScalar>(
    segments: &[SMatrix<T, N, N>],
    g: f64,
    radius: f64,
    relative_tolerance: T,
) -> usize {
    let mut r: Option<SMatrix<T, N, N>> = None;
    for f in segments {
        let (f, h) = nondimensional(f, g, radius);
        let block = observability_block(&f, &h);
        let mut stacked = SMatrix::<T, { BLOCK_ROWS + N }, N>::zeros();
        stacked
            .fixed_view_mut::<BLOCK_ROWS, N>(0, 0)
            .copy_from(&block);
        if let Some(previous) = &r {
            stacked
                .fixed_view_mut::<N, N>(BLOCK_ROWS, 0)
                .copy_from(previous);
        }
        r = Some(stacked.qr().r().fixed_view::<N, N>(0, 0).into_owned());
    }
    let Some(r) = r else {
        return 0;
    };
    let s = r.singular_values();
    let largest = s.max();
    s.iter()
        .filter(|v| **v > relative_tolerance * largest && largest > T::zero())
        .count()
}
