//! The one place for frames, angles and their conversions. Nothing else in
//! the project re-derives them.
//!
//! * Body frame `b` (the paper's Fig. 2): x right, y forward along the tool
//!   axis, z up.
//! * Navigation frame `n`: local level, north-east-down (NED).
//! * Attitude is the rotation from body to navigation frame: the direction
//!   cosine matrix C_b^n (`v_n = C_b^n v_b`) or the unit quaternion of the
//!   same rotation (Hamilton convention, `v_n = q v_b q*`).
//! * Euler angles are the aerospace yaw-pitch-roll (Z-Y-X) angles of the
//!   tool's forward-right-down frame `f` (x forward, y right, z down), which
//!   is the body frame with axes renamed: `v_f = P v_b` with the fixed
//!   permutation [`body_to_frd`]. So C_b^n = Rz(heading) Ry(pitch) Rx(roll) P:
//!   heading is the tool axis' azimuth from north, clockwise seen from above;
//!   pitch is the tool axis' elevation above the horizontal (nose up
//!   positive); roll is the rotation about the tool axis, right side down
//!   positive.
//! * Drilling terms: inclination is the angle between the tool axis and
//!   vertical down (0 = drilling straight down, 90 deg = horizontal), so
//!   inclination = 90 deg + pitch; azimuth = heading in [0, 360) deg; gravity
//!   toolface is the angle about the tool axis from the high side of the hole
//!   to the body +z mark, clockwise looking down-hole, which equals roll in
//!   [0, 360) deg.
//!
//! Transcendental functions go through `libm` so the probe and the host
//! compute the same bits.
use core::f64::consts::{FRAC_PI_2, PI, TAU};
use nalgebra::{Matrix3, Quaternion, UnitQuaternion, Vector3};

/// One degree in radians, for constants written in degrees (at run time
/// `f64::to_radians` does the same).
pub const DEG: f64 = PI / 180.0;

/// The fixed rotation from the body frame (right, forward, up) to the
/// forward-right-down frame the Euler angles are defined in: `v_f = P v_b`.
/// P is a proper rotation (180 deg about (1, 1, 0)/sqrt 2), symmetric, and its
/// own inverse.
pub fn body_to_frd() -> Matrix3<f64> {
    Matrix3::new(0.0, 1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, -1.0)
}

/// The skew-symmetric (cross-product) matrix: `skew(a) * b == a.cross(&b)`.
pub fn skew(v: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
}

/// Wraps an angle to [-pi, pi).
pub fn wrap_pi(angle: f64) -> f64 {
    let wrapped = wrap_two_pi(angle + PI) - PI;
    if wrapped >= PI {
        wrapped - TAU
    } else {
        wrapped
    }
}

/// Wraps an angle to [0, 2 pi).
pub fn wrap_two_pi(angle: f64) -> f64 {
    let r = libm::fmod(angle, TAU);
    let r = if r < 0.0 { r + TAU } else { r };
    // fmod of a value just below a multiple of 2 pi plus TAU can round to TAU.
    if r >= TAU {
        0.0
    } else {
        r
    }
}

/// Aerospace Z-Y-X Euler angles of the tool (see the module documentation),
/// in radians.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Euler {
    /// Rotation about the tool axis, right side down positive.
    pub roll: f64,
    /// Elevation of the tool axis above the horizontal, in [-pi/2, pi/2].
    pub pitch: f64,
    /// Azimuth of the tool axis from north, clockwise seen from above.
    pub heading: f64,
}

impl Euler {
    pub const fn new(roll: f64, pitch: f64, heading: f64) -> Self {
        Self {
            roll,
            pitch,
            heading,
        }
    }
}

/// C_b^n from Euler angles: Rz(heading) Ry(pitch) Rx(roll) P.
pub fn dcm_from_euler(e: &Euler) -> Matrix3<f64> {
    let (sr, cr) = (libm::sin(e.roll), libm::cos(e.roll));
    let (sp, cp) = (libm::sin(e.pitch), libm::cos(e.pitch));
    let (sh, ch) = (libm::sin(e.heading), libm::cos(e.heading));
    // C_f^n, the standard aerospace matrix.
    let c_fn = Matrix3::new(
        cp * ch,
        -cr * sh + sr * sp * ch,
        sr * sh + cr * sp * ch,
        cp * sh,
        cr * ch + sr * sp * sh,
        -sr * ch + cr * sp * sh,
        -sp,
        sr * cp,
        cr * cp,
    );
    c_fn * body_to_frd()
}

/// Euler angles from C_b^n. At pitch +-90 deg (tool axis vertical) roll and
/// heading are not separable; the rotation about the vertical is then put
/// into heading and roll is returned as 0.
pub fn euler_from_dcm(c_bn: &Matrix3<f64>) -> Euler {
    // C_f^n = C_b^n P (P is its own inverse): P swaps the first two columns
    // and negates the third. Taken by index, not by a 3 x 3 product (27
    // software multiplications on the probe's single-precision FPU).
    let c = Matrix3::from_fn(|i, k| match k {
        0 => c_bn[(i, 1)],
        1 => c_bn[(i, 0)],
        _ => -c_bn[(i, 2)],
    });
    let horizontal = libm::sqrt(c[(0, 0)] * c[(0, 0)] + c[(1, 0)] * c[(1, 0)]);
    let pitch = libm::atan2(-c[(2, 0)], horizontal);
    if horizontal < 1e-12 {
        // Gimbal lock: C_f^n reduces to a rotation about the vertical.
        let heading = libm::atan2(-c[(0, 1)], c[(1, 1)]);
        return Euler::new(0.0, pitch.clamp(-FRAC_PI_2, FRAC_PI_2), heading);
    }
    let roll = libm::atan2(c[(2, 1)], c[(2, 2)]);
    let heading = libm::atan2(c[(1, 0)], c[(0, 0)]);
    Euler::new(roll, pitch, heading)
}

/// d(roll, pitch, heading) / d(phi) for an attitude error phi in the
/// navigation frame (computed C = (I - [phi x]) C_true, i.e. q_computed =
/// q(-phi) q_true), evaluated at C_b^n `c_bn`.
///
/// With C_f^n = Rz(heading) Ry(pitch) Rx(roll), a small rotation w of the
/// navigation frame changes the angles by d(r, p, h) with
/// w = d_h e3 + d_p Rz(h) e2 + d_r Rz(h) Ry(p) e1 = M d(r, p, h), where the
/// columns of M are the tool axis t = C_b^n e_y = (cp ch, cp sh, -sp),
/// (-sh, ch, 0) and (0, 0, 1). The error is a rotation by -phi, so
/// J = -M^-1 = -[[ch/cp, sh/cp, 0], [-sh, ch, 0], [tp ch, tp sh, 1]].
/// The sines and cosines come from t itself: no trigonometric call. At a
/// vertical tool axis (cp = 0) roll and heading have no meaning and the
/// entries are infinite. Checked against central differences of
/// [`euler_from_dcm`] in the tests.
pub fn euler_error_jacobian(c_bn: &Matrix3<f64>) -> Matrix3<f64> {
    let (tn, te, td) = (c_bn[(0, 1)], c_bn[(1, 1)], c_bn[(2, 1)]);
    let cp = libm::sqrt(tn * tn + te * te);
    let sp = -td;
    let (ch, sh) = if cp > 0.0 {
        (tn / cp, te / cp)
    } else {
        (1.0, 0.0)
    };
    let tp = sp / cp;
    -Matrix3::new(ch / cp, sh / cp, 0.0, -sh, ch, 0.0, tp * ch, tp * sh, 1.0)
}

/// The Euler order's index (roll 0, pitch 1, heading 2) of inclination,
/// azimuth and toolface, in that order.
pub const DRILLING_FROM_EULER: [usize; 3] = [1, 2, 0];

/// Inclination, azimuth, toolface (rad) and d(inc, azi, tf)/d(phi) at
/// C_b^n `c_bn`: the rows of [`euler_error_jacobian`] for pitch, heading
/// and roll (`probe::station` has the derivation and the tests).
pub fn angles_and_jacobian(c_bn: &Matrix3<f64>) -> (DrillingAngles, Matrix3<f64>) {
    let angles = DrillingAngles::from_euler(&euler_from_dcm(c_bn));
    let euler = euler_error_jacobian(c_bn);
    let j = Matrix3::from_fn(|i, k| euler[(DRILLING_FROM_EULER[i], k)]);
    (angles, j)
}

/// The unit quaternion of the rotation C_b^n.
pub fn quat_from_dcm(c: &Matrix3<f64>) -> UnitQuaternion<f64> {
    // Shepperd's method: take the square root of the largest of the four
    // squared components, which keeps the division well conditioned.
    let trace = c[(0, 0)] + c[(1, 1)] + c[(2, 2)];
    let candidates = [trace, c[(0, 0)], c[(1, 1)], c[(2, 2)]];
    let mut largest = 0;
    for (i, v) in candidates.iter().enumerate() {
        if *v > candidates[largest] {
            largest = i;
        }
    }
    let q = match largest {
        0 => {
            let s = 2.0 * libm::sqrt(1.0 + trace);
            Quaternion::new(
                0.25 * s,
                (c[(2, 1)] - c[(1, 2)]) / s,
                (c[(0, 2)] - c[(2, 0)]) / s,
                (c[(1, 0)] - c[(0, 1)]) / s,
            )
        }
        1 => {
            let s = 2.0 * libm::sqrt(1.0 + c[(0, 0)] - c[(1, 1)] - c[(2, 2)]);
            Quaternion::new(
                (c[(2, 1)] - c[(1, 2)]) / s,
                0.25 * s,
                (c[(0, 1)] + c[(1, 0)]) / s,
                (c[(0, 2)] + c[(2, 0)]) / s,
            )
        }
        2 => {
            let s = 2.0 * libm::sqrt(1.0 - c[(0, 0)] + c[(1, 1)] - c[(2, 2)]);
            Quaternion::new(
                (c[(0, 2)] - c[(2, 0)]) / s,
                (c[(0, 1)] + c[(1, 0)]) / s,
                0.25 * s,
                (c[(1, 2)] + c[(2, 1)]) / s,
            )
        }
        _ => {
            let s = 2.0 * libm::sqrt(1.0 - c[(0, 0)] - c[(1, 1)] + c[(2, 2)]);
            Quaternion::new(
                (c[(1, 0)] - c[(0, 1)]) / s,
                (c[(0, 2)] + c[(2, 0)]) / s,
                (c[(1, 2)] + c[(2, 1)]) / s,
                0.25 * s,
            )
        }
    };
    // Canonical sign: non-negative scalar part.
    let q = if q.w < 0.0 { -q } else { q };
    UnitQuaternion::new_normalize(q)
}

/// C_b^n of a unit quaternion.
pub fn dcm_from_quat(q: &UnitQuaternion<f64>) -> Matrix3<f64> {
    let (w, x, y, z) = (q.w, q.i, q.j, q.k);
    Matrix3::new(
        1.0 - 2.0 * (y * y + z * z),
        2.0 * (x * y - w * z),
        2.0 * (x * z + w * y),
        2.0 * (x * y + w * z),
        1.0 - 2.0 * (x * x + z * z),
        2.0 * (y * z - w * x),
        2.0 * (x * z - w * y),
        2.0 * (y * z + w * x),
        1.0 - 2.0 * (x * x + y * y),
    )
}

/// The attitude quaternion from Euler angles.
pub fn quat_from_euler(e: &Euler) -> UnitQuaternion<f64> {
    quat_from_dcm(&dcm_from_euler(e))
}

/// Euler angles from the attitude quaternion.
pub fn euler_from_quat(q: &UnitQuaternion<f64>) -> Euler {
    euler_from_dcm(&dcm_from_quat(q))
}

/// The drilling view of the tool's attitude, in radians.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct DrillingAngles {
    /// Tool axis from vertical down: 0 = straight down, pi/2 = horizontal.
    pub inclination: f64,
    /// Tool axis azimuth from true north, clockwise, in [0, 2 pi).
    pub azimuth: f64,
    /// Gravity toolface: high side to the body +z mark, clockwise looking
    /// down-hole, in [0, 2 pi).
    pub toolface: f64,
}

impl DrillingAngles {
    pub fn from_euler(e: &Euler) -> Self {
        Self {
            inclination: FRAC_PI_2 + e.pitch,
            azimuth: wrap_two_pi(e.heading),
            toolface: wrap_two_pi(e.roll),
        }
    }

    pub fn to_euler(&self) -> Euler {
        Euler::new(
            wrap_pi(self.toolface),
            self.inclination - FRAC_PI_2,
            wrap_pi(self.azimuth),
        )
    }
}

/// Specific force the accelerometers read when the tool is at rest with
/// attitude `e` under gravity `g` (m/s^2): `f_b = C_n^b (0, 0, -g)`. Written
/// out so the sign conventions are visible next to the levelling formulas in
/// `attitude`.
pub fn specific_force_at_rest(e: &Euler, g: f64) -> Vector3<f64> {
    let (sr, cr) = (libm::sin(e.roll), libm::cos(e.roll));
    let (sp, cp) = (libm::sin(e.pitch), libm::cos(e.pitch));
    Vector3::new(-g * sr * cp, g * sp, g * cr * cp)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn angle_close(a: f64, b: f64, tol: f64) -> bool {
        libm::fabs(wrap_pi(a - b)) < tol
    }

    fn euler_strategy() -> impl Strategy<Value = Euler> {
        // Keep away from the gimbal lock, where roll and heading are not
        // separable (tested on its own below).
        (-PI..PI, -1.55f64..1.55, -PI..PI).prop_map(|(r, p, h)| Euler::new(r, p, h))
    }

    /// The slow reference of [`euler_error_jacobian`]: central differences
    /// of the Euler extraction itself.
    fn euler_error_jacobian_numeric(c_bn: &Matrix3<f64>) -> Matrix3<f64> {
        let h = 1e-6;
        let euler = |phi: &Vector3<f64>| {
            let e = euler_from_dcm(&((Matrix3::identity() - skew(phi)) * c_bn));
            Vector3::new(e.roll, e.pitch, e.heading)
        };
        let mut j = Matrix3::zeros();
        for k in 0..3 {
            let mut d = Vector3::zeros();
            d[k] = h;
            let (plus, minus) = (euler(&d), euler(&-d));
            for i in 0..3 {
                j[(i, k)] = wrap_pi(plus[i] - minus[i]) / (2.0 * h);
            }
        }
        j
    }

    proptest! {
        #[test]
        fn euler_error_jacobian_matches_central_differences(e in euler_strategy()) {
            let c = dcm_from_euler(&e);
            let fast = euler_error_jacobian(&c);
            let slow = euler_error_jacobian_numeric(&c);
            // Central differences with h = 1e-6 of a first-order rotation:
            // O(h) curvature terms scaled by 1/cos(pitch) (<= 48 here).
            let scale = 1.0 / libm::cos(e.pitch);
            for (a, b) in fast.iter().zip(slow.iter()) {
                prop_assert!((a - b).abs() < 1e-5 * scale * scale, "{fast} vs {slow}");
            }
        }
    }

    proptest! {
        #[test]
        fn euler_dcm_round_trip(e in euler_strategy()) {
            let back = euler_from_dcm(&dcm_from_euler(&e));
            prop_assert!(angle_close(back.roll, e.roll, 1e-9));
            prop_assert!((back.pitch - e.pitch).abs() < 1e-9);
            prop_assert!(angle_close(back.heading, e.heading, 1e-9));
        }

        #[test]
        fn quaternion_dcm_round_trip(e in euler_strategy()) {
            let c = dcm_from_euler(&e);
            let q = quat_from_dcm(&c);
            prop_assert!((q.norm() - 1.0).abs() < 1e-12);
            prop_assert!((dcm_from_quat(&q) - c).abs().max() < 1e-12);
            let back = euler_from_quat(&quat_from_euler(&e));
            prop_assert!(angle_close(back.roll, e.roll, 1e-9));
            prop_assert!(angle_close(back.heading, e.heading, 1e-9));
        }

        #[test]
        fn dcm_is_a_proper_rotation(e in euler_strategy()) {
            let c = dcm_from_euler(&e);
            prop_assert!((c * c.transpose() - Matrix3::identity()).abs().max() < 1e-12);
            prop_assert!((c.determinant() - 1.0).abs() < 1e-12);
        }

        #[test]
        fn our_quaternion_rotates_like_nalgebra(e in euler_strategy(),
                                                v in prop::array::uniform3(-10.0f64..10.0)) {
            let v = Vector3::from(v);
            let q = quat_from_euler(&e);
            prop_assert!((q * v - dcm_from_euler(&e) * v).norm() < 1e-9);
        }

        #[test]
        fn drilling_angles_round_trip(e in euler_strategy()) {
            let d = DrillingAngles::from_euler(&e);
            prop_assert!((0.0..=PI).contains(&d.inclination));
            prop_assert!((0.0..TAU).contains(&d.azimuth));
            prop_assert!((0.0..TAU).contains(&d.toolface));
            let back = d.to_euler();
            prop_assert!(angle_close(back.roll, e.roll, 1e-12));
            prop_assert!((back.pitch - e.pitch).abs() < 1e-12);
            prop_assert!(angle_close(back.heading, e.heading, 1e-12));
        }

        #[test]
        fn specific_force_matches_dcm(e in euler_strategy()) {
            let g = 9.8;
            let f = dcm_from_euler(&e).transpose() * Vector3::new(0.0, 0.0, -g);
            prop_assert!((f - specific_force_at_rest(&e, g)).norm() < 1e-12);
        }

        #[test]
        fn wrapping_stays_in_range(a in -100.0f64..100.0) {
            let w = wrap_pi(a);
            prop_assert!((-PI..PI).contains(&w));
            prop_assert!(libm::fabs(libm::sin(w) - libm::sin(a)) < 1e-9);
            prop_assert!((0.0..TAU).contains(&wrap_two_pi(a)));
        }
    }

    #[test]
    fn body_axes_point_where_the_conventions_say() {
        // Level, heading north, no roll: forward = north, right = east, up = -down.
        let c = dcm_from_euler(&Euler::new(0.0, 0.0, 0.0));
        assert!((c * Vector3::y() - Vector3::x()).norm() < 1e-15);
        assert!((c * Vector3::x() - Vector3::y()).norm() < 1e-15);
        assert!((c * Vector3::z() + Vector3::z()).norm() < 1e-15);
        // Heading east: the tool axis points east.
        let c = dcm_from_euler(&Euler::new(0.0, 0.0, FRAC_PI_2));
        assert!((c * Vector3::y() - Vector3::y()).norm() < 1e-15);
        // Pitch -90 deg: the tool drills straight down, inclination 0.
        let e = Euler::new(0.0, -FRAC_PI_2, 0.0);
        assert!((dcm_from_euler(&e) * Vector3::y() - Vector3::z()).norm() < 1e-15);
        assert!(DrillingAngles::from_euler(&e).inclination.abs() < 1e-15);
        // Roll +90 deg about the tool axis: the right side (x) points down.
        let c = dcm_from_euler(&Euler::new(FRAC_PI_2, 0.0, 0.0));
        assert!((c * Vector3::x() - Vector3::z()).norm() < 1e-15);
    }

    #[test]
    fn toolface_is_measured_from_the_high_side() {
        // Inclined 60 deg, toolface 90 deg: the +z mark points to the right of
        // the hole (looking down-hole), i.e. horizontally, to the east when
        // the well heads north.
        let d = DrillingAngles {
            inclination: 60f64.to_radians(),
            azimuth: 0.0,
            toolface: FRAC_PI_2,
        };
        let c = dcm_from_euler(&d.to_euler());
        assert!((c * Vector3::z() - Vector3::y()).norm() < 1e-12);
        // Toolface 0: the mark points to the high side (up and back along the
        // hole's vertical plane).
        let d = DrillingAngles { toolface: 0.0, ..d };
        let mark = dcm_from_euler(&d.to_euler()) * Vector3::z();
        assert!(mark.z < 0.0 && mark.y.abs() < 1e-12);
    }

    #[test]
    fn gimbal_lock_keeps_the_rotation() {
        let e = Euler::new(0.3, -FRAC_PI_2, 1.0);
        let c = dcm_from_euler(&e);
        let back = dcm_from_euler(&euler_from_dcm(&c));
        assert!((back - c).abs().max() < 1e-9);
    }
}
