//! Scalar measurement update with a sparse row, Joseph form (eq. 19-21).

use super::measurement::ScalarMeasurement;
use super::{CrossCovariances, FilterScalar, ScalarOutcome};
use core::ops::Range;
use nalgebra::{SMatrix, SVector};

/// Updates `x` and `p` with one scalar; on any rejection both are left as
/// they were. Reads and writes only the upper triangle of `p` (the lower one
/// is stale afterwards: the caller mirrors it once per measurement, which
/// saves a strided N^2/2 copy per scalar). Cost ~N^2/2 for the covariance,
/// O(N * nnz) for the rest.
///
/// `noise_cross`, where given, is `E[x v]`: the prior error's covariance
/// with the scalar's measurement noise, for noise that already entered the
/// state (a gyro's samples both propagated the attitude and make the
/// measurement). Then `c = P h + s` and the variance `h^T P h + 2 h^T s +
/// r` (Simon, Optimal State Estimation, 2006, section 7.1), and the
/// covariance update below is unchanged in form.
///
/// `consider`: states whose gain is set to zero (the Schmidt-Kalman
/// filter's consider states, `KalmanFilter::consider`): the Joseph form
/// below holds for any gain, so their covariance with the rest stays
/// right while their estimate and variance do not move.
pub(super) fn joseph_update<T: FilterScalar, const N: usize>(
    x: &mut SVector<T, N>,
    p: &mut SMatrix<T, N, N>,
    m: &ScalarMeasurement<T>,
    gate: Option<T>,
    cross: &mut CrossCovariances<T, N>,
    noise_cross: Option<&[T; N]>,
    consider: Range<usize>,
) -> ScalarOutcome<T> {
    let row_finite = m.h.entries().all(|(i, c)| i < N && c.is_finite());
    if !(m.z.is_finite() && m.r.is_finite() && m.r >= T::zero() && row_finite) {
        return ScalarOutcome::NonFinite;
    }

    // c = P h, and h^T P h. Column i of P from the upper triangle: rows
    // 0..=i of stored column i, then row i of the later columns.
    let mut c = [T::zero(); N];
    {
        let d = &p.data.0; // d[column][row]
        for (i, coef) in m.h.entries() {
            let column = &d[i];
            for (cr, v) in c[..=i].iter_mut().zip(&column[..=i]) {
                *cr += coef * *v;
            }
            for (cr, later) in c[i + 1..].iter_mut().zip(&d[i + 1..]) {
                *cr += coef * later[i];
            }
        }
    }
    let hph =
        m.h.entries()
            .fold(T::zero(), |acc, (i, coef)| acc + coef * c[i]);
    let mut variance = hph + m.r;
    if let Some(s) = noise_cross {
        if !s.iter().all(|v| v.is_finite()) {
            return ScalarOutcome::NonFinite;
        }
        let hs =
            m.h.entries()
                .fold(T::zero(), |acc, (i, coef)| acc + coef * s[i]);
        variance += hs + hs;
        for (ci, si) in c.iter_mut().zip(s) {
            *ci += *si;
        }
    }
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

    // Gain, eq. 19: the inverse is one reciprocal for a scalar (the Joseph
    // form below is right for any gain, so its rounding does not matter).
    let inverse = T::one() / variance;
    let mut k = [T::zero(); N];
    let mut finite = true;
    for (ki, ci) in k.iter_mut().zip(&c) {
        *ki = if inverse.is_finite() {
            *ci * inverse
        } else {
            *ci / variance
        };
        finite &= ki.is_finite();
    }
    if !finite {
        return ScalarOutcome::Degenerate;
    }
    if let Some(held) = k.get_mut(consider) {
        held.fill(T::zero());
    }

    // The snapshots' cross-covariances take the same gain (`cross`).
    cross.update(&k, &m.h);

    // State, eq. 20.
    for (xi, ki) in x.iter_mut().zip(&k) {
        *xi += innovation * *ki;
    }

    // Covariance, eq. 21. Expanding (I - k h^T) P (I - k h^T)^T + r k k^T
    // with c = P h and s = h^T c + r gives P - k c^T - c k^T + s k k^T
    // (with a noise cross-covariance, c and s as above: the same form),
    // exactly and for any gain k: an error dk in the gain changes P only by
    // s dk dk^T (second order, the Joseph form's robustness), and every term
    // is symmetric, so the upper triangle is computed and mirrored: about a
    // quarter of the work of the two matrix products.
    // The M4F (no SIMD) keeps a block of rows' k_i and c_i in registers;
    // a host with SIMD lanes runs each column's rows contiguously: there the
    // compiler vectorizes the blocked loop across columns, with gathers, and
    // the lateral studies spent 28 % of their time in it. Each entry is the
    // same expression in either order, so the host keeps the probe's bits.
    #[cfg(target_arch = "arm")]
    joseph_upper::<T, N, 8>(&mut p.data.0, &k, &c, variance);
    #[cfg(not(target_arch = "arm"))]
    joseph_last_rows(&mut p.data.0, &k, &c, variance, 0);

    ScalarOutcome::Accepted {
        innovation,
        variance,
    }
}

/// `p_ij += k_i (s k_j - c_j) - c_i k_j` on the upper triangle (i <= j),
/// in blocks of `R` rows: right of the block's diagonal part, its k_i and
/// c_i stay in registers while the columns go by (~4.5 instructions per
/// f32 entry on the M4F against ~10 column by column).
#[inline(always)]
#[cfg_attr(not(target_arch = "arm"), allow(dead_code))] // the host's tests use it
fn joseph_upper<T: FilterScalar, const N: usize, const R: usize>(
    d: &mut [[T; N]; N], // d[column][row]
    k: &[T; N],
    c: &[T; N],
    s: T,
) {
    let mut b = 0;
    while b + R <= N {
        let kb: [T; R] = core::array::from_fn(|r| k[b + r]);
        let cb: [T; R] = core::array::from_fn(|r| c[b + r]);
        let after = b + R;
        // The block's diagonal part (unrolled: R is a constant).
        for jj in 0..R {
            let (kj, cj) = (kb[jj], cb[jj]);
            let skj = s * kj - cj;
            let column = &mut d[b + jj][b..after];
            for ii in 0..R {
                if ii <= jj {
                    column[ii] = column[ii] + kb[ii] * skj - cb[ii] * kj;
                }
            }
        }
        for ((column, kj), cj) in d[after..].iter_mut().zip(&k[after..]).zip(&c[after..]) {
            let skj = s * *kj - *cj;
            for ((pij, ki), ci) in column[b..after].iter_mut().zip(&kb).zip(&cb) {
                *pij = *pij + *ki * skj - *ci * *kj;
            }
        }
        b = after;
    }
    joseph_last_rows(d, k, c, s, b);
}

/// The same on the rows `first..N`, upper triangle, column by column: on
/// the probe the rows left over after the blocks (fewer than a block), on
/// a SIMD host the whole triangle (`first` = 0).
#[inline(always)]
fn joseph_last_rows<T: FilterScalar, const N: usize>(
    d: &mut [[T; N]; N],
    k: &[T; N],
    c: &[T; N],
    s: T,
    first: usize,
) {
    for (j, column) in d.iter_mut().enumerate().skip(first) {
        let (kj, cj) = (k[j], c[j]);
        let skj = s * kj - cj;
        let rows = first..=j;
        // Zipped slices, not indices: no bounds checks, so the host's
        // compiler runs the rows in SIMD lanes.
        for ((pij, ki), ci) in column[rows.clone()]
            .iter_mut()
            .zip(&k[rows.clone()])
            .zip(&c[rows])
        {
            *pij = *pij + *ki * skj - *ci * kj;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kalman::SparseRow;

    /// The probe's blocked loop and the host's column loop compute each
    /// entry with the same expression, so the host replays the probe's
    /// bits.
    #[test]
    fn the_probes_blocked_order_and_the_hosts_column_order_give_the_same_bits() {
        const N: usize = 39;
        // Entries of many magnitudes and both signs, none special.
        let value = |i: usize, j: usize| {
            let m = ((i * 7 + j * 13) % 17) as f32 - 8.5;
            m * 10f32.powi(((i + 2 * j) % 9) as i32 - 4)
        };
        let mut blocked: [[f32; N]; N] =
            core::array::from_fn(|j| core::array::from_fn(|i| value(i, j)));
        let mut columns = blocked;
        let k: [f32; N] = core::array::from_fn(|i| value(i, 3) * 1e-3);
        let c: [f32; N] = core::array::from_fn(|i| value(5, i));
        joseph_upper::<f32, N, 8>(&mut blocked, &k, &c, 3.7);
        joseph_last_rows(&mut columns, &k, &c, 3.7, 0);
        for j in 0..N {
            for i in 0..N {
                assert_eq!(
                    blocked[j][i].to_bits(),
                    columns[j][i].to_bits(),
                    "({i}, {j})"
                );
            }
        }
        assert_ne!(blocked[20][10], value(10, 20), "the update changed nothing");
    }

    /// A positive definite covariance of four states, all but one pair
    /// correlated.
    fn four_state_covariance() -> SMatrix<f64, 4, 4> {
        SMatrix::from_row_slice(&[
            4.0, 1.0, 0.5, 0.0, //
            1.0, 3.0, 0.2, 0.1, //
            0.5, 0.2, 2.0, 0.3, //
            0.0, 0.1, 0.3, 1.0,
        ])
    }

    /// A scalar whose noise v is correlated with the prior error (E[x v]
    /// = s) is an ordinary scalar of the state augmented with v: z = h^T
    /// x + v with P_a = [[P, s], [s^T, r]] and a zero noise. The
    /// correlated update must give the augmented filter's marginal.
    #[test]
    fn a_correlated_scalar_is_the_augmented_states_update() {
        const N: usize = 4;
        let p = four_state_covariance();
        let s = [0.3, -0.2, 0.0, 0.1];
        let r = 0.8;
        let mut h = SparseRow::empty();
        h.push(0, 1.0);
        h.push(2, -0.5);
        let m = ScalarMeasurement { z: 0.7, h, r };

        let mut x = SVector::<f64, N>::zeros();
        let mut pc = p;
        let mut cross = CrossCovariances::default();
        let outcome = joseph_update(&mut x, &mut pc, &m, None, &mut cross, Some(&s), 0..0);
        assert!(outcome.is_accepted());

        const A: usize = N + 1;
        let mut pa = SMatrix::<f64, A, A>::zeros();
        for i in 0..N {
            for j in 0..N {
                pa[(i, j)] = p[(i, j)];
            }
            pa[(i, N)] = s[i];
            pa[(N, i)] = s[i];
        }
        pa[(N, N)] = r;
        let mut ha = SparseRow::empty();
        ha.push(0, 1.0);
        ha.push(2, -0.5);
        ha.push(N, 1.0);
        let ma = ScalarMeasurement {
            z: 0.7,
            h: ha,
            r: 0.0,
        };
        let mut xa = SVector::<f64, A>::zeros();
        let mut cross_a = CrossCovariances::default();
        let outcome = joseph_update(&mut xa, &mut pa, &ma, None, &mut cross_a, None, 0..0);
        assert!(outcome.is_accepted());
        for i in 0..N {
            assert!((x[i] - xa[i]).abs() < 1e-12, "x[{i}]");
            for j in i..N {
                // the upper triangle is the updated one
                assert!((pc[(i, j)] - pa[(i, j)]).abs() < 1e-12, "P[{i},{j}]");
            }
        }
        // and it differs from the update that ignores the correlation
        let mut xu = SVector::<f64, N>::zeros();
        let mut pu = p;
        joseph_update(&mut xu, &mut pu, &m, None, &mut cross, None, 0..0);
        assert!((xu[0] - x[0]).abs() > 1e-3);
    }

    #[test]
    fn a_non_finite_noise_cross_covariance_is_refused() {
        let mut x = SVector::<f64, 2>::zeros();
        let mut p = SMatrix::<f64, 2, 2>::identity();
        let mut h = SparseRow::empty();
        h.push(0, 1.0);
        let m = ScalarMeasurement { z: 1.0, h, r: 1.0 };
        let mut cross = CrossCovariances::default();
        let outcome = joseph_update(
            &mut x,
            &mut p,
            &m,
            None,
            &mut cross,
            Some(&[f64::NAN, 0.0]),
            0..0,
        );
        assert!(matches!(outcome, ScalarOutcome::NonFinite));
        assert_eq!(p, SMatrix::<f64, 2, 2>::identity());
    }

    /// A consider state (Schmidt-Kalman): its estimate and variance do not
    /// move, and the covariance is the Joseph form's for the gain with
    /// that row zeroed, (I - k h^T) P (I - k h^T)^T + r k k^T, computed
    /// densely here.
    #[test]
    fn a_consider_state_keeps_its_estimate_and_the_joseph_covariance_of_its_gain() {
        const N: usize = 4;
        let p = four_state_covariance();
        let r = 0.8;
        let mut h = SparseRow::empty();
        h.push(0, 1.0);
        h.push(3, 0.5);
        let m = ScalarMeasurement { z: 0.7, h, r };
        let mut x = SVector::<f64, N>::from_column_slice(&[0.0, 0.0, 0.0, 0.25]);
        let mut pc = p;
        let mut cross = CrossCovariances::default();
        let outcome = joseph_update(&mut x, &mut pc, &m, None, &mut cross, None, 3..4);
        assert!(outcome.is_accepted());
        assert_eq!(x[3], 0.25, "a consider state's estimate moved");
        assert_eq!(pc[(3, 3)], p[(3, 3)], "a consider state's variance moved");

        let hv = SVector::<f64, N>::from_column_slice(&[1.0, 0.0, 0.0, 0.5]);
        let s = (hv.transpose() * p * hv)[(0, 0)] + r;
        let mut k = p * hv / s;
        k[3] = 0.0;
        let a = SMatrix::<f64, N, N>::identity() - k * hv.transpose();
        let dense = a * p * a.transpose() + k * k.transpose() * r;
        for i in 0..N {
            for j in i..N {
                assert!((pc[(i, j)] - dense[(i, j)]).abs() < 1e-12, "P[{i},{j}]");
            }
        }
        // the optimal update would have moved it
        let mut xo = SVector::<f64, N>::zeros();
        let mut po = p;
        joseph_update(&mut xo, &mut po, &m, None, &mut cross, None, 0..0);
        assert!(po[(3, 3)] < p[(3, 3)] - 1e-3);
    }
}
