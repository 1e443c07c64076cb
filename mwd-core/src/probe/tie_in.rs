//! Starting navigation from a tie-in instead of the static alignment: a
//! lateral drilled out of a horizontal well starts where the parent well's
//! survey says the window is, with that survey's inclination, azimuth and
//! toolface and their 1-sigma (docs/filter-derivation.md section 4c).
//!
//! The angles become the initial attitude; their variances become the
//! attitude-error covariance through the Jacobian of the project's Euler
//! convention (`conventions::euler_error_jacobian`): with the tool axis
//! t = C_b^n e_y = (cp ch, cp sh, -sp) and M = [t, (-sh, ch, 0), e3]
//! (columns), an error d(roll, pitch, heading) is the nav-frame rotation
//! M d, and the psi-angle phi is its opposite (C~ = (I - [phi x]) C), so
//!
//! ```text
//! phi = -M d(roll, pitch, heading),   P_phi = M diag(s_roll^2, s_pitch^2, s_heading^2) M^T
//! ```
//!
//! and J P_phi J^T with J = -M^-1 gives the diagonal back. Roll is the
//! toolface, pitch the inclination less 90 deg and heading the azimuth
//! (`conventions::DrillingAngles`), so their sigmas are the same numbers.
//! The three survey angles are taken as independent (a survey listing gives
//! no correlations).

use crate::aid_sources::attitude_angle_scalar;
use crate::conventions::{dcm_from_euler, quat_from_euler, DrillingAngles, DEG};
use crate::error_model::TILT_SIGMA_LIMIT_RAD;
use crate::kalman::{FilterScalar, Measurement, ScalarMeasurement};
use core::f64::consts::{PI, TAU};
use nalgebra::{Matrix3, UnitQuaternion};

/// Inclination (rad) within which of vertical a tie-in is refused: there
/// the azimuth and the gravity toolface are not defined by the survey, and
/// the Euler angles' Jacobian grows as 1/sin(inclination) (57 at 1 deg).
pub const MIN_INCLINATION_RAD: f64 = 1.0 * DEG;

/// The largest azimuth 1-sigma (rad) accepted: the filter's largest
/// heading prior (`FineAlignmentConfig::physical` clamps to 30 deg); beyond
/// it the small-angle error model does not describe the error.
pub const MAX_AZIMUTH_SIGMA_RAD: f64 = 30.0 * DEG;

/// Which of the tie-in's numbers is wrong.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TieInAngle {
    Inclination,
    Azimuth,
    Toolface,
}

/// Why a tie-in was refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TieInError {
    /// The angle is NaN or infinite.
    AngleNotFinite(TieInAngle),
    /// The angle is outside its range: inclination [0, 180] deg, azimuth
    /// and toolface [0, 360) deg.
    AngleOutOfRange(TieInAngle),
    /// The inclination is within [`MIN_INCLINATION_RAD`] of vertical.
    NearVertical,
    /// The angle's 1-sigma is NaN, infinite, zero or negative.
    SigmaNotPositive(TieInAngle),
    /// The 1-sigma is beyond what the filter's small-angle model holds:
    /// inclination and toolface beyond the error model's tilt limit
    /// ([`TILT_SIGMA_LIMIT_RAD`], 3 deg: the solution would be invalid from
    /// its first frame), azimuth beyond [`MAX_AZIMUTH_SIGMA_RAD`].
    SigmaTooLarge(TieInAngle),
}

impl core::fmt::Display for TieInAngle {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            TieInAngle::Inclination => "inclination",
            TieInAngle::Azimuth => "azimuth",
            TieInAngle::Toolface => "toolface",
        })
    }
}

impl core::fmt::Display for TieInError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            TieInError::AngleNotFinite(a) => write!(f, "tie-in {a} is not a finite number"),
            TieInError::AngleOutOfRange(a) => write!(
                f,
                "tie-in {a} out of range (inclination 0..180 deg, azimuth and toolface 0..360 deg)"
            ),
            TieInError::NearVertical => write!(
                f,
                "tie-in inclination within 1 deg of vertical: azimuth and toolface undefined"
            ),
            TieInError::SigmaNotPositive(a) => {
                write!(f, "tie-in {a} 1-sigma must be a finite number > 0")
            }
            TieInError::SigmaTooLarge(a) => write!(
                f,
                "tie-in {a} 1-sigma too large (inclination and toolface <= 3 deg, azimuth <= 30 deg)"
            ),
        }
    }
}

/// A validated tie-in: the parent well's survey angles at the window and
/// their 1-sigma, all in radians.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TieIn {
    angles: DrillingAngles,
    sigma: DrillingAngles,
}

impl TieIn {
    /// `angles`: inclination in [0, pi], azimuth and toolface in
    /// [0, 2 pi); `sigma`: the 1-sigma of each (rad, > 0; inclination and
    /// toolface at most the tilt limit, 3 deg; azimuth at most 30 deg).
    pub fn new(angles: DrillingAngles, sigma: DrillingAngles) -> Result<Self, TieInError> {
        use TieInAngle::*;
        let checks = [
            (Inclination, angles.inclination, PI, sigma.inclination),
            (Azimuth, angles.azimuth, TAU, sigma.azimuth),
            (Toolface, angles.toolface, TAU, sigma.toolface),
        ];
        for (which, value, _, _) in checks {
            if !value.is_finite() {
                return Err(TieInError::AngleNotFinite(which));
            }
        }
        for (which, value, end, _) in checks {
            // Inclination's range is closed, the circular ones half-open.
            let inside = match which {
                Inclination => (0.0..=end).contains(&value),
                Azimuth | Toolface => (0.0..end).contains(&value),
            };
            if !inside {
                return Err(TieInError::AngleOutOfRange(which));
            }
        }
        if angles.inclination < MIN_INCLINATION_RAD || angles.inclination > PI - MIN_INCLINATION_RAD
        {
            return Err(TieInError::NearVertical);
        }
        for (which, _, _, s) in checks {
            // `!(s > 0)` also catches NaN.
            if !(s > 0.0 && s.is_finite()) {
                return Err(TieInError::SigmaNotPositive(which));
            }
            let limit = match which {
                Azimuth => MAX_AZIMUTH_SIGMA_RAD,
                Inclination | Toolface => TILT_SIGMA_LIMIT_RAD,
            };
            if s > limit {
                return Err(TieInError::SigmaTooLarge(which));
            }
        }
        Ok(Self { angles, sigma })
    }

    /// Inclination, azimuth, toolface (rad).
    pub fn angles(&self) -> DrillingAngles {
        self.angles
    }

    /// Their 1-sigma (rad).
    pub fn sigma(&self) -> DrillingAngles {
        self.sigma
    }

    /// The attitude C_b^n as a quaternion.
    pub fn attitude(&self) -> UnitQuaternion<f64> {
        quat_from_euler(&self.angles.to_euler())
    }

    /// 1-sigma of roll, pitch, heading (rad): toolface, inclination and
    /// azimuth differ from them by constants, so the sigmas are theirs.
    pub fn euler_sigma(&self) -> [f64; 3] {
        [
            self.sigma.toolface,
            self.sigma.inclination,
            self.sigma.azimuth,
        ]
    }

    /// The attitude-error (psi-angle) covariance, rad^2:
    /// M diag(sigma^2) M^T (module documentation).
    pub fn attitude_error_covariance(&self) -> Matrix3<f64> {
        let e = self.angles.to_euler();
        let c_bn = dcm_from_euler(&e);
        let (sh, ch) = (libm::sin(e.heading), libm::cos(e.heading));
        #[rustfmt::skip]
        let m = Matrix3::new(
            c_bn[(0, 1)], -sh, 0.0,
            c_bn[(1, 1)], ch,  0.0,
            c_bn[(2, 1)], 0.0, 1.0,
        );
        let d = Matrix3::from_diagonal(&self.euler_sigma().map(|s| s * s).into());
        m * d * m.transpose()
    }
}

/// The tie-in's inclination and toolface as measurements of the filter's
/// attitude error (`Navigator::start_from_tie_in`): z = computed - tie-in
/// (toolface wrapped), h = the angle's row of the drilling-angle Jacobian
/// (`super::station::angles_and_jacobian`) on the attitude states, r = the
/// tie-in's variance. Fused with the probe's own levelling, not put in its
/// place: the levelled tilt carries the accelerometer biases it was
/// levelled with, and that correlation is the filter's to keep.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TieInTilt<T> {
    pub rows: [[T; 3]; 2],
    pub innovation: [T; 2],
    pub variance: [T; 2],
}

impl<T: FilterScalar> Measurement<T> for TieInTilt<T> {
    fn len(&self) -> usize {
        2
    }
    fn scalar(&self, k: usize) -> Option<ScalarMeasurement<T>> {
        let row = self.rows.get(k)?;
        Some(attitude_angle_scalar(
            self.innovation[k],
            row,
            self.variance[k],
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::conventions::{euler_error_jacobian, euler_from_quat, skew, wrap_pi, Euler};
    use crate::earth::Position;
    use crate::probe::Navigator;
    use crate::protocol::frame::{nav_flags, nav_mode};
    use crate::protocol::RawSample;
    use crate::sensor_units::STANDARD_GRAVITY_M_S2;
    use nalgebra::{Rotation3, Vector3};

    fn angles(inc_deg: f64, azi_deg: f64, tf_deg: f64) -> DrillingAngles {
        DrillingAngles {
            inclination: inc_deg * DEG,
            azimuth: azi_deg * DEG,
            toolface: tf_deg * DEG,
        }
    }

    /// A lateral's tie-in: 89.5 deg inclination heading 137 deg, toolface
    /// 210 deg; 0.1 deg inclination, 0.5 deg azimuth, 0.3 deg toolface.
    fn lateral() -> TieIn {
        TieIn::new(angles(89.5, 137.0, 210.0), angles(0.1, 0.5, 0.3)).unwrap()
    }

    #[test]
    fn the_covariance_maps_back_to_the_sigmas_through_the_jacobian() {
        for (inc, azi, tf) in [
            (89.5, 137.0, 210.0),
            (45.0, 0.0, 0.0),
            (2.0, 300.0, 91.0),
            (178.0, 45.0, 359.0),
            (120.0, 270.0, 180.0),
        ] {
            let sigma = angles(0.2, 3.0, 1.5);
            let t = TieIn::new(angles(inc, azi, tf), sigma).unwrap();
            let c_bn = dcm_from_euler(&t.angles().to_euler());
            let j = euler_error_jacobian(&c_bn);
            let back = j * t.attitude_error_covariance() * j.transpose();
            let expected = Matrix3::from_diagonal(&t.euler_sigma().map(|s| s * s).into());
            // The Jacobian's 1/cos(pitch) entries amplify rounding near
            // vertical (28 at 2 deg).
            let tolerance = 1e-14 / libm::pow(libm::sin(inc * DEG), 2.0);
            assert!(
                (back - expected).amax() < tolerance * expected.amax(),
                "{inc} {azi} {tf}: {back} vs {expected}"
            );
        }
    }

    /// The mapping is the linearisation of the angles' own error: drawn
    /// errors d(roll, pitch, heading) turned into C~ and read back as phi
    /// (C~ C^T = I - [phi x]) give phi = -M d to second order.
    #[test]
    fn the_mapping_matches_angle_errors_turned_into_rotations() {
        let t = lateral();
        let e = t.angles().to_euler();
        let c = dcm_from_euler(&e);
        let p = t.attitude_error_covariance();
        for d in [
            Vector3::new(1e-5, 0.0, 0.0),
            Vector3::new(0.0, 1e-5, 0.0),
            Vector3::new(0.0, 0.0, 1e-5),
        ] {
            let perturbed =
                dcm_from_euler(&Euler::new(e.roll + d.x, e.pitch + d.y, e.heading + d.z));
            // phi from the small rotation I - [phi x] = C~ C^T.
            let r = Rotation3::from_matrix_unchecked(perturbed * c.transpose());
            let phi = -r.scaled_axis();
            // phi^T P^-1 phi = d^T diag(sigma^-2) d: the same Mahalanobis
            // length in both parametrisations.
            let inv = p.try_inverse().unwrap();
            let s = t.euler_sigma();
            let in_angles = (d.x / s[0]).powi(2) + (d.y / s[1]).powi(2) + (d.z / s[2]).powi(2);
            let in_phi = (phi.transpose() * inv * phi)[(0, 0)];
            assert!(
                (in_phi / in_angles - 1.0).abs() < 1e-4,
                "{in_phi} vs {in_angles}"
            );
            // And the first-order relation itself.
            let small = (Matrix3::identity() - skew(&phi)) * c;
            assert!((small - perturbed).amax() < 1e-9);
        }
    }

    #[test]
    fn started_from_a_tie_in_the_solution_is_the_tie_in() {
        let t = lateral();
        let mut navigator = Navigator::new(Position::paper_site());
        navigator.start_from_tie_in(&t);
        assert!(navigator.is_navigating());
        let fa = navigator.filter();
        let got =
            crate::conventions::DrillingAngles::from_euler(&euler_from_quat(&fa.state().attitude));
        let want = t.angles();
        for (a, b) in [
            (got.inclination, want.inclination),
            (got.azimuth, want.azimuth),
            (got.toolface, want.toolface),
        ] {
            assert!(wrap_pi(a - b).abs() < 1e-12, "{got:?} vs {want:?}");
        }
        // The sigmas through the round trip P_phi (f32) -> J P J^T: f32's
        // rounding of the covariance, ~1e-7 relative on the variances.
        let std = fa.euler_std();
        for (i, s) in t.euler_sigma().iter().enumerate() {
            assert!((std[i] / s - 1.0).abs() < 1e-6, "{i}: {std:?} vs {s}");
        }
        // The attitude is independent of everything else.
        let p = &fa.filter().p;
        for i in 0..3 {
            for j in 3..p.ncols() {
                assert_eq!(p[(i, j)], 0.0);
            }
        }
    }

    /// Tied in while navigating: the azimuth is the tie-in's with its
    /// sigma, its inclination pulls the probe's own by the weights of the
    /// two variances, and a toolface with a 3-deg sigma barely moves the
    /// probe's.
    #[test]
    fn a_navigating_probe_takes_the_azimuth_and_fuses_the_tilt() {
        let first = lateral();
        let mut navigator = Navigator::new(Position::paper_site());
        navigator.start_from_tie_in(&first);
        let own = first.angles();
        let tie = TieIn::new(
            DrillingAngles {
                inclination: own.inclination + 0.3 * DEG,
                azimuth: own.azimuth + 10.0 * DEG,
                toolface: own.toolface + 1.0 * DEG,
            },
            DrillingAngles {
                inclination: 0.1 * DEG,
                azimuth: 0.5 * DEG,
                toolface: 3.0 * DEG,
            },
        )
        .unwrap();
        navigator.start_from_tie_in(&tie);
        let fa = navigator.filter();
        let got =
            crate::conventions::DrillingAngles::from_euler(&euler_from_quat(&fa.state().attitude));
        // Inclination: pulled towards the tie-in's, by the weight of the
        // two variances: the probe's own is the levelling's (0.1 deg here)
        // plus its accelerometer biases' share, so more than half way.
        let moved = (got.inclination - own.inclination) / (0.3 * DEG);
        assert!((0.5..0.95).contains(&moved), "moved {moved}: {got:?}");
        // The azimuth is the tie-in's (the tilt update's Jacobian reaches
        // the heading a little at 89.5 deg).
        assert!(
            wrap_pi(got.azimuth - tie.angles().azimuth).abs() < 0.01 * DEG,
            "{got:?}"
        );
        // Toolface: a 3-deg tie-in moves the probe's levelled toolface
        // towards it, by less than half the offset.
        let moved_tf = wrap_pi(got.toolface - own.toolface) / (1.0 * DEG);
        assert!((0.0..0.5).contains(&moved_tf), "moved {moved_tf}: {got:?}");
        let std = fa.euler_std();
        assert!((std.z / (0.5 * DEG) - 1.0).abs() < 1e-3, "{std:?}");
    }

    /// A still probe feeling gravity at the tie-in's attitude (no earth
    /// rate: the hil-mock static probe).
    fn still_at(t: &TieIn, n: u32) -> RawSample {
        let force = crate::conventions::specific_force_at_rest(
            &t.angles().to_euler(),
            f64::from(STANDARD_GRAVITY_M_S2),
        )
        .map(|f| f as f32);
        crate::probe::test_support::still_sample(n, [force.x, force.y, force.z])
    }

    #[test]
    fn the_first_frame_after_a_tie_in_navigates_from_it() {
        let t = lateral();
        let mut navigator = Navigator::new(Position::paper_site());
        // Part-way through a coarse alignment: the tie-in replaces it.
        for n in 0..10 {
            navigator.step(&still_at(&t, n));
        }
        navigator.start_from_tie_in(&t);
        let frame = navigator.step(&still_at(&t, 10));
        assert_eq!(frame.mode, nav_mode::NAVIGATING);
        assert_eq!(frame.flags & nav_flags::SOLUTION_INVALID, 0, "{frame:?}");
        let e = t.angles().to_euler();
        // One 50 ms step: the probe sensed no earth rate (7.3e-5 rad/s):
        // 3.6e-6 rad of turn, plus f32 rounding of the frame.
        let want = [e.roll, e.pitch, e.heading];
        for (got, want) in frame.attitude.iter().zip(want) {
            let error = wrap_pi(f64::from(*got) - want);
            assert!(error.abs() < 1e-5, "{want}: {frame:?}");
        }
        // One step of process noise on top of the tie-in's sigmas, and the
        // step's non-holonomic update (not yet still: the detector needs
        // its window), which levels a little.
        for (i, s) in t.euler_sigma().iter().enumerate() {
            let ratio = f64::from(frame.attitude_std[i]) / s;
            assert!((0.99..1.01).contains(&ratio), "{i}: {frame:?}");
        }
        assert!(frame.velocity_std.iter().all(|s| s.is_finite() && *s > 0.0));
    }

    /// The navigator's NHC hook: only while navigating; on a still probe
    /// started from a tie-in both scalars are taken and the cross-axis
    /// velocity variances drop below the constraint's.
    #[test]
    fn the_navigator_applies_the_constraint_only_while_navigating() {
        use crate::aid_sources::DRILLING_VARIANCE;
        use crate::error_model::VEL;
        let t = lateral();
        let mut navigator = Navigator::new(Position::paper_site());
        navigator.step(&still_at(&t, 0));
        assert_eq!(navigator.apply_non_holonomic(), None);
        navigator.start_from_tie_in(&t);
        for n in 1..=20 {
            navigator.step(&still_at(&t, n));
        }
        let cross_variance = |nav: &Navigator| -> [f64; 2] {
            let c = dcm_from_euler(&t.angles().to_euler());
            let p = nav
                .filter()
                .filter()
                .p
                .fixed_view::<3, 3>(VEL, VEL)
                .map(f64::from);
            [0, 2].map(|a| {
                let r = c.column(a);
                (r.transpose() * p * r)[(0, 0)]
            })
        };
        let before = cross_variance(&navigator);
        let report = navigator.apply_non_holonomic().expect("navigating");
        assert_eq!(report.accepted, 2, "{report:?}");
        let after = cross_variance(&navigator);
        for a in 0..2 {
            assert!(
                after[a] < before[a] && after[a] < DRILLING_VARIANCE,
                "{before:?} {after:?}"
            );
        }
    }

    #[test]
    fn bad_tie_ins_are_refused_with_the_reason() {
        let good = angles(89.5, 137.0, 210.0);
        let sigma = angles(0.1, 0.5, 0.3);
        assert!(TieIn::new(good, sigma).is_ok());
        // Edges that are valid.
        assert!(TieIn::new(angles(90.0, 0.0, 0.0), sigma).is_ok());
        assert!(TieIn::new(angles(179.0, 359.999, 359.999), angles(3.0, 30.0, 3.0)).is_ok());
        use TieInAngle::*;
        use TieInError::*;
        let cases = [
            (
                DrillingAngles {
                    inclination: f64::NAN,
                    ..good
                },
                sigma,
                AngleNotFinite(Inclination),
            ),
            (
                DrillingAngles {
                    azimuth: f64::INFINITY,
                    ..good
                },
                sigma,
                AngleNotFinite(Azimuth),
            ),
            (
                DrillingAngles {
                    toolface: f64::NEG_INFINITY,
                    ..good
                },
                sigma,
                AngleNotFinite(Toolface),
            ),
            (
                angles(-1.0, 137.0, 210.0),
                sigma,
                AngleOutOfRange(Inclination),
            ),
            (
                angles(181.0, 137.0, 210.0),
                sigma,
                AngleOutOfRange(Inclination),
            ),
            (angles(89.5, 360.0, 210.0), sigma, AngleOutOfRange(Azimuth)),
            (angles(89.5, -0.1, 210.0), sigma, AngleOutOfRange(Azimuth)),
            (angles(89.5, 137.0, 400.0), sigma, AngleOutOfRange(Toolface)),
            (angles(0.5, 137.0, 210.0), sigma, NearVertical),
            (angles(0.0, 137.0, 210.0), sigma, NearVertical),
            (angles(179.5, 137.0, 210.0), sigma, NearVertical),
            (good, angles(0.0, 0.5, 0.3), SigmaNotPositive(Inclination)),
            (good, angles(0.1, -0.5, 0.3), SigmaNotPositive(Azimuth)),
            (
                good,
                DrillingAngles {
                    toolface: f64::NAN,
                    ..sigma
                },
                SigmaNotPositive(Toolface),
            ),
            (
                good,
                DrillingAngles {
                    azimuth: f64::INFINITY,
                    ..sigma
                },
                SigmaNotPositive(Azimuth),
            ),
            (good, angles(3.5, 0.5, 0.3), SigmaTooLarge(Inclination)),
            (good, angles(0.1, 31.0, 0.3), SigmaTooLarge(Azimuth)),
            (good, angles(0.1, 0.5, 5.0), SigmaTooLarge(Toolface)),
        ];
        for (a, s, expected) in cases {
            assert_eq!(TieIn::new(a, s), Err(expected), "{a:?} {s:?}");
        }
    }

    #[test]
    fn every_refusal_says_what_is_wrong() {
        extern crate std;
        use std::string::ToString;
        let text = TieInError::SigmaTooLarge(TieInAngle::Azimuth).to_string();
        assert!(
            text.contains("azimuth") && text.contains("30 deg"),
            "{text}"
        );
        let text = TieInError::AngleNotFinite(TieInAngle::Toolface).to_string();
        assert!(text.contains("toolface"), "{text}");
    }
}
