//! The attitude and its error covariance from outside the filter's own
//! updates: a tie-in's attitude and heading, a re-roll, the drilling
//! environment's attitude noise; and the attitude's sigmas.

use super::filter::FineAlignment;
use crate::conventions::{dcm_from_quat, euler_error_jacobian, euler_from_quat, quat_from_euler};
use crate::error_model::ATT;
use crate::kalman::{std_dev_of, FilterScalar};
use nalgebra::{Matrix3, Vector3};

impl<T: FilterScalar, const N: usize> FineAlignment<T, N> {
    /// Replaces the attitude-error covariance (rad^2, nav frame) and clears
    /// its cross-covariances with every other state: an attitude from
    /// outside the probe's own sensors (a tie-in survey) is independent of
    /// their errors. `p_phi` must be symmetric positive semi-definite.
    pub fn set_attitude_error_covariance(&mut self, p_phi: &Matrix3<f64>) {
        self.forget_states(ATT, 3);
        let p = &mut self.filter.p;
        for i in 0..3 {
            for j in 0..3 {
                p[(ATT + i, ATT + j)] = T::of(p_phi[(i, j)]);
            }
        }
    }

    /// Adds `q` (rad^2, nav frame, symmetric positive semi-definite) to the
    /// attitude-error covariance: process noise that is not isotropic, such
    /// as the drilling environment's (the vibration turns the tool about
    /// its cross axes, the orienter about its own axis; derivation section
    /// 4d), added after the step's own time update.
    pub fn add_attitude_noise(&mut self, q: &Matrix3<f64>) {
        let p = &mut self.filter.p;
        for i in 0..3 {
            for j in 0..3 {
                p[(ATT + i, ATT + j)] += T::of(q[(i, j)]);
            }
        }
    }

    /// Makes the heading error independent of every other state, its
    /// variance kept: the other states' own (marginal) covariance is
    /// unchanged; what goes is the first-order link through which an
    /// update of any of them would move the heading, and a heading update
    /// them. For a heading the filter cannot carry to first order
    /// (`probe::Navigator`, an undetermined heading).
    pub fn decouple_heading(&mut self) {
        let variance = self.filter.p[(ATT + 2, ATT + 2)];
        self.forget_states(ATT + 2, 1);
        self.filter.p[(ATT + 2, ATT + 2)] = variance;
    }

    /// Turns the solution about the vertical by `angle` (rad, exact, not a
    /// small-angle correction) and makes the heading error independent of
    /// everything else with variance `variance` (rad^2): a heading given
    /// from outside the probe's sensors (a tie-in survey's azimuth), which
    /// replaces the probe's own. A turn about the vertical keeps the
    /// inclination and toolface, and the tilt errors' covariance with the
    /// sensor states (the levelling's own accelerometer biases) is kept.
    pub fn set_heading(&mut self, angle: f64, variance: f64) {
        let mut state = *self.strapdown.state();
        let turn = nalgebra::UnitQuaternion::from_axis_angle(&Vector3::z_axis(), angle);
        state.attitude = turn * state.attitude;
        self.strapdown.reset(state);
        self.forget_states(ATT + 2, 1);
        self.filter.p[(ATT + 2, ATT + 2)] = T::of(variance);
        self.filter.x[ATT + 2] = T::zero();
    }

    /// Turns the solution about the tool axis so that its roll is `roll`
    /// (rad), exactly (not a small-angle correction), keeping pitch and
    /// heading: a toolface found far from the filter's while drilling
    /// (`aid_sources::DrillingToolface`). The caller adds the new roll's
    /// uncertainty ([`add_attitude_noise`](Self::add_attitude_noise)).
    pub fn set_roll(&mut self, roll: f64) {
        let mut state = *self.strapdown.state();
        let mut euler = euler_from_quat(&state.attitude);
        euler.roll = roll;
        state.attitude = quat_from_euler(&euler);
        self.strapdown.reset(state);
    }

    /// Covariance of the attitude error phi (nav frame), rad^2.
    pub fn attitude_error_covariance(&self) -> Matrix3<f64> {
        self.filter
            .p
            .fixed_view::<3, 3>(ATT, ATT)
            .map(|v| v.as_f64())
    }

    /// Standard deviations of roll, pitch and heading (rad; NaN where the
    /// variance is not valid, see
    /// [`KalmanFilter::std_dev`](crate::kalman::KalmanFilter::std_dev)),
    /// through the Jacobian of the project's Euler convention at the
    /// current attitude.
    pub fn euler_std(&self) -> Vector3<f64> {
        let j = euler_error_jacobian(&dcm_from_quat(&self.state().attitude));
        let p = j * self.attitude_error_covariance() * j.transpose();
        // A negative or NaN variance stays NaN: never a confident 0.
        Vector3::new(p[(0, 0)], p[(1, 1)], p[(2, 2)]).map(std_dev_of)
    }
}
