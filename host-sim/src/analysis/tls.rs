//! Total least squares and the static decoupling of accelerometer triads
//! (TLS paper, Ding et al. 2011, eq. 13-23).
//!
//! The coupling model (eq. 13, 20): `A_out = H [Ax Ay Az 1]^T`, H = [K | C]
//! with K the 3x3 coupling (scale and misalignment) block and C the zero
//! offsets. Each row of H is a linear fit of one output against the
//! reference inputs (eq. 21). When the references carry errors too, least
//! squares is biased towards zero slope (errors-in-variables attenuation);
//! TLS (eq. 14-19) minimises the errors of inputs and outputs together.
//!
//! The column of ones in eq. 21 carries no error: fitting it by plain TLS
//! would perturb it. The intercept is therefore handled exactly by centring
//! (the mixed LS-TLS problem with one exact column): TLS on the centred
//! data gives the slopes, the means give the offset.

use anyhow::{bail, Result};
use mwd_core::calibration::TriadCalibration;
use nalgebra::{DMatrix, DVector, Matrix3, Matrix4, Vector3, Vector4};

/// How a row of H is fitted.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum FitMethod {
    /// Ordinary least squares: errors in the outputs only.
    Ls,
    /// Total least squares: errors in the reference inputs and the outputs.
    Tls,
}

/// The method as the command line and the calibration file name it.
impl std::fmt::Display for FitMethod {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Self::Ls => "ls",
            Self::Tls => "tls",
        })
    }
}

/// Classic TLS solution of `A x ~ b` (eq. 14-19): the right singular vector
/// v of `[A | b]` for the smallest singular value gives x = -v[..n] / v[n].
pub fn tls_solve(a: &DMatrix<f64>, b: &DVector<f64>) -> Result<DVector<f64>> {
    let (m, n) = a.shape();
    if m <= n || b.len() != m {
        bail!("TLS needs more equations ({m}) than unknowns ({n}) and a matching right-hand side");
    }
    let mut c = DMatrix::zeros(m, n + 1);
    c.view_mut((0, 0), (m, n)).copy_from(a);
    c.set_column(n, b);
    let svd = c.svd(false, true);
    let v_t = svd.v_t.ok_or_else(|| anyhow::anyhow!("SVD failed"))?;
    let smallest = svd
        .singular_values
        .iter()
        .enumerate()
        .min_by(|p, q| p.1.total_cmp(q.1))
        .map_or(0, |(i, _)| i);
    let v = v_t.row(smallest).transpose();
    let last = v[n];
    if last.abs() < 1e-12 {
        bail!("TLS problem is not generic: the smallest singular vector has no b component");
    }
    Ok(DVector::from_fn(n, |i, _| -v[i] / last))
}

/// Ordinary least squares `min |A x - b|` by SVD.
pub fn ls_solve(a: &DMatrix<f64>, b: &DVector<f64>) -> Result<DVector<f64>> {
    a.clone()
        .svd(true, true)
        .solve(b, 1e-14)
        .map_err(|e| anyhow::anyhow!("least squares: {e}"))
}

/// Fits `y ~ x . slopes + intercept` by LS or TLS (TLS on the centred data,
/// the intercept exact): one row of H in eq. 21.
pub fn fit_row(
    inputs: &DMatrix<f64>,
    y: &DVector<f64>,
    method: FitMethod,
) -> Result<(DVector<f64>, f64)> {
    let (m, n) = inputs.shape();
    if m != y.len() || m < n + 2 {
        bail!("{m} samples are too few to fit {n} slopes and an offset");
    }
    let means = DVector::from_fn(n, |j, _| inputs.column(j).mean());
    let y_mean = y.mean();
    let centred = DMatrix::from_fn(m, n, |i, j| inputs[(i, j)] - means[j]);
    let y_c = y.map(|v| v - y_mean);
    let slopes = match method {
        FitMethod::Ls => ls_solve(&centred, &y_c)?,
        FitMethod::Tls => tls_solve(&centred, &y_c)?,
    };
    let intercept = y_mean - means.dot(&slopes);
    Ok((slopes, intercept))
}

/// The 3x4 coupling matrix H = [K | C] of a triad (eq. 20-21) from
/// reference inputs and measured outputs, one row at a time.
pub fn fit_coupling(
    inputs: &[[f64; 3]],
    outputs: &[[f64; 3]],
    method: FitMethod,
) -> Result<Coupling> {
    if inputs.len() != outputs.len() {
        bail!(
            "{} reference inputs for {} outputs",
            inputs.len(),
            outputs.len()
        );
    }
    let a = DMatrix::from_fn(inputs.len(), 3, |i, j| inputs[i][j]);
    let mut h = [[0.0; 4]; 3];
    for (row, h_row) in h.iter_mut().enumerate() {
        let y = DVector::from_fn(outputs.len(), |i, _| outputs[i][row]);
        let (slopes, offset) = fit_row(&a, &y, method)?;
        *h_row = [slopes[0], slopes[1], slopes[2], offset];
    }
    Ok(Coupling { h })
}

/// A triad's coupling-coefficient matrix H = [K | C] (eq. 20).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Coupling {
    /// Rows: the three outputs; columns: Ax, Ay, Az, 1.
    pub h: [[f64; 4]; 3],
}

impl Coupling {
    /// The 3x3 coupling block K (scale factors on the diagonal).
    pub fn k(&self) -> Matrix3<f64> {
        Matrix3::from_fn(|i, j| self.h[i][j])
    }

    /// Zero offsets C.
    pub fn offsets(&self) -> Vector3<f64> {
        Vector3::new(self.h[0][3], self.h[1][3], self.h[2][3])
    }

    /// Reconstructed input (eq. 22-23) by the Moore-Penrose inverse. H is
    /// augmented with the row [0 0 0 1] and the output with a 1: the paper's
    /// pinv of the bare 3x4 H returns the minimum-norm 4-vector, whose last
    /// element is not 1, so the offsets would not be removed.
    pub fn reconstruct(&self, output: [f64; 3]) -> Result<[f64; 3]> {
        let aug = Matrix4::from_fn(|i, j| {
            if i < 3 {
                self.h[i][j]
            } else if j == 3 {
                1.0
            } else {
                0.0
            }
        });
        let pinv = aug
            .pseudo_inverse(1e-12)
            .map_err(|e| anyhow::anyhow!("pseudo-inverse: {e}"))?;
        let x = pinv * Vector4::new(output[0], output[1], output[2], 1.0);
        Ok([x[0], x[1], x[2]])
    }

    /// The probe's correction step for this triad: corrected = K^-1 (raw - C).
    pub fn to_triad_calibration(&self) -> Result<TriadCalibration> {
        let m = self
            .k()
            .try_inverse()
            .ok_or_else(|| anyhow::anyhow!("coupling block K is singular"))?;
        let c = self.offsets();
        Ok(TriadCalibration {
            bias: [c[0], c[1], c[2]],
            correction: [
                [m[(0, 0)], m[(0, 1)], m[(0, 2)]],
                [m[(1, 0)], m[(1, 1)], m[(1, 2)]],
                [m[(2, 0)], m[(2, 1)], m[(2, 2)]],
            ],
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_data_gives_exact_solutions() {
        let a = DMatrix::from_row_slice(4, 2, &[1.0, 0.0, 0.0, 1.0, 1.0, 1.0, 2.0, -1.0]);
        let x = DVector::from_vec(vec![0.5, -2.0]);
        let b = &a * &x;
        assert!((tls_solve(&a, &b).unwrap() - &x).norm() < 1e-12);
        assert!((ls_solve(&a, &b).unwrap() - &x).norm() < 1e-12);
    }

    #[test]
    fn tls_is_orthogonal_regression() {
        // Points on y = x plus symmetric perpendicular offsets: the
        // orthogonal (TLS) fit is y = x exactly, LS is flatter.
        let xs = [-2.0, -1.0, 1.0, 2.0];
        let mut a = Vec::new();
        let mut b = Vec::new();
        for (i, &x) in xs.iter().enumerate() {
            let d = if i == 0 || i == 3 { 0.3 } else { -0.3 };
            a.push(x + d);
            b.push(x - d);
        }
        let am = DMatrix::from_vec(4, 1, a);
        let bv = DVector::from_vec(b);
        let (tls, _) = fit_row(&am, &bv, FitMethod::Tls).unwrap();
        let (ls, _) = fit_row(&am, &bv, FitMethod::Ls).unwrap();
        assert!((tls[0] - 1.0).abs() < 1e-12, "{tls}");
        assert!(ls[0] < 0.99, "{ls}");
    }

    #[test]
    fn coupling_round_trip() {
        let h = Coupling {
            h: [
                [1.001, 0.002, -0.001, 0.01],
                [0.0015, 0.999, 0.0007, -0.02],
                [-0.0004, 0.001, 1.002, 0.003],
            ],
        };
        let truth = [0.3, -9.8, 0.7];
        let k = h.k();
        let out = k * Vector3::from(truth) + h.offsets();
        let rec = h.reconstruct([out[0], out[1], out[2]]).unwrap();
        let cal = h
            .to_triad_calibration()
            .unwrap()
            .apply([out[0], out[1], out[2]]);
        for i in 0..3 {
            assert!((rec[i] - truth[i]).abs() < 1e-12);
            assert!((cal[i] - truth[i]).abs() < 1e-12);
        }
        let inputs: Vec<[f64; 3]> = (0..8)
            .map(|i| [i as f64, (i * i) as f64 * 0.1, -(i as f64)])
            .collect();
        let inputs: Vec<[f64; 3]> = inputs
            .iter()
            .enumerate()
            .map(|(i, v)| [v[0], v[1], v[2] + (i % 3) as f64])
            .collect();
        let outputs: Vec<[f64; 3]> = inputs
            .iter()
            .map(|v| {
                let o = k * Vector3::from(*v) + h.offsets();
                [o[0], o[1], o[2]]
            })
            .collect();
        for method in [FitMethod::Ls, FitMethod::Tls] {
            let fit = fit_coupling(&inputs, &outputs, method).unwrap();
            for i in 0..3 {
                for j in 0..4 {
                    assert!(
                        (fit.h[i][j] - h.h[i][j]).abs() < 1e-9,
                        "{method:?} {:?}",
                        fit.h
                    );
                }
            }
        }
    }
}
