//! Where the error model is linearised: the specific force of F21 (the
//! measured one or gravity's reaction), and the attitude (each step's, or
//! fixed at a still tool's first estimate with its heading following the
//! estimate's; derivation sections 4e, 4i).

use super::config::SpecificForceInModel;
use super::filter::FineAlignment;
use crate::error_model::{ATT, VEL};
use crate::kalman::FilterScalar;
use nalgebra::{Quaternion, UnitQuaternion};

/// How far the computed attitude may turn from a fixed linearisation point
/// before the point is taken again (rad;
/// [`FineAlignment::fix_linearization`]): 1 deg, well above a station's
/// ZUPT jitter (~0.01 deg), well below the heading a quiet gyro re-finds.
pub const MAX_LINEARIZATION_TURN_RAD: f64 = crate::conventions::DEG;
/// cos(MAX_LINEARIZATION_TURN_RAD / 2) = 0.99996192...
pub(super) const COS_HALF_MAX_LINEARIZATION_TURN: f64 = 0.999_961_923_064_171;
/// How far a fixed linearisation point's heading may lag the estimate's
/// before it is turned to it, about the vertical (rad;
/// [`FineAlignment::fix_linearization`]): 0.1 deg, far below the SCC1300's
/// heading sigma (~7 deg) and a quiet gyro's station corrections, and far
/// above rounding: a few turns of the covariance per station.
pub const MAX_LINEARIZATION_HEADING_LAG_RAD: f64 = 0.1 * crate::conventions::DEG;
/// sin^2(MAX_LINEARIZATION_HEADING_LAG_RAD / 2) = 7.6154...e-7.
const SIN_SQ_HALF_MAX_HEADING_LAG: f64 = 7.615_433_561_505_986e-7;

impl<T: FilterScalar, const N: usize> FineAlignment<T, N> {
    /// Linearises F21 (the velocity error's f^n x phi) at the gravity
    /// reaction instead of the measured specific force (`true`), or back
    /// at the measured one: while drilling the measured force is mostly
    /// vibration (~0.74 g per sample), which the mechanization integrates
    /// as noise; linearised at it the filter would read that noise, through
    /// the constraints, as azimuth information (derivation section 4d). A
    /// tool turning at rest is the same case: the sample's force, rotated
    /// through the roll's error, leans across the tool (derivation section
    /// 4h, seventh item). The probe's navigator takes gravity in every
    /// navigating cycle.
    pub fn linearize_at_gravity(&mut self, at_gravity: bool) {
        self.config.specific_force = if at_gravity {
            SpecificForceInModel::GravityAtRest
        } else {
            SpecificForceInModel::MeasuredSample
        };
    }

    /// Linearises the error model of the following steps (Phi, the held
    /// tool axis, the gyro instability's noise) at the attitude computed
    /// now (`true`; kept while called with `true` again), or again at each
    /// step's computed attitude (`false`). For a tool that is still (a
    /// station): its true attitude does not change, but the estimate does,
    /// by every zero-velocity update's correction, and a Jacobian that
    /// follows that jitter sees the tool-axis accelerometer bias from
    /// directions the tool never took (derivation section 4i: the
    /// first-estimates Jacobian of Huang, Mourikis and Roumeliotis, 2008).
    /// A first estimate is only good while the estimate stays near it: a
    /// station re-finds its heading by degrees (a quiet gyro's rate
    /// gyrocompass, or the SCC1300's heading sigma of ~7 deg being read
    /// from its horizontal earth rate and the tilt it drives), and a model
    /// left at the old heading (the held axis, the biases' directions) then
    /// drove it away (100 deg in one simulated station) or, re-taken at
    /// each degree, saw the tool-axis accelerometer bias from new
    /// directions again. The heading is not what the first estimate is
    /// for: the point's heading follows the estimate's (about the vertical,
    /// once it lags by more than [`MAX_LINEARIZATION_HEADING_LAG_RAD`]),
    /// and the navigation-frame attitude and velocity errors' covariance is
    /// turned with it ([`follow_heading`](Self::follow_heading), derivation
    /// section 4e), while its tilt and roll stay the first estimate's. The
    /// point is taken again only once the estimate has turned more than
    /// [`MAX_LINEARIZATION_TURN_RAD`] from it otherwise (a re-levelling).
    pub fn fix_linearization(&mut self, fixed: bool) {
        let current = self.strapdown.state().attitude;
        self.linearization_attitude = match self.linearization_attitude {
            _ if !fixed => None,
            None => Some(current),
            Some(at) => {
                let at = self.follow_heading(at, &current);
                // |q1 . q2| = cos(angle / 2): no trigonometry per step
                if at.coords.dot(&current.coords).abs() >= COS_HALF_MAX_LINEARIZATION_TURN {
                    Some(at)
                } else {
                    Some(current)
                }
            }
        };
    }

    /// The fixed point `at` turned about the navigation frame's vertical
    /// to the heading of `current`, once it lags by more than
    /// [`MAX_LINEARIZATION_HEADING_LAG_RAD`], with the covariance of the
    /// navigation-frame errors (attitude and velocity) turned by the same
    /// rotation R_z: P <- T P T^T, T = R_z on those two blocks and 1 on the
    /// rest (the body-frame biases and AR states, and the position, whose
    /// past does not turn with a new heading). So the model's C_b^n and the
    /// covariance the filter holds in navigation axes stay in one frame: a
    /// still tool's errors are then the same statement about the body
    /// whatever heading the estimate has found, and the zero-velocity
    /// updates do not see a bias from a direction the tool never took
    /// (derivation section 4e). The rotation is the twist about the
    /// vertical of current at^-1 (swing-twist: (w, 0, 0, k) normalised; no
    /// trigonometry).
    fn follow_heading(
        &mut self,
        at: UnitQuaternion<f64>,
        current: &UnitQuaternion<f64>,
    ) -> UnitQuaternion<f64> {
        let (w, k) = vertical_twist(current, &at);
        match self.turn_navigation_covariance(w, k) {
            Some(twist) => twist * at,
            None => at,
        }
    }

    /// The same turn for the corrections fed back while the model is
    /// linearised at each step's estimate (no fixed point: the start of a
    /// station, the moving tool): a correction that turns the estimate's
    /// heading turns the frame its navigation-frame errors are stated in,
    /// the heading part of the error-state reset's Jacobian, which the
    /// filter otherwise leaves out. Unturned, a station that re-finds its
    /// heading by degrees after drilling (a quiet gyro: 5-11 deg in the
    /// simulated 1000 m lateral) kept its tilt errors' covariance in the
    /// old heading's axes while the model's C_b^n took the new one: the
    /// zero-velocity updates saw the tool-axis accelerometer bias from a
    /// direction the tool never took and read the inclination from it
    /// (derivation section 4l). `heading` is the correction's vertical
    /// component (rad, navigation frame: the estimate is turned by
    /// exp(phi), `Strapdown::apply_correction`), whose twist about the
    /// vertical is (1, heading / 2) to first order, the order of the whole
    /// error model (no trigonometry: every cycle on the probe). The turns
    /// are summed (rotations about one axis: w + k i multiply as complex
    /// numbers) until they pass [`MAX_LINEARIZATION_HEADING_LAG_RAD`], as a
    /// fixed point's lag is; a fixed point follows the estimate itself.
    /// Navigation only: the alignment is the paper's filter as it is.
    pub(super) fn turn_with_corrections(&mut self, heading: f64) {
        let Some((w0, k0)) = self.unturned_correction else {
            return;
        };
        if self.linearization_attitude.is_some() {
            self.unturned_correction = Some((1.0, 0.0));
            return;
        }
        let half = 0.5 * heading;
        let (w, k) = (w0 - k0 * half, w0 * half + k0);
        self.unturned_correction = match self.turn_navigation_covariance(w, k) {
            Some(_) => Some((1.0, 0.0)),
            None => Some((w, k)),
        };
    }

    /// Turns the covariance of the navigation-frame errors (attitude and
    /// velocity) by the rotation about the vertical whose quaternion is
    /// (w, 0, 0, k) normalised, if it is more than
    /// [`MAX_LINEARIZATION_HEADING_LAG_RAD`]; the rotation if it did.
    fn turn_navigation_covariance(&mut self, w: f64, k: f64) -> Option<UnitQuaternion<f64>> {
        let twist_sq = w * w + k * k;
        // sin^2(twist / 2) = k^2 / (w^2 + k^2); also a turn of 180 deg
        // about a horizontal axis (twist_sq = 0, k = 0) stays here
        if k * k <= SIN_SQ_HALF_MAX_HEADING_LAG * twist_sq {
            return None;
        }
        let norm = libm::sqrt(twist_sq);
        let twist = UnitQuaternion::new_unchecked(Quaternion::new(w / norm, 0.0, 0.0, k / norm));
        let r = twist.to_rotation_matrix().into_inner().map(T::of);
        let p = &mut self.filter.p;
        for first in [ATT, VEL] {
            let rows = r * p.fixed_view::<3, N>(first, 0);
            p.fixed_view_mut::<3, N>(first, 0).copy_from(&rows);
        }
        for first in [ATT, VEL] {
            let columns = p.fixed_view::<N, 3>(0, first) * r.transpose();
            p.fixed_view_mut::<N, 3>(0, first).copy_from(&columns);
        }
        // exactly symmetric again (the two products round differently)
        let half = T::of(0.5);
        for first in [ATT, VEL] {
            for i in first..first + 3 {
                for j in 0..N {
                    let v = (p[(i, j)] + p[(j, i)]) * half;
                    p[(i, j)] = v;
                    p[(j, i)] = v;
                }
            }
        }
        Some(twist)
    }

    /// The attitude the error model is linearised at: the fixed one
    /// ([`fix_linearization`](Self::fix_linearization)) or the current
    /// estimate. An aiding row that depends on the attitude (the station's
    /// rate gyrocompass, `aid_sources::EarthRate`) takes it too, so that
    /// the model's Jacobians all sit at one point (derivation section 4e).
    pub fn linearization_attitude(&self) -> UnitQuaternion<f64> {
        self.linearization_attitude
            .unwrap_or(self.strapdown.state().attitude)
    }
}

/// The scalar and vertical parts (w, k) of `current * at^-1`: the twist
/// about the navigation frame's vertical that takes `at`'s heading to
/// `current`'s, unnormalised (swing-twist decomposition; the product's
/// other two parts are not needed: half the software f64 multiplications
/// of the whole product on the probe, every cycle).
fn vertical_twist(current: &UnitQuaternion<f64>, at: &UnitQuaternion<f64>) -> (f64, f64) {
    let (c, a) = (current.quaternion(), at.quaternion());
    let w = c.w * a.w + c.i * a.i + c.j * a.j + c.k * a.k;
    let k = c.k * a.w - c.w * a.k + c.j * a.i - c.i * a.j;
    (w, k)
}
