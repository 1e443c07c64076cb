//! Scalar measurement update with a sparse row, Joseph form (eq. 19-21).

use super::{FilterScalar, ScalarOutcome};
use crate::measurement::ScalarMeasurement;
use nalgebra::{SMatrix, SVector};

/// Updates `x` and `p` with one scalar; on any rejection both are left as
/// they were. Reads and writes only the upper triangle of `p` (the lower one
/// is stale afterwards: the caller mirrors it once per measurement, which
/// saves a strided N^2/2 copy per scalar). Cost ~N^2/2 for the covariance,
/// O(N * nnz) for the rest.
pub(super) fn joseph_update<T: FilterScalar, const N: usize>(
    x: &mut SVector<T, N>,
    p: &mut SMatrix<T, N, N>,
    m: &ScalarMeasurement<T>,
    gate: Option<T>,
) -> ScalarOutcome<T> {
    let row_finite = m.h.entries().all(|(i, c)| i < N && c.is_finite());
    if !(m.z.is_finite() && m.r.is_finite() && m.r >= T::zero() && row_finite) {
        return ScalarOutcome::NonFinite;
    }

    // c = P h, and h^T P h. Column i of P from the upper triangle: rows
    // 0..=i of stored column i, then row i of the later columns.
    let mut c = SVector::<T, N>::zeros();
    {
        let data = p.as_slice(); // column-major: (r, i) at i * N + r
        for (i, coef) in m.h.entries() {
            for (r, cr) in c.iter_mut().enumerate() {
                let v = if r <= i {
                    data[i * N + r]
                } else {
                    data[r * N + i]
                };
                *cr += coef * v;
            }
        }
    }
    let hph =
        m.h.entries()
            .fold(T::zero(), |acc, (i, coef)| acc + coef * c[i]);
    let variance = hph + m.r;
    if !(variance.is_finite() && variance > T::zero()) {
        return ScalarOutcome::Degenerate;
    }

    let predicted =
        m.h.entries()
            .fold(T::zero(), |acc, (i, coef)| acc + coef * x[i]);
    let innovation = m.z - predicted;
    if !innovation.is_finite() {
        return ScalarOutcome::NonFinite;
    }
    if let Some(threshold) = gate {
        if innovation * innovation > threshold * variance {
            return ScalarOutcome::Gated {
                innovation,
                variance,
            };
        }
    }

    // Gain, eq. 19 (the inverse is a division for a scalar).
    let k = c / variance;
    if !k.iter().all(|v| v.is_finite()) {
        return ScalarOutcome::Degenerate;
    }

    // State, eq. 20.
    x.axpy(innovation, &k, T::one());

    // Covariance, eq. 21. Expanding (I - k h^T) P (I - k h^T)^T + r k k^T
    // with c = P h and s = h^T c + r gives P - k c^T - c k^T + s k k^T,
    // exactly and for any gain k: an error dk in the gain changes P only by
    // s dk dk^T (second order, the Joseph form's robustness), and every term
    // is symmetric, so the upper triangle is computed and mirrored: about a
    // quarter of the work of the two matrix products.
    let (k, c) = (k.as_slice(), c.as_slice());
    let data = p.as_mut_slice(); // column-major: (i, j) at j * N + i
    for j in 0..N {
        let (kj, cj) = (k[j], c[j]);
        let skj = variance * kj - cj;
        let column = &mut data[j * N..j * N + j + 1];
        for ((pij, ki), ci) in column.iter_mut().zip(&k[..=j]).zip(&c[..=j]) {
            *pij = *pij + *ki * skj - *ci * kj;
        }
    }

    ScalarOutcome::Accepted {
        innovation,
        variance,
    }
}
