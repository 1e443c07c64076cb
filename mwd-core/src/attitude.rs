//! Attitude kinematics: rotation vectors, the two-sample coning correction,
//! and the probe's accelerometer-derived roll and tool-axis rate (paper
//! section 2.2, eq. 1-10, with errata 4, 9, 13 of `docs/paper-errata.md`).
use crate::conventions::{wrap_pi, DEG};
use crate::probe_sample::ProbeSample;
use nalgebra::{Matrix3, Quaternion, UnitQuaternion, Vector3};

/// Below this rotation angle (rad) the series forms are used; their
/// truncation error (angle^6 / 5040) is far below f64 resolution there.
const SMALL_ANGLE: f64 = 1e-4;

/// The quaternion of a rotation vector (paper eq. 4 and 6, with eq. 6's
/// misprinted sin||0.5 zeta|| read as sin||0.5 Lambda||).
///
/// Below `SMALL_ANGLE` (every increment of the 20 Hz cycle) both parts
/// come from series in a^2 = |v|^2, with no square root or trigonometry:
/// cos(a/2) = 1 - a^2/8 + a^4/384, truncation <= a^6/46080 = 2.2e-29, and
/// sin(a/2)/a = 1/2 - a^2/48, truncation <= a^4/3840 = 2.6e-20 (5.2e-20
/// relative): both under half an ulp (2^-53 = 1.1e-16 relative), so the
/// series are libm's values to f64 rounding.
pub fn quat_from_rotation_vector(v: &Vector3<f64>) -> UnitQuaternion<f64> {
    let angle2 = v.norm_squared();
    let (w, k) = if angle2 < SMALL_ANGLE * SMALL_ANGLE {
        (
            1.0 - angle2 * (1.0 / 8.0) + angle2 * angle2 * (1.0 / 384.0),
            0.5 - angle2 * (1.0 / 48.0),
        )
    } else {
        let angle = libm::sqrt(angle2);
        let half = 0.5 * angle;
        (libm::cos(half), libm::sin(half) / angle)
    };
    UnitQuaternion::new_unchecked(Quaternion::new(w, k * v.x, k * v.y, k * v.z))
}

/// The direction cosine matrix of a rotation vector, Rodrigues' formula
/// (paper eq. 9-10): I + sin|v|/|v| (v x) + (1 - cos|v|)/|v|^2 (v x)^2.
pub fn dcm_from_rotation_vector(v: &Vector3<f64>) -> Matrix3<f64> {
    let angle = v.norm();
    let (a, b) = if angle < SMALL_ANGLE {
        let a2 = angle * angle;
        (1.0 - a2 / 6.0, 0.5 - a2 / 24.0)
    } else {
        (
            libm::sin(angle) / angle,
            (1.0 - libm::cos(angle)) / (angle * angle),
        )
    };
    let s = crate::conventions::skew(v);
    Matrix3::identity() + s * a + s * s * b
}

/// Two-sample coning correction (paper eq. 7): the rotation vector over the
/// latest interval from the latest two angle increments,
/// Lambda_k = dtheta_k + (1/12) dtheta_{k-1} x dtheta_k.
pub fn coning_rotation_vector(previous: &Vector3<f64>, latest: &Vector3<f64>) -> Vector3<f64> {
    latest + previous.cross(latest) / 12.0
}

/// Accelerometer levelling (paper eq. 1 and 27-28, restated in this
/// project's conventions): roll and pitch from the specific force of a tool
/// at rest, f_b = g (-sin roll cos pitch, sin pitch, cos roll cos pitch).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Levelling {
    pub roll: f64,
    pub pitch: f64,
    /// False when the tool axis is within [`NEAR_VERTICAL`] of vertical:
    /// the cross-axis gravity components vanish and roll is undefined.
    pub roll_valid: bool,
}

/// How close (rad) the tool axis may come to vertical before the
/// accelerometer roll, and everything derived from it, is declared invalid:
/// 5 deg, where the cross-axis gravity is g sin 5 deg = 0.085 g, about
/// 55 times the accelerometer's 1.5 mg LSB.
pub const NEAR_VERTICAL: f64 = 5.0 * DEG;

pub fn level(specific_force: &Vector3<f64>) -> Levelling {
    let f = specific_force;
    let cross = libm::sqrt(f.x * f.x + f.z * f.z);
    let pitch = libm::atan2(f.y, cross);
    Levelling {
        roll: libm::atan2(-f.x, f.z),
        pitch,
        roll_valid: libm::cos(pitch) > libm::sin(NEAR_VERTICAL),
    }
}

/// The rate about the tool axis, which no gyro senses on the probe.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ToolAxisRate {
    /// omega_ib,y (rad/s).
    Valid(f64),
    /// The tool axis is near vertical (or no previous roll exists yet): the
    /// rate cannot be derived from the accelerometers.
    Unavailable,
}

/// Derives the tool-axis rate from successive accelerometer roll angles
/// (paper eq. 1-2), corrected with the two gyros.
///
/// Euler kinematics give, for the body's rate relative to the navigation
/// frame, omega_nb,y = d(roll)/dt - tan(pitch) (omega_nb,x sin roll -
/// omega_nb,z cos roll): the paper's eq. 2 is the first term only, exact for
/// a level tool. The gyros measure omega_ib = omega_nb + C_n^b omega_in^n, so
/// `omega_in_b` (earth plus transport rate in body axes) is removed from the
/// gyro rates and added back to the result.
#[derive(Clone, Copy, Debug, Default)]
pub struct ToolAxisRateEstimator {
    previous_roll: Option<f64>,
}

impl ToolAxisRateEstimator {
    pub fn new() -> Self {
        Self::default()
    }

    /// One sample of the probe, the navigation frame's rate in body axes,
    /// and the sample interval.
    pub fn update(
        &mut self,
        sample: &ProbeSample,
        omega_in_b: &Vector3<f64>,
        dt: f64,
    ) -> ToolAxisRate {
        let lev = level(&sample.specific_force);
        // Written so that a NaN interval is rejected too.
        let dt_valid = dt > 0.0;
        if !lev.roll_valid || !dt_valid {
            self.previous_roll = None;
            return ToolAxisRate::Unavailable;
        }
        let previous = self.previous_roll.replace(lev.roll);
        let Some(previous) = previous else {
            return ToolAxisRate::Unavailable;
        };
        let roll_rate = wrap_pi(lev.roll - previous) / dt;
        let (s, c) = (libm::sin(lev.roll), libm::cos(lev.roll));
        let nb_x = sample.rate_x() - omega_in_b.x;
        let nb_z = sample.rate_z() - omega_in_b.z;
        let nb_y = roll_rate - libm::tan(lev.pitch) * (nb_x * s - nb_z * c);
        ToolAxisRate::Valid(nb_y + omega_in_b.y)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::conventions::{dcm_from_euler, dcm_from_quat, specific_force_at_rest, Euler};
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn rotation_vector_quaternion_and_rodrigues_agree(
            v in prop::array::uniform3(-3.0f64..3.0), scale in prop::sample::select(&[1.0, 1e-3, 1e-5, 1e-9][..])
        ) {
            let v = Vector3::from(v) * scale;
            let q = quat_from_rotation_vector(&v);
            prop_assert!((q.norm() - 1.0).abs() < 1e-15);
            prop_assert!((dcm_from_quat(&q) - dcm_from_rotation_vector(&v)).abs().max() < 1e-14);
            // The same rotation as nalgebra's exponential map.
            let reference = UnitQuaternion::from_scaled_axis(v);
            prop_assert!((q.to_rotation_matrix().into_inner()
                - reference.to_rotation_matrix().into_inner()).abs().max() < 1e-14);
        }

        #[test]
        fn levelling_inverts_the_specific_force(
            roll in -3.1f64..3.1, pitch in -1.4f64..1.4, heading in -3.1f64..3.1
        ) {
            let f = specific_force_at_rest(&Euler::new(roll, pitch, heading), 9.8);
            let lev = level(&f);
            prop_assert!(lev.roll_valid);
            prop_assert!(wrap_pi(lev.roll - roll).abs() < 1e-12);
            prop_assert!((lev.pitch - pitch).abs() < 1e-12);
        }
    }

    /// Pure coning: the body z axis sweeps a cone of half-angle `alpha` at
    /// `w` rad/s, attitude C(t) = Rz(w t) Rx(alpha) Rz(-w t) exactly, which
    /// returns to C(0) every period. The body rate (from C^T dC/dt) is
    /// integrated with Simpson's rule into each interval's angle increment.
    /// Returns the attitude error after `duration` seconds without and with
    /// the coning correction.
    fn coning_errors(alpha: f64, w: f64, dt: f64, duration: f64) -> (f64, f64) {
        let rz = |a: f64| {
            let (s, c) = (libm::sin(a), libm::cos(a));
            Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
        };
        let (sa, ca) = (libm::sin(alpha), libm::cos(alpha));
        let rx = Matrix3::new(1.0, 0.0, 0.0, 0.0, ca, -sa, 0.0, sa, ca);
        let attitude = |t: f64| rz(w * t) * rx * rz(-w * t);
        let body_rate = |t: f64| {
            let h = 1e-6;
            let dc = (attitude(t + h) - attitude(t - h)) / (2.0 * h);
            let s = attitude(t).transpose() * dc;
            Vector3::new(s[(2, 1)], s[(0, 2)], s[(1, 0)])
        };
        let increment = |t0: f64| {
            let n = 32;
            let h = dt / n as f64;
            let mut sum = body_rate(t0) + body_rate(t0 + dt);
            for i in 1..n {
                let weight = if i % 2 == 1 { 4.0 } else { 2.0 };
                sum += body_rate(t0 + i as f64 * h) * weight;
            }
            sum * h / 3.0
        };
        let mut corrected = crate::conventions::quat_from_dcm(&attitude(0.0));
        let mut plain = corrected;
        let mut previous = increment(-dt);
        let steps = libm::round(duration / dt) as usize;
        for k in 0..steps {
            let dtheta = increment(k as f64 * dt);
            corrected *= quat_from_rotation_vector(&coning_rotation_vector(&previous, &dtheta));
            plain *= quat_from_rotation_vector(&dtheta);
            previous = dtheta;
        }
        let truth = attitude(steps as f64 * dt);
        let error = |q: &UnitQuaternion<f64>| {
            let e = dcm_from_quat(q).transpose() * truth;
            Vector3::new(e[(2, 1)], e[(0, 2)], e[(1, 0)]).norm()
        };
        (error(&plain), error(&corrected))
    }

    /// Adding the increments as if they commuted drifts about the cone axis
    /// at about (alpha^2 w / 2)(1 - sin(w dt)/(w dt)), which falls with
    /// (w dt)^2; the two-sample correction (eq. 7) leaves a residual that
    /// falls with (w dt)^4. Stated tolerance, for a 1 Hz, 0.05 rad cone
    /// sampled at the probe's 20 Hz over 20 s: uncorrected 2.6e-3 rad as
    /// the formula predicts (within 5 %), corrected below 2.5 % of that, and
    /// halving dt cuts the corrected error at least 12-fold (ideal 16) and
    /// the uncorrected about 4-fold.
    #[test]
    fn coning_correction_tracks_pure_coning() {
        let (alpha, w, duration) = (0.05, 2.0 * core::f64::consts::PI, 20.0);
        let (plain, corrected) = coning_errors(alpha, w, 0.05, duration);
        let x = w * 0.05;
        let predicted = 0.5 * alpha * alpha * w * (1.0 - libm::sin(x) / x) * duration;
        assert!(
            (plain / predicted - 1.0).abs() < 0.05,
            "{plain} vs {predicted}"
        );
        assert!(
            corrected < 0.025 * plain,
            "corrected {corrected}, plain {plain}"
        );
        let (plain_half, corrected_half) = coning_errors(alpha, w, 0.025, duration);
        assert!(
            corrected / corrected_half > 12.0,
            "{corrected} -> {corrected_half}"
        );
        let ratio = plain / plain_half;
        assert!((3.5..4.5).contains(&ratio), "uncorrected ratio {ratio}");
    }

    /// Uniform in [-1, 1) from xorshift64* (seeded, no dependency).
    fn uniform(state: &mut u64) -> f64 {
        *state ^= *state >> 12;
        *state ^= *state << 25;
        *state ^= *state >> 27;
        let bits = state.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11;
        2.0 * (bits as f64 / (1u64 << 53) as f64) - 1.0
    }

    /// 10^6 updates with random rotation vectors (each component uniform
    /// in +-0.05 rad, up to about 1.7 rad/s at 20 Hz) through the coning
    /// correction, with no renormalisation at all: the norm is what the
    /// arithmetic keeps. Each product and each increment's quaternion is
    /// unit to about f64 epsilon (1.1e-16), so the norm walks by about
    /// sqrt(N) eps = 1e-13; the stated bound, 1e-11, is 100 times that
    /// and still 20 times below the linear worst case N eps = 2.2e-10.
    #[test]
    fn unit_norm_is_kept_over_a_million_updates() {
        let mut q = crate::conventions::quat_from_euler(&Euler::new(0.1, -0.4, 2.0));
        let mut rng = 0x9e37_79b9_7f4a_7c15u64;
        let mut random =
            || 0.05 * Vector3::new(uniform(&mut rng), uniform(&mut rng), uniform(&mut rng));
        let mut previous = random();
        let mut worst = 0.0f64;
        for _ in 0..1_000_000u32 {
            let latest = random();
            q *= quat_from_rotation_vector(&coning_rotation_vector(&previous, &latest));
            worst = worst.max((q.norm() - 1.0).abs());
            previous = latest;
        }
        assert!(worst < 1e-11, "norm drifted by {worst:e}");
        let c = dcm_from_quat(&q);
        // dcm_from_quat assumes a unit norm: its rows are orthonormal to
        // a few times the norm error.
        assert!((c * c.transpose() - Matrix3::identity()).abs().max() < 1e-11);
    }

    /// A constant body rate about a fixed axis has the closed form
    /// q(t) = q0 exp(w t u / 2) (here nalgebra's exponential map); the
    /// coning term vanishes (the increments are parallel). 10^6 steps at
    /// 20 Hz of 0.5 rad/s (13.9 h, 25 000 rad in all), no renormalisation.
    /// The same increment every step repeats the same rounding, so errors
    /// grow linearly, not as a random walk: the norm may drift up to the
    /// linear worst case N eps = 2.2e-10 (measured about 5e-11), and the
    /// attitude must match the closed form to 1e-10 rad (measured about
    /// 4e-12; the closed form's own sin/cos of a 12 500 rad half angle is
    /// good to about 1.4e-12).
    #[test]
    fn constant_rate_rotation_matches_the_closed_form_over_a_million_updates() {
        let q0 = crate::conventions::quat_from_euler(&Euler::new(0.1, -0.4, 2.0));
        let axis = Vector3::new(1.0, -2.0, 0.5).normalize();
        let (rate, dt, steps) = (0.5, 0.05, 1_000_000u32);
        let dtheta = axis * (rate * dt);
        let mut q = q0;
        let mut previous = dtheta;
        for _ in 0..steps {
            q *= quat_from_rotation_vector(&coning_rotation_vector(&previous, &dtheta));
            previous = dtheta;
        }
        let drift = (q.norm() - 1.0).abs();
        assert!(drift < 2.2e-10, "norm drifted by {drift:e}");
        let closed = q0 * UnitQuaternion::from_scaled_axis(axis * (rate * dt * steps as f64));
        // The rotation between the two, from the normalised product (the
        // norm is checked above), so the norm error does not enter.
        let error =
            UnitQuaternion::new_normalize(closed.inverse().into_inner() * q.into_inner()).angle();
        assert!(
            error < 1e-10,
            "attitude off the closed form by {error:e} rad"
        );
    }

    #[test]
    fn tool_axis_rate_from_rolling_accelerometers() {
        // A tool at 30 deg pitch, heading 40 deg, rolling about its axis at
        // 0.2 rad/s relative to the earth; earth rate ignored here
        // (omega_in = 0), so the gyros see only the roll's body rate, which is
        // purely along y: the x and z gyros read 0.
        let (pitch, heading, rate, dt) = (0.5, 0.7, 0.2, 0.05);
        let mut est = ToolAxisRateEstimator::new();
        let mut last = ToolAxisRate::Unavailable;
        for k in 0..5 {
            let e = Euler::new(0.1 + rate * dt * k as f64, pitch, heading);
            let f = specific_force_at_rest(&e, 9.8);
            last = est.update(&ProbeSample::new(0.0, 0.0, f), &Vector3::zeros(), dt);
            if k == 0 {
                assert_eq!(last, ToolAxisRate::Unavailable);
            }
        }
        let ToolAxisRate::Valid(r) = last else {
            panic!("expected a rate")
        };
        assert!((r - rate).abs() < 1e-12);
    }

    #[test]
    fn tool_axis_rate_with_heading_change_uses_the_gyros() {
        // Heading turning at 0.1 rad/s at fixed pitch and roll: the body rate
        // about y is -heading_rate sin(pitch) even though the accelerometer
        // roll does not change.
        let (roll, pitch, heading_rate, dt) = (0.3_f64, 0.4_f64, 0.1_f64, 0.05);
        let omega_n = Vector3::new(0.0, 0.0, heading_rate); // about down
        let mut est = ToolAxisRateEstimator::new();
        let mut last = ToolAxisRate::Unavailable;
        for k in 0..3 {
            let e = Euler::new(roll, pitch, heading_rate * dt * k as f64);
            let c = dcm_from_euler(&e);
            let w_b = c.transpose() * omega_n;
            let f = specific_force_at_rest(&e, 9.8);
            last = est.update(&ProbeSample::new(w_b.x, w_b.z, f), &Vector3::zeros(), dt);
            if k == 2 {
                let ToolAxisRate::Valid(r) = last else {
                    panic!("expected a rate")
                };
                assert!((r - w_b.y).abs() < 1e-12, "{r} vs {}", w_b.y);
            }
        }
        assert!(matches!(last, ToolAxisRate::Valid(_)));
    }

    #[test]
    fn tool_axis_rate_is_flagged_near_vertical() {
        let mut est = ToolAxisRateEstimator::new();
        let f = specific_force_at_rest(&Euler::new(0.0, -1.56, 0.0), 9.8);
        for _ in 0..3 {
            assert_eq!(
                est.update(&ProbeSample::new(0.0, 0.0, f), &Vector3::zeros(), 0.05),
                ToolAxisRate::Unavailable
            );
        }
        assert!(!level(&f).roll_valid);
        // A NaN sample never produces a rate either.
        let nan = Vector3::new(f64::NAN, 0.0, 9.8);
        assert_eq!(
            est.update(&ProbeSample::new(0.0, 0.0, nan), &Vector3::zeros(), 0.05),
            ToolAxisRate::Unavailable
        );
    }
}
