//! A station survey's drilling angles and their uncertainty from the
//! filter's attitude and attitude-error covariance.
//!
//! The angles (`conventions::DrillingAngles`): inclination = pi/2 + pitch,
//! azimuth = heading, gravity toolface = roll, of the Z-Y-X Euler angles of
//! C_b^n. The filter's attitude error phi is in the navigation frame
//! (computed C = (I - [phi x]) C_true, docs/filter-derivation.md section 1),
//! with covariance P_phi. To first order the angles' error is
//! d(inc, azi, tf) = J phi, where J's rows are the pitch, heading and roll
//! rows of `conventions::euler_error_jacobian` (the constant pi/2 and the
//! wrap to [0, 2 pi) do not change derivatives), so their covariance is
//! J P_phi J^T (first-order propagation of a covariance through a
//! function; J's derivation is written out at `euler_error_jacobian`; the
//! sign convention of phi flips J but not J P J^T). At a vertical tool
//! axis azimuth and toolface are undefined and their rows infinite.
//! Checked against central differences in the tests.

pub use crate::conventions::angles_and_jacobian;
use crate::kalman::std_dev_of;
use nalgebra::Matrix3;

/// Sigmas and correlations of (inc, azi, tf) from their covariance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AngleUncertainty {
    /// 1-sigma of inclination, azimuth, toolface (rad; NaN where the
    /// variance is not valid).
    pub sigma: [f64; 3],
    /// Correlations inc-azi, inc-tf, azi-tf.
    pub correlation: [f64; 3],
}

/// J P_phi J^T, as sigmas and correlations.
pub fn angle_uncertainty(jacobian: &Matrix3<f64>, attitude_cov: &Matrix3<f64>) -> AngleUncertainty {
    AngleUncertainty::from_covariance(&(jacobian * attitude_cov * jacobian.transpose()))
}

impl AngleUncertainty {
    /// The sigmas and correlations of (inc, azi, tf) with covariance `p`.
    pub fn from_covariance(p: &Matrix3<f64>) -> Self {
        let sigma = [0, 1, 2].map(|i| std_dev_of(p[(i, i)]));
        let corr = |i: usize, k: usize| p[(i, k)] / (sigma[i] * sigma[k]);
        Self {
            sigma,
            correlation: [corr(0, 1), corr(0, 2), corr(1, 2)],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::conventions::{
        dcm_from_euler, euler_from_dcm, skew, wrap_pi, DrillingAngles, Euler, DEG,
    };
    use nalgebra::Vector3;

    fn numeric_jacobian(c_bn: &Matrix3<f64>) -> Matrix3<f64> {
        let h = 1e-6;
        let angles = |phi: &Vector3<f64>| {
            let d = DrillingAngles::from_euler(&euler_from_dcm(
                &((Matrix3::identity() - skew(phi)) * c_bn),
            ));
            Vector3::new(d.inclination, d.azimuth, d.toolface)
        };
        Matrix3::from_fn(|i, k| {
            let mut d = Vector3::zeros();
            d[k] = h;
            wrap_pi(angles(&d)[i] - angles(&-d)[i]) / (2.0 * h)
        })
    }

    #[test]
    fn the_jacobian_matches_central_differences() {
        for (inc, azi, tf) in [
            (45.0, 120.0, 300.0),
            (10.0, 359.0, 1.0),
            (90.0, 0.5, 180.0),
            (120.0, 250.0, 45.0),
            (3.0, 30.0, 200.0),
        ] {
            let d = DrillingAngles {
                inclination: inc * DEG,
                azimuth: azi * DEG,
                toolface: tf * DEG,
            };
            let c = dcm_from_euler(&d.to_euler());
            let (angles, fast) = angles_and_jacobian(&c);
            assert!((angles.inclination - d.inclination).abs() < 1e-9);
            assert!(wrap_pi(angles.azimuth - d.azimuth).abs() < 1e-9);
            assert!(wrap_pi(angles.toolface - d.toolface).abs() < 1e-9);
            let slow = numeric_jacobian(&c);
            let scale = 1.0 / (inc * DEG).sin().powi(2);
            for (a, b) in fast.iter().zip(slow.iter()) {
                assert!((a - b).abs() < 1e-5 * scale, "{inc}: {fast} vs {slow}");
            }
        }
    }

    #[test]
    fn a_pure_tilt_error_moves_the_inclination_only_at_high_side_toolface() {
        // Toolface 0 (high side up), azimuth north: the tool axis is in the
        // north-down plane; a rotation about east (phi_e) tilts it.
        let d = DrillingAngles {
            inclination: 30.0 * DEG,
            azimuth: 0.0,
            toolface: 0.0,
        };
        let c = dcm_from_euler(&d.to_euler());
        let (_, j) = angles_and_jacobian(&c);
        let cov = Matrix3::from_diagonal(&Vector3::new(0.0, 1e-6, 0.0));
        let u = angle_uncertainty(&j, &cov);
        assert!((u.sigma[0] - 1e-3).abs() < 1e-9, "{u:?}");
        assert!(u.sigma[1] < 1e-12, "{u:?}");
    }

    #[test]
    fn correlations_are_within_one_and_a_bad_variance_is_nan() {
        let c = dcm_from_euler(&Euler::new(1.0, -0.4, 2.0));
        let (_, j) = angles_and_jacobian(&c);
        let cov = Matrix3::new(4e-6, 1e-6, 0.0, 1e-6, 3e-6, 5e-7, 0.0, 5e-7, 1e-4);
        let u = angle_uncertainty(&j, &cov);
        assert!(
            u.correlation.iter().all(|r| r.abs() <= 1.0 + 1e-12),
            "{u:?}"
        );
        let bad = angle_uncertainty(&j, &(-cov));
        assert!(bad.sigma.iter().all(|s| s.is_nan()), "{bad:?}");
    }
}
