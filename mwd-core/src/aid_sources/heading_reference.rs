//! An azimuth from outside the probe: the master of the [RINS] paper's
//! master/backup pair (docs/redundant-rins.md, "The probe"). While a
//! reference heading lasts (the parent well's survey at the tie-in, a
//! magnetic MWD station away from steel, a second probe) the gyro probe is
//! the backup: each reference azimuth is one scalar update of the probe's
//! own filter, whose rate-bias states are correlated with its heading error
//! by the drilling since the last update, so the update learns the
//! azimuth drift (the paper's eps_z) as the reduced-order filter does from
//! the master-backup difference (eq. 19-24). The filter feeds the learned
//! biases back into the mechanization, so after the reference is lost the
//! probe's heading is propagated with the drift removed: the prediction and
//! compensation of eq. 31-33, done by the closed loop.
//!
//! The row: the computed azimuth's error is d(azi) = j . phi, with j the
//! azimuth row of `probe::station`'s Jacobian (`conventions::
//! euler_error_jacobian`, phi the navigation-frame attitude error); z is
//! the computed azimuth minus the reference, wrapped to (-pi, pi].

use super::attitude_angle::attitude_angle_scalar;
use crate::attitude::NEAR_VERTICAL;
use crate::conventions::angles_and_jacobian;
use crate::conventions::{dcm_from_quat, wrap_pi};
use crate::kalman::{FilterScalar, Measurement, ScalarMeasurement};
use crate::mechanization::NavState;

/// One reference azimuth against the filter's attitude: one scalar.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeadingReference<T> {
    /// Computed minus reference azimuth (rad, wrapped).
    pub azimuth_residual: T,
    /// d(azimuth) / d(phi).
    pub attitude_row: [T; 3],
    /// The reference's variance (rad^2).
    pub variance: T,
}

/// Why a reference azimuth was not used.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HeadingReferenceError {
    /// The azimuth is not a finite number.
    AzimuthNotFinite,
    /// The sigma is not a positive finite number.
    SigmaNotPositive,
    /// The tool axis is within `attitude::NEAR_VERTICAL` of vertical, where
    /// the probe reports no azimuth either.
    AzimuthUndefined,
}

impl<T: FilterScalar> HeadingReference<T> {
    /// The update at `state` for a reference `azimuth` (rad, true north)
    /// with 1-sigma `sigma` (rad).
    pub fn at(state: &NavState, azimuth: f64, sigma: f64) -> Result<Self, HeadingReferenceError> {
        if !azimuth.is_finite() {
            return Err(HeadingReferenceError::AzimuthNotFinite);
        }
        // also refuses NaN
        if !(sigma > 0.0 && sigma.is_finite()) {
            return Err(HeadingReferenceError::SigmaNotPositive);
        }
        let (angles, jacobian) = angles_and_jacobian(&dcm_from_quat(&state.attitude));
        let row: [f64; 3] = core::array::from_fn(|k| jacobian[(1, k)]);
        let inclined =
            (NEAR_VERTICAL..=core::f64::consts::PI - NEAR_VERTICAL).contains(&angles.inclination);
        if !(inclined && row.iter().all(|v| v.is_finite())) {
            return Err(HeadingReferenceError::AzimuthUndefined);
        }
        Ok(Self {
            azimuth_residual: T::of(wrap_pi(angles.azimuth - azimuth)),
            attitude_row: row.map(T::of),
            variance: T::of(sigma * sigma),
        })
    }
}

impl<T: FilterScalar> Measurement<T> for HeadingReference<T> {
    fn len(&self) -> usize {
        1
    }
    fn scalar(&self, k: usize) -> Option<ScalarMeasurement<T>> {
        if k != 0 {
            return None;
        }
        Some(attitude_angle_scalar(
            self.azimuth_residual,
            &self.attitude_row,
            self.variance,
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::conventions::{quat_from_euler, Euler, DEG};
    use crate::earth::Position;
    use nalgebra::{UnitQuaternion, Vector3};

    fn state(euler: Euler) -> NavState {
        NavState::at_rest(quat_from_euler(&euler), Position::paper_site())
    }

    /// z predicted by the row: a true attitude at the reference azimuth,
    /// the computed one rotated by a small phi (C = (I - [phi x]) C_true),
    /// the residual equals j . phi to first order.
    #[test]
    fn the_residual_is_the_row_times_the_attitude_error() {
        let truth = Euler::new(0.3, -0.05, 200.0 * DEG);
        let c_true = dcm_from_quat(&quat_from_euler(&truth));
        let phi = Vector3::new(2e-4, -3e-4, 5e-4);
        // the exact rotation by -phi; first order (I - [phi x])
        let c = nalgebra::Rotation3::new(-phi).into_inner() * c_true;
        let mut computed = state(truth);
        computed.attitude = UnitQuaternion::from_matrix(&c);
        let reference = angles_and_jacobian(&c_true).0.azimuth;
        let m = HeadingReference::<f64>::at(&computed, reference, 0.01).unwrap();
        let predicted: f64 = (0..3).map(|k| m.attitude_row[k] * phi[k]).sum();
        // second-order terms: |phi|^2 ~ 4e-7
        assert!(
            (m.azimuth_residual - predicted).abs() < 2e-6,
            "{} {}",
            m.azimuth_residual,
            predicted
        );
        assert!(m.azimuth_residual.abs() > 1e-4);
        assert_eq!(m.variance, 1e-4);
    }

    #[test]
    fn the_residual_wraps_across_north() {
        let s = state(Euler::new(0.0, 0.0, 359.0 * DEG));
        let m = HeadingReference::<f64>::at(&s, 1.0 * DEG, 0.01).unwrap();
        assert!((m.azimuth_residual + 2.0 * DEG).abs() < 1e-9);
    }

    #[test]
    fn bad_references_are_refused() {
        let s = state(Euler::new(0.0, 0.0, 1.0));
        let at = |azi: f64, sigma: f64| HeadingReference::<f64>::at(&s, azi, sigma).map(|_| ());
        assert_eq!(
            at(f64::NAN, 0.01),
            Err(HeadingReferenceError::AzimuthNotFinite)
        );
        assert_eq!(at(1.0, 0.0), Err(HeadingReferenceError::SigmaNotPositive));
        assert_eq!(
            at(1.0, f64::NAN),
            Err(HeadingReferenceError::SigmaNotPositive)
        );
        let vertical = state(Euler::new(0.0, 90.0 * DEG, 1.0));
        assert_eq!(
            HeadingReference::<f64>::at(&vertical, 1.0, 0.01).map(|_| ()),
            Err(HeadingReferenceError::AzimuthUndefined)
        );
    }
}
