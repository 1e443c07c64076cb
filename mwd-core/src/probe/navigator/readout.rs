//! The cycle's attitude as people read it: the Euler angles, their
//! Jacobian and their covariance J P_phi J^T (`crate::probe::station`),
//! computed once per cycle for the frame, the heading-loss check and the
//! station's survey.
//!
//! On the probe these are software f64 (the M4F's FPU is single precision):
//! a direction cosine matrix, four arctangents and two 3 x 3 products cost
//! ~25,000 instructions, and a station's cycle made them three times over
//! (its survey, its own sigmas, then the frame's), about a tenth of the
//! busiest cycle. The readout keeps the attitude and attitude covariance it
//! was made from, and is made again whenever either has changed since (a
//! command between the station and the frame, say), so a reader never
//! gets another state's angles.

use crate::conventions::{
    dcm_from_quat, euler_error_jacobian, euler_from_dcm, Euler, DRILLING_FROM_EULER,
};
use crate::error_model::{ATT, STATES_WITH_BIASES};
use crate::fine_alignment::FineAlignment;
use crate::kalman::{std_dev_of, FilterScalar};
use crate::probe::station::AngleUncertainty;
use nalgebra::{Matrix3, Vector3};

/// One attitude's angles and their first-order covariance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AttitudeReadout {
    /// What it was made from ([`key`]).
    attitude: [f64; 4],
    covariance_phi: [f64; 9],
    /// Roll, pitch, heading (rad).
    pub euler: Euler,
    /// d(roll, pitch, heading) / d(phi) (`conventions::euler_error_jacobian`).
    pub jacobian: Matrix3<f64>,
    /// The Euler angles' covariance J P_phi J^T (rad^2).
    pub covariance: Matrix3<f64>,
}

impl AttitudeReadout {
    /// The sigmas of roll, pitch and heading (rad; NaN where a variance is
    /// not valid: never a confident 0).
    pub fn euler_std(&self) -> Vector3<f64> {
        Vector3::from_fn(|i, _| std_dev_of(self.covariance[(i, i)]))
    }

    /// d(inc, azi, tf) / d(phi): the Jacobian's rows in the drilling order.
    pub fn drilling_jacobian(&self) -> Matrix3<f64> {
        Matrix3::from_fn(|i, k| self.jacobian[(DRILLING_FROM_EULER[i], k)])
    }

    /// The drilling angles' sigmas and correlations.
    pub fn drilling_uncertainty(&self) -> AngleUncertainty {
        AngleUncertainty::from_covariance(&Matrix3::from_fn(|i, k| {
            self.covariance[(DRILLING_FROM_EULER[i], DRILLING_FROM_EULER[k])]
        }))
    }
}

impl AttitudeReadout {
    /// The readout of `filter`'s attitude now.
    pub fn of<T: FilterScalar>(filter: &FineAlignment<T, STATES_WITH_BIASES>) -> Self {
        let (attitude, covariance_phi) = key(filter);
        let c_bn = dcm_from_quat(&filter.state().attitude);
        let jacobian = euler_error_jacobian(&c_bn);
        let phi = Matrix3::from_row_slice(&covariance_phi);
        Self {
            attitude,
            covariance_phi,
            euler: euler_from_dcm(&c_bn),
            jacobian,
            covariance: jacobian * phi * jacobian.transpose(),
        }
    }

    /// Whether this is the readout of `filter` as it is now: the same
    /// attitude and attitude covariance, bit for bit.
    pub fn is_of<T: FilterScalar>(&self, filter: &FineAlignment<T, STATES_WITH_BIASES>) -> bool {
        key(filter) == (self.attitude, self.covariance_phi)
    }
}

/// What a readout is made from: the attitude quaternion's coordinates and
/// the attitude-error covariance, row by row, in f64.
fn key<T: FilterScalar>(filter: &FineAlignment<T, STATES_WITH_BIASES>) -> ([f64; 4], [f64; 9]) {
    let q = filter.state().attitude.coords;
    let p = &filter.filter().p;
    (
        [q.x, q.y, q.z, q.w],
        core::array::from_fn(|k| p[(ATT + k / 3, ATT + k % 3)].as_f64()),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::probe::station::angle_uncertainty;
    use crate::probe::test_support::aligned_navigator;

    /// The readout is what the filter's own functions give, and it follows
    /// a changed attitude or covariance at once.
    #[test]
    fn the_readout_is_the_filters_angles_and_follows_any_change() {
        let mut navigator = aligned_navigator();
        let r = navigator.readout();
        let filter = &navigator.filter;
        let c_bn = dcm_from_quat(&filter.state().attitude);
        assert_eq!(r.euler, euler_from_dcm(&c_bn));
        assert_eq!(r.euler_std(), filter.euler_std());
        let (_, j) = crate::conventions::angles_and_jacobian(&c_bn);
        assert_eq!(r.drilling_jacobian(), j);
        let u = angle_uncertainty(&j, &filter.attitude_error_covariance());
        let v = r.drilling_uncertainty();
        for i in 0..3 {
            assert!(
                (u.sigma[i] - v.sigma[i]).abs() <= 1e-12 * u.sigma[i],
                "{u:?} {v:?}"
            );
        }

        // a changed covariance: made again
        navigator
            .filter
            .add_attitude_noise(&(Matrix3::identity() * 1e-4));
        let again = navigator.readout();
        assert!(again.euler_std().x > r.euler_std().x);
        assert_eq!(again.euler_std(), navigator.filter.euler_std());
        // a changed attitude: made again
        navigator.filter.set_roll(r.euler.roll + 0.5);
        let turned = navigator.readout();
        assert!((turned.euler.roll - r.euler.roll - 0.5).abs() < 1e-9);
    }
}
