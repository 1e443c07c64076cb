//! Six-position calibration (MGWD paper section 3.2, Table 3): the probe
//! rests with each body axis in turn pointing up and down. At rest an
//! accelerometer triad reads +g along the up axis, so the six reference
//! inputs are +-g e_i and each triad's H = [K | C] (TLS paper eq. 20) follows
//! from a fit of the six position means: bias C, scale factors diag(K),
//! misalignment / cross-coupling off-diag(K). By LS or by TLS ([`super::tls`]).
//!
//! A gyro sensing body axis i reads b + s Omega sin(L) with i up and
//! b - s Omega sin(L) with i down (earth rate omega_ie^n = Omega (cos L, 0,
//! -sin L) in NED, its up component Omega sin L whatever the heading), so
//! the pair gives the bias with earth rate cancelled exactly, and the scale
//! factor from earth rate (coarse: 10 deg/h of signal).

use super::tls::{fit_coupling, Coupling, FitMethod};
use anyhow::{bail, Result};
use mwd_core::calibration::GyroCalibration;

/// Which body axis points up, and which way. File code in parentheses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub enum Face {
    /// +x up (1).
    XUp,
    /// -x up, x down (2).
    XDown,
    /// +y up (3).
    YUp,
    /// y down (4).
    YDown,
    /// +z up (5).
    ZUp,
    /// z down (6).
    ZDown,
}

/// The position's name in the calibration report.
impl std::fmt::Display for Face {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Self::XUp => "XUp",
            Self::XDown => "XDown",
            Self::YUp => "YUp",
            Self::YDown => "YDown",
            Self::ZUp => "ZUp",
            Self::ZDown => "ZDown",
        })
    }
}

impl Face {
    /// All six, in file-code order.
    pub const ALL: [Face; 6] = [
        Face::XUp,
        Face::XDown,
        Face::YUp,
        Face::YDown,
        Face::ZUp,
        Face::ZDown,
    ];

    /// Its code in the `position` column, 1..=6.
    pub fn code(self) -> usize {
        Self::ALL.iter().position(|&f| f == self).unwrap_or(0) + 1
    }

    /// The face of a file code 1..=6.
    pub fn from_code(code: f64) -> Option<Face> {
        let i = code as i64;
        (i as f64 == code && (1..=6).contains(&i)).then(|| Self::ALL[(i - 1) as usize])
    }

    /// Body axis index (0 = x) pointing up or down, and +1 for up, -1 for down.
    pub fn axis(self) -> (usize, f64) {
        let i = Self::ALL.iter().position(|&f| f == self).unwrap_or(0);
        (i / 2, if i % 2 == 0 { 1.0 } else { -1.0 })
    }

    /// Specific force an ideal triad reads at rest in this position.
    pub fn reference_force(self, gravity: f64) -> [f64; 3] {
        let (axis, sign) = self.axis();
        let mut f = [0.0; 3];
        f[axis] = sign * gravity;
        f
    }
}

/// Averages of every column over the samples of one position.
#[derive(Clone, Debug, PartialEq)]
pub struct PositionMean {
    /// The position.
    pub face: Face,
    /// Samples averaged.
    pub samples: usize,
    /// Mean of each column.
    pub mean: Vec<f64>,
    /// Standard error of each mean (sample sd / sqrt(n)), white-noise law.
    pub std_error: Vec<f64>,
}

/// Groups rows by their position code and averages each column.
/// `positions[r]` is the code of row r; `columns[c][r]` the data.
pub fn position_means(positions: &[f64], columns: &[&[f64]]) -> Result<Vec<PositionMean>> {
    let mut rows: Vec<Vec<usize>> = vec![Vec::new(); 6];
    for (r, &code) in positions.iter().enumerate() {
        let Some(face) = Face::from_code(code) else {
            bail!(
                "data row {}: position code {code} is not one of 1..6",
                r + 1
            );
        };
        rows[face.axis().0 * 2 + usize::from(face.axis().1 < 0.0)].push(r);
    }
    let mut out = Vec::new();
    for (face, idx) in Face::ALL.iter().zip(&rows) {
        if idx.len() < 2 {
            bail!(
                "position {} ({face}) has {} samples; each of the six needs at least 2",
                face.code(),
                idx.len()
            );
        }
        let n = idx.len() as f64;
        let (mut mean, mut se) = (Vec::new(), Vec::new());
        for col in columns {
            let m = idx.iter().map(|&r| col[r]).sum::<f64>() / n;
            let var = idx.iter().map(|&r| (col[r] - m).powi(2)).sum::<f64>() / (n - 1.0);
            mean.push(m);
            se.push((var / n).sqrt());
        }
        out.push(PositionMean {
            face: *face,
            samples: idx.len(),
            mean,
            std_error: se,
        });
    }
    Ok(out)
}

/// One triad's calibration with the noise bounds of its estimates.
#[derive(Clone, Debug, PartialEq)]
pub struct TriadResult {
    /// Fitting method.
    pub method: FitMethod,
    /// H = [K | C].
    pub coupling: Coupling,
    /// Standard error of each offset: the root-sum-square of the six
    /// position-mean errors / 6 (the offset is the mean of the six).
    pub bias_se: [f64; 3],
    /// Standard error of each K element: RSS of the up/down errors / 2g.
    pub k_se: [[f64; 3]; 3],
}

/// Calibrates the triad in columns `cols` (indices into the means).
pub fn calibrate_triad(
    means: &[PositionMean],
    cols: [usize; 3],
    gravity: f64,
    method: FitMethod,
) -> Result<TriadResult> {
    let inputs: Vec<[f64; 3]> = means
        .iter()
        .map(|m| m.face.reference_force(gravity))
        .collect();
    let outputs: Vec<[f64; 3]> = means.iter().map(|m| cols.map(|c| m.mean[c])).collect();
    let coupling = fit_coupling(&inputs, &outputs, method)?;
    let mut bias_se = [0.0; 3];
    let mut k_se = [[0.0; 3]; 3];
    for (row, &c) in cols.iter().enumerate() {
        bias_se[row] = means
            .iter()
            .map(|m| m.std_error[c].powi(2))
            .sum::<f64>()
            .sqrt()
            / means.len() as f64;
        for (axis, k) in k_se[row].iter_mut().enumerate() {
            let pair: f64 = means
                .iter()
                .filter(|m| m.face.axis().0 == axis)
                .map(|m| m.std_error[c].powi(2))
                .sum();
            *k = pair.sqrt() / (2.0 * gravity);
        }
    }
    Ok(TriadResult {
        method,
        coupling,
        bias_se,
        k_se,
    })
}

/// One gyro's calibration.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct GyroResult {
    /// Body axis sensed (0 = x).
    pub axis: usize,
    /// Bias (rad/s), earth rate cancelled.
    pub bias: f64,
    /// Its standard error.
    pub bias_se: f64,
    /// Scale factor from the earth-rate difference (coarse).
    pub scale: f64,
    /// Its standard error.
    pub scale_se: f64,
    /// The earth-rate component along the up axis used (rad/s).
    pub earth_rate_up: f64,
}

impl GyroResult {
    /// The probe's correction: bias only. The earth-rate scale estimate is
    /// reported but not applied (its error is larger than a datasheet scale).
    pub fn to_core(&self) -> GyroCalibration {
        GyroCalibration {
            bias: self.bias,
            scale: 1.0,
        }
    }
}

/// Calibrates the gyro in column `col` sensing body axis `axis`.
pub fn calibrate_gyro(
    means: &[PositionMean],
    col: usize,
    axis: usize,
    earth_rate_up: f64,
) -> Result<GyroResult> {
    let pick = |sign: f64| means.iter().find(|m| m.face.axis() == (axis, sign));
    let (Some(up), Some(down)) = (pick(1.0), pick(-1.0)) else {
        bail!("the gyro on axis {axis} needs both its up and down positions");
    };
    let se = (up.std_error[col].powi(2) + down.std_error[col].powi(2)).sqrt();
    Ok(GyroResult {
        axis,
        bias: 0.5 * (up.mean[col] + down.mean[col]),
        bias_se: 0.5 * se,
        scale: (up.mean[col] - down.mean[col]) / (2.0 * earth_rate_up),
        scale_se: se / (2.0 * earth_rate_up.abs()),
        earth_rate_up,
    })
}

/// Earth rate's up component Omega sin(L) at a geodetic latitude (rad).
pub fn earth_rate_up(latitude: f64) -> f64 {
    -mwd_core::earth::earth_rate_n(latitude)[2]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn faces_and_codes() {
        assert_eq!(Face::from_code(3.0), Some(Face::YUp));
        assert_eq!(Face::from_code(2.5), None);
        assert_eq!(Face::from_code(7.0), None);
        assert_eq!(Face::ZDown.reference_force(9.8), [0.0, 0.0, -9.8]);
        assert_eq!(Face::XUp.axis(), (0, 1.0));
        for (i, face) in Face::ALL.iter().enumerate() {
            assert_eq!(Face::from_code(face.code() as f64), Some(*face), "{i}");
        }
    }

    #[test]
    fn missing_position_is_an_error() {
        let pos = [1.0, 1.0, 2.0, 2.0];
        let col = [0.0; 4];
        let e = position_means(&pos, &[&col]).unwrap_err().to_string();
        assert!(e.contains("YUp"), "{e}");
        let e = position_means(&[9.0], &[&[0.0]]).unwrap_err().to_string();
        assert!(e.contains("row 1"), "{e}");
    }

    #[test]
    fn earth_rate_at_the_paper_site() {
        let lat = mwd_core::earth::Position::paper_site().lat;
        let up = earth_rate_up(lat);
        assert!((up - 7.292115e-5 * lat.sin()).abs() < 1e-15);
    }
}
