//! The horizontal error ellipse of a station from its NEV covariance.
//!
//! Convention: the 2x2 block `[[nn, ne], [ne, ee]]` (m^2, north/east) is
//! diagonalised; the 1-sigma semi-axes are the square roots of its
//! eigenvalues and the orientation is the azimuth of the major axis,
//! clockwise from the covariance's north, folded into [0, 180) deg (an axis
//! has no sense). A circle (equal eigenvalues) is given azimuth 0. The
//! ellipse at confidence `p` of a 2-D normal is the 1-sigma one scaled by
//! `k = sqrt(-2 ln(1 - p))` (p = 0.3935 gives k = 1; 0.95 gives 2.4477).
//! The vertical 1-sigma is `sqrt(vv)`, unscaled. (ISCWSA separation
//! factors use their own scaling of the 1-sigma axes; none is computed
//! here.)

/// The horizontal ellipse and the vertical sigma of one covariance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ellipse {
    /// 1-sigma semi-major axis, m.
    pub semi_major: f64,
    /// 1-sigma semi-minor axis, m.
    pub semi_minor: f64,
    /// Azimuth of the major axis, deg in [0, 180).
    pub azimuth_deg: f64,
    /// 1-sigma vertical, m.
    pub sigma_vert: f64,
}

impl Ellipse {
    /// From a NEV covariance `[nn, ee, vv, ne, nv, ev]`, m^2.
    pub fn from_cov(cov: &[f64; 6]) -> Self {
        let (nn, ee, vv, ne) = (cov[0], cov[1], cov[2], cov[3]);
        let mean = 0.5 * (nn + ee);
        let half = (0.5 * (nn - ee)).hypot(ne);
        let major = (mean + half).max(0.0);
        let minor = (mean - half).max(0.0);
        let mut azimuth_deg = (0.5 * (2.0 * ne).atan2(nn - ee)).to_degrees();
        if azimuth_deg < 0.0 {
            azimuth_deg += 180.0;
        }
        if azimuth_deg >= 180.0 {
            azimuth_deg -= 180.0;
        }
        Self {
            semi_major: major.sqrt(),
            semi_minor: minor.sqrt(),
            azimuth_deg,
            sigma_vert: vv.max(0.0).sqrt(),
        }
    }

    /// The semi-axes (major, minor) at confidence `p` of a 2-D normal.
    pub fn scaled(&self, p: f64) -> (f64, f64) {
        let k = scale_2d(p);
        (k * self.semi_major, k * self.semi_minor)
    }
}

/// The squared Mahalanobis distance of a north-east error `[n, e]` (m) in
/// the north-east covariance `[nn, ee, ne]` (m^2): inside the ellipse
/// holding `p` when at most `scale_2d(p)^2`. `None` where the covariance
/// is singular or not a number.
pub fn ne_mahalanobis2(cov_ne: [f64; 3], error_ne: [f64; 2]) -> Option<f64> {
    let [nn, ee, ne] = cov_ne;
    let [n, e] = error_ne;
    let det = nn * ee - ne * ne;
    if det.is_nan() || det <= 0.0 {
        return None;
    }
    Some((ee * n * n - 2.0 * ne * n * e + nn * e * e) / det)
}

/// `k = sqrt(-2 ln(1 - p))`: the ellipse of a 2-D normal holding
/// probability `p` is the 1-sigma ellipse times `k`.
pub fn scale_2d(p: f64) -> f64 {
    (-2.0 * (1.0 - p).ln()).sqrt()
}

/// A test covariance: the horizontal ellipse R diag(9, 1) R^T, semi-axes
/// 3 and 1 m with the major axis (cos a, sin a) in (N, E) at azimuth
/// `azimuth_deg`, and `vv` vertical.
#[cfg(test)]
pub(crate) fn three_by_one_cov(azimuth_deg: f64, vv: f64) -> [f64; 6] {
    let (s, c) = azimuth_deg.to_radians().sin_cos();
    [
        9.0 * c * c + s * s,
        9.0 * s * s + c * c,
        vv,
        8.0 * c * s,
        0.0,
        0.0,
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64, tol: f64) {
        assert!((a - b).abs() <= tol, "{a} vs {b}");
    }

    #[test]
    fn circle() {
        let e = Ellipse::from_cov(&[4.0, 4.0, 9.0, 0.0, 0.0, 0.0]);
        close(e.semi_major, 2.0, 1e-12);
        close(e.semi_minor, 2.0, 1e-12);
        close(e.azimuth_deg, 0.0, 1e-12);
        close(e.sigma_vert, 3.0, 1e-12);
    }

    #[test]
    fn known_two_by_two() {
        // [[3, 1], [1, 3]]: eigenvalues 4 and 2, major axis along N45E.
        let e = Ellipse::from_cov(&[3.0, 3.0, 0.0, 1.0, 0.0, 0.0]);
        close(e.semi_major, 2.0, 1e-12);
        close(e.semi_minor, 2f64.sqrt(), 1e-12);
        close(e.azimuth_deg, 45.0, 1e-12);
        // [[2, 0], [0, 5]]: major axis east.
        let e = Ellipse::from_cov(&[2.0, 5.0, 0.0, 0.0, 0.0, 0.0]);
        close(e.semi_major, 5f64.sqrt(), 1e-12);
        close(e.semi_minor, 2f64.sqrt(), 1e-12);
        close(e.azimuth_deg, 90.0, 1e-12);
    }

    #[test]
    fn orientation_of_a_rotated_ellipse() {
        for a_deg in [0.0, 10.0, 60.0, 90.0, 135.0, 179.0] {
            let e = Ellipse::from_cov(&three_by_one_cov(a_deg, 1.0));
            close(e.semi_major, 3.0, 1e-9);
            close(e.semi_minor, 1.0, 1e-9);
            close(e.azimuth_deg, a_deg, 1e-9);
        }
        // the same axis given as 190 deg folds to 10 deg
        let e = Ellipse::from_cov(&three_by_one_cov(190.0, 0.0));
        close(e.azimuth_deg, 10.0, 1e-9);
    }

    #[test]
    fn confidence_scale() {
        close(scale_2d(0.95), 2.447_746_830_680_816, 1e-12);
        close(scale_2d(1.0 - (-0.5f64).exp()), 1.0, 1e-12);
        let e = Ellipse::from_cov(&[4.0, 1.0, 0.0, 0.0, 0.0, 0.0]);
        let (a, b) = e.scaled(0.95);
        close(a, 2.0 * 2.447_746_830_680_816, 1e-12);
        close(b, 2.447_746_830_680_816, 1e-12);
    }
}
