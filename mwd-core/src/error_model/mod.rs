//! Error model of the navigation solution (paper section 2.3, eq. 11-12),
//! restated for NED with position error in metres, and its AR(4)
//! augmentation to 33 states (eq. 31-45, corrected: errata 1-3, 6), and
//! optionally 6 sensor-bias states more (39 states; not in the paper).
//!
//! The derivation is in `docs/filter-derivation.md`; this code only
//! evaluates it. Errors are computed - true; the attitude error phi is the
//! nav-frame psi-angle, C_computed = (I - [phi x]) C_true.
//!
//! State layout (indices below):
//! `[phiN phiE phiD | dvN dvE dvD | dpN dpE dpD | accel AR x,y,z (4 each,
//! oldest first) | rate AR x,y,z (4 each, oldest first)]` (33), then for
//! the 39-state form `[accel bias x,y,z | rate bias x,y,z]`.

mod augmented;
mod bias;

pub use augmented::{AugmentedModel, AugmentedTransition, Coupling, ProcessNoise};
pub use bias::{BiasState, SensorBiases};

use crate::conventions::DEG;
use crate::earth::{LocalEarth, Position, EARTH_RATE};
use crate::kalman::FilterScalar;
use nalgebra::{Matrix3, SMatrix, Vector3};

/// First attitude-error state.
pub const ATT: usize = 0;
/// First velocity-error state.
pub const VEL: usize = 3;
/// First position-error state.
pub const POS: usize = 6;
/// Number of navigation-error states.
pub const NAV_STATES: usize = 9;
/// Order of each sensor's AR model (the paper's p = 4).
pub const AR_ORDER: usize = 4;
/// First accelerometer AR state (x axis block, oldest sample first).
pub const ACCEL_AR: usize = NAV_STATES;
/// First rate (gyro) AR state.
pub const GYRO_AR: usize = ACCEL_AR + 3 * AR_ORDER;
/// Size of the augmented state: 9 + 12 + 12 = 33 (eq. 43).
pub const STATES: usize = GYRO_AR + 3 * AR_ORDER;
/// First accelerometer bias state (body x; 39-state form only).
pub const ACCEL_BIAS: usize = STATES;
/// First rate bias state (body x; 39-state form only).
pub const GYRO_BIAS: usize = ACCEL_BIAS + 3;
/// Size of the state with the six sensor biases: 33 + 3 + 3 = 39.
pub const STATES_WITH_BIASES: usize = GYRO_BIAS + 3;

/// The largest roll or pitch 1-sigma (rad) for which a solution is
/// valid: the error model is linear in the attitude error phi
/// (C_computed = (I - [phi x]) C_true, docs/filter-derivation.md section
/// 1); its neglected second-order term is phi^2/2 against phi, a relative
/// error of phi/2. At 3 sigma of this limit (9 deg = 0.157 rad) that is
/// 8 %: beyond it the covariance no longer describes the error, and the
/// probe's frames say "solution invalid" (docs/protocol.md, Kind 2) and
/// a tie-in with a larger tilt sigma is refused (`probe::tie_in`).
pub const TILT_SIGMA_LIMIT_RAD: f64 = 3.0 * DEG;

/// Whether a state size is one the augmented model defines (33 or 39).
pub const fn is_model_size(n: usize) -> bool {
    n == STATES || n == STATES_WITH_BIASES
}

/// Index of the newest AR state (the current sensor error) of body axis
/// `axis` in the block starting at `first`.
pub const fn newest_ar_state(first: usize, axis: usize) -> usize {
    first + axis * AR_ORDER + AR_ORDER - 1
}

/// Where the error model is linearised: the current navigation solution.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinearizationPoint {
    /// C_b^n of the computed solution.
    pub c_bn: Matrix3<f64>,
    /// NED velocity (m/s).
    pub velocity_n: Vector3<f64>,
    pub position: Position,
    /// Specific force in NED, f^n = C_b^n f^b (m/s^2).
    pub specific_force_n: Vector3<f64>,
}

/// Continuous-time navigation-error dynamics F (9 x 9, eq. 11-12 for NED
/// with metres): `d/dt [phi dv dp] = F [phi dv dp] + (sensor error terms)`.
pub fn navigation_error_dynamics<T: FilterScalar>(lp: &LinearizationPoint) -> SMatrix<T, 9, 9> {
    navigation_error_dynamics_with(&LocalEarth::at(&lp.position), lp)
}

/// F with the local earth given (the filter keeps one while the solution
/// stays near it, [`LocalEarth::is_near`]); the matrix arithmetic runs in
/// the filter's scalar (hardware f32 on the probe).
pub fn navigation_error_dynamics_with<T: FilterScalar>(
    earth: &LocalEarth,
    lp: &LinearizationPoint,
) -> SMatrix<T, 9, 9> {
    let (rm, rn) = (earth.meridian, earth.transverse);
    let (sin_l, cos_l) = (earth.sin_lat, earth.cos_lat);
    let tan_l = sin_l / cos_l;
    let omega = EARTH_RATE;
    let v64 = lp.velocity_n;

    let w_ie = earth.earth_rate_n();
    let w_en = earth.transport_rate_n(&v64);
    let dg_dh = earth.gravity_gradient;

    let t = T::of;
    let v = v64.map(t);
    let (rm_t, rn_t, tan_t, cos_t) = (t(rm), t(rn), t(tan_l), t(cos_l));
    let zero = T::zero();

    // d(omega_ie^n) and d(omega_en^n) as linear maps of dv and dp (metres,
    // dpN = (R_M + h) dL, dpD = -dh); derivation section 2.
    #[rustfmt::skip]
    let d_wie_dp = Matrix3::new(
        t(-omega * sin_l / rm), zero, zero,
        zero,                   zero, zero,
        t(-omega * cos_l / rm), zero, zero,
    );
    #[rustfmt::skip]
    let d_wen_dv = Matrix3::new(
        zero,              T::one() / rn_t, zero,
        -T::one() / rm_t,  zero,            zero,
        zero,              -tan_t / rn_t,   zero,
    );
    #[rustfmt::skip]
    let d_wen_dp = Matrix3::new(
        zero,                                    zero, v.y / (rn_t * rn_t),
        zero,                                    zero, -v.x / (rm_t * rm_t),
        -v.y / (rn_t * rm_t * cos_t * cos_t),    zero, -v.y * tan_t / (rn_t * rn_t),
    );

    let skew = |w: &Vector3<T>| Matrix3::new(zero, -w.z, w.y, w.z, zero, -w.x, -w.y, w.x, zero);
    let (w_ie, w_en) = (w_ie.map(t), w_en.map(t));
    let two = t(2.0);
    let f11 = -skew(&(w_ie + w_en));
    let f12 = d_wen_dv;
    let f13 = d_wie_dp + d_wen_dp;

    let vx = skew(&v);
    let f21 = skew(&lp.specific_force_n.map(t));
    let f22 = -skew(&(w_ie * two + w_en)) + vx * d_wen_dv;
    // Down-error in the normal gravity: dg_D = (dg/dh) dh = -(dg/dh) dpD.
    let mut f23 = vx * (d_wie_dp * two + d_wen_dp);
    f23[(2, 2)] -= t(dg_dh);

    let f32_ = Matrix3::identity();
    #[rustfmt::skip]
    let f33 = Matrix3::new(
        -v.z / rm_t,          zero,                                 v.x / rm_t,
        v.y * tan_t / rm_t,   -(v.z + v.x * tan_t) / rn_t,          v.y / rn_t,
        zero,                 zero,                                 zero,
    );

    let mut f = SMatrix::<T, 9, 9>::zeros();
    f.fixed_view_mut::<3, 3>(ATT, ATT).copy_from(&f11);
    f.fixed_view_mut::<3, 3>(ATT, VEL).copy_from(&f12);
    f.fixed_view_mut::<3, 3>(ATT, POS).copy_from(&f13);
    f.fixed_view_mut::<3, 3>(VEL, ATT).copy_from(&f21);
    f.fixed_view_mut::<3, 3>(VEL, VEL).copy_from(&f22);
    f.fixed_view_mut::<3, 3>(VEL, POS).copy_from(&f23);
    f.fixed_view_mut::<3, 3>(POS, VEL).copy_from(&f32_);
    f.fixed_view_mut::<3, 3>(POS, POS).copy_from(&f33);
    f
}

#[cfg(test)]
mod tests;
