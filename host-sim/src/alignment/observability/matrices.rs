//! Controllability and observability matrices (paper section 2.4, and the
//! piece-wise constant systems of toolface indexing), their ranks and a
//! per-state report.
//!
//! The stacked matrices of the 33-state model are 33 x 1089 (ctrb with a
//! full noise input) and 198 x 33 (obsv with six measurements): too big for
//! the probe's stack, so this analysis lives on the host, in heap matrices.
//!
//! Numerical rank of such stacks is delicate: F's entries span g ~ 10 to
//! earth rate ~ 7e-5, and its powers up to F^32 span hundreds of decades.
//! [`rank`] is MATLAB's `rank` (tolerance max(m, n) eps sigma_max), to
//! compare with the paper's claims. For a statement about *which* states a
//! measurement determines, stack the discrete system over the real horizon
//! with noise-weighted rows ([`observability_matrix_discrete`]) and read
//! the [`ObservabilityReport`]: its `std_from_measurements` is what the
//! horizon's data alone can pin each state down to.

use nalgebra::{DMatrix, DVector, SMatrix};

/// A heap copy of a fixed-size matrix.
pub fn dynamic<const R: usize, const C: usize>(m: &SMatrix<f64, R, C>) -> DMatrix<f64> {
    DMatrix::from_column_slice(R, C, m.as_slice())
}

/// Controllability matrix `[G, F G, ..., F^(n-1) G]` (n = F's size).
pub fn controllability_matrix(f: &DMatrix<f64>, g: &DMatrix<f64>) -> DMatrix<f64> {
    let (n, m) = (f.nrows(), g.ncols());
    let mut out = DMatrix::zeros(n, n * m);
    let mut block = g.clone();
    for k in 0..n {
        out.view_mut((0, k * m), (n, m)).copy_from(&block);
        block = f * block;
    }
    out
}

/// Observability matrix `[H; H F; ...; H F^(n-1)]`.
pub fn observability_matrix(f: &DMatrix<f64>, h: &DMatrix<f64>) -> DMatrix<f64> {
    let (n, m) = (f.nrows(), h.nrows());
    let mut out = DMatrix::zeros(n * m, n);
    let mut block = h.clone();
    for k in 0..n {
        out.view_mut((k * m, 0), (m, n)).copy_from(&block);
        block *= f;
    }
    out
}

/// Observability matrix of the discrete system over `steps` samples,
/// `[H; H Phi; ...; H Phi^(steps-1)]`. With H's rows divided by the
/// measurement noise sigma, its singular values are information: a
/// direction with singular value s is determined to 1/s by the noisy
/// measurements of the horizon (no prior, no process noise).
pub fn observability_matrix_discrete(
    phi: &DMatrix<f64>,
    h: &DMatrix<f64>,
    steps: usize,
) -> DMatrix<f64> {
    let (n, m) = (phi.nrows(), h.nrows());
    let mut out = DMatrix::zeros(steps * m, n);
    let mut block = h.clone();
    for k in 0..steps {
        out.view_mut((k * m, 0), (m, n)).copy_from(&block);
        block *= phi;
    }
    out
}

/// Stripped observability matrix of a piece-wise constant system
/// (Goshen-Meskin and Bar-Itzhack): the segments' observability matrices
/// stacked, `[O_1; O_2; ...; O_r]`. Its rank equals the total
/// observability matrix's when [`stripping_condition_holds`].
pub fn stripped_observability_matrix(segments: &[(DMatrix<f64>, DMatrix<f64>)]) -> DMatrix<f64> {
    let blocks: Vec<DMatrix<f64>> = segments
        .iter()
        .map(|(f, h)| observability_matrix(f, h))
        .collect();
    let n = segments.first().map_or(0, |(f, _)| f.ncols());
    let rows = blocks.iter().map(|b| b.nrows()).sum();
    let mut out = DMatrix::zeros(rows, n);
    let mut r = 0;
    for b in &blocks {
        out.view_mut((r, 0), (b.nrows(), n)).copy_from(b);
        r += b.nrows();
    }
    out
}

/// Sufficient condition for the stripped matrix: the null space of each
/// segment's observability matrix lies in the null space of its F
/// (F v = 0 for every unobservable direction v).
pub fn stripping_condition_holds(segments: &[(DMatrix<f64>, DMatrix<f64>)]) -> bool {
    segments.iter().all(|(f, h)| {
        let o = observability_matrix(f, h);
        let null = null_space(&o, default_tolerance(&o));
        let scale = f.amax().max(f64::MIN_POSITIVE);
        null.iter().all(|v| (f * v).amax() <= 1e-9 * scale)
    })
}

fn singular_values(m: &DMatrix<f64>) -> DVector<f64> {
    m.clone().svd(false, false).singular_values
}

/// MATLAB's default rank tolerance: max(rows, cols) * eps * sigma_max.
pub fn default_tolerance(m: &DMatrix<f64>) -> f64 {
    let s = singular_values(m);
    m.nrows().max(m.ncols()) as f64 * f64::EPSILON * s.max()
}

/// Numerical rank with MATLAB's default tolerance.
pub fn rank(m: &DMatrix<f64>) -> usize {
    let tol = default_tolerance(m);
    singular_values(m).iter().filter(|s| **s > tol).count()
}

/// `m` with zero rows appended up to square: the SVD of M^T M would square
/// the condition number, while the padded SVD returns all n right vectors.
fn pad_rows(m: &DMatrix<f64>) -> DMatrix<f64> {
    let n = m.ncols();
    let mut padded = DMatrix::zeros(m.nrows().max(n), n);
    padded.view_mut((0, 0), (m.nrows(), n)).copy_from(m);
    padded
}

/// Right singular vectors of `m` whose singular values are at most `tol`,
/// including the directions beyond the row count of a wide matrix.
fn null_space(m: &DMatrix<f64>, tol: f64) -> Vec<DVector<f64>> {
    let n = m.ncols();
    let svd = pad_rows(m).svd(false, true);
    let Some(v_t) = svd.v_t else {
        return Vec::new();
    };
    (0..n)
        .filter(|&i| svd.singular_values[i] <= tol)
        .map(|i| v_t.row(i).transpose())
        .collect()
}

/// Which states an observability matrix determines, after scaling.
#[derive(Debug, Clone, PartialEq)]
pub struct ObservabilityReport {
    /// Singular values of the state-scaled matrix, largest first.
    pub singular_values: Vec<f64>,
    /// Unit right singular vector of the smallest singular value: the
    /// combination of (scaled) states the measurements see least.
    pub weakest_direction: DVector<f64>,
    /// Relative tolerance used: sigma <= tolerance * sigma_max is zero.
    pub tolerance: f64,
    pub rank: usize,
    /// Per state, in [0, 1]: the squared length of its unit vector's
    /// projection on the unobservable subspace (0 = fully observable).
    pub unobservable_share: Vec<f64>,
    /// Unit vectors spanning the unobservable subspace (scaled states).
    pub unobservable_directions: Vec<DVector<f64>>,
    /// Per state, in its own units: sqrt of the diagonal of (O^T O)^-1,
    /// infinite for a state touched by the unobservable subspace.
    pub std_from_measurements: Vec<f64>,
}

impl ObservabilityReport {
    /// `state_scale[i]` is the expected size of state i (e.g. sqrt(P0_ii)):
    /// the matrix is analysed in states divided by their scale (rows should
    /// already be in comparable units, e.g. divided by the measurement
    /// noise). Singular values at most `relative_tolerance * sigma_max`
    /// count as zero.
    pub fn new(o: &DMatrix<f64>, state_scale: &[f64], relative_tolerance: f64) -> Self {
        let n = o.ncols();
        let mut scaled = o.clone();
        for (j, s) in state_scale.iter().enumerate().take(n) {
            scaled.column_mut(j).scale_mut(*s);
        }
        let mut s: Vec<f64> = singular_values(&scaled).iter().copied().collect();
        s.sort_by(|a, b| b.total_cmp(a));
        let sigma_max = s.first().copied().unwrap_or(0.0);
        let tol = relative_tolerance * sigma_max;
        let null = null_space(&scaled, tol);
        let share = (0..n)
            .map(|i| null.iter().map(|v| v[i] * v[i]).sum())
            .collect();
        let svd = pad_rows(&scaled).svd(false, true);
        let mut weakest = DVector::zeros(n);
        let mut std = vec![0.0; n];
        if let Some(v_t) = &svd.v_t {
            let sv = &svd.singular_values;
            if let Some(i_min) = (0..n).min_by(|&a, &b| sv[a].total_cmp(&sv[b])) {
                weakest = v_t.row(i_min).transpose();
            }
            for (j, std_j) in std.iter_mut().enumerate() {
                let mut var = 0.0;
                for i in 0..n {
                    let v = v_t[(i, j)];
                    if v * v > 1e-24 {
                        var += if sv[i] > tol {
                            v * v / (sv[i] * sv[i])
                        } else {
                            f64::INFINITY
                        };
                    }
                }
                *std_j = libm::sqrt(var) * state_scale.get(j).copied().unwrap_or(1.0);
            }
        }
        Self {
            rank: n - null.len(),
            weakest_direction: weakest,
            std_from_measurements: std,
            singular_values: s,
            tolerance: relative_tolerance,
            unobservable_share: share,
            unobservable_directions: null,
        }
    }
}
