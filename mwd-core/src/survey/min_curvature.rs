//! Minimum curvature between two stations (the SPE / ISCWSA method): the
//! hole between stations 1 and 2 is the circular arc whose tangents at its
//! ends are the stations' unit directions t1 and t2. The arc turns by the
//! dogleg beta (the angle between t1 and t2) over the course length L, and
//! its chord is L/2 * RF * (t1 + t2) with the ratio factor
//! RF = 2/beta * tan(beta/2): the balanced-tangential step stretched onto
//! the arc.

use super::{NorthReference, Station, SurveyError};
use crate::conventions::{wrap_two_pi, DEG};
use core::f64::consts::PI;
use nalgebra::Vector3;

/// Below this dogleg (rad) the ratio factor is its series
/// 1 + beta^2/12 + beta^4/120: the next term, 17 beta^6/20160, is under
/// 1e-27 there, so the series is exact in f64, and it has no 0/0 at 0.
pub const SERIES_THRESHOLD: f64 = 1e-4;

/// A dogleg closer than this (rad) to pi is refused: the arc's chord is a
/// huge RF times a vanishing t1 + t2, and at pi no arc exists.
const OPPOSITE_MARGIN: f64 = 1e-6;

/// Metres in 100 ft.
const HUNDRED_FEET: f64 = 30.48;

/// The unit direction of the hole, NEV (north, east, down), from
/// inclination and azimuth: (sin I cos A, sin I sin A, cos I).
pub fn tangent(inclination: f64, azimuth: f64) -> Vector3<f64> {
    let (si, ci) = (libm::sin(inclination), libm::cos(inclination));
    Vector3::new(si * libm::cos(azimuth), si * libm::sin(azimuth), ci)
}

/// The dogleg (rad) between two directions, by the haversine form
/// beta = 2 asin(sqrt(h)), h = sin^2(dI/2) + sin I1 sin I2 sin^2(dA/2),
/// which keeps full relative precision at small angles where the usual
/// cosine form acos(cos dI - sin I1 sin I2 (1 - cos dA)) loses half the
/// digits. Near 180 deg asin loses them instead, so the angle is taken as
/// beta = 2 atan2(sqrt(h), sqrt(1 - h)) with 1 - h from its own sum of
/// non-negative terms, cos^2((I1 + I2)/2) + sin I1 sin I2 cos^2(dA/2): no
/// cancellation at either end.
pub fn dogleg(inc1: f64, azi1: f64, inc2: f64, azi2: f64) -> f64 {
    let sines = libm::sin(inc1) * libm::sin(inc2);
    let (s_inc, c_mean) = (
        libm::sin(0.5 * (inc2 - inc1)),
        libm::cos(0.5 * (inc1 + inc2)),
    );
    let (s_azi, c_azi) = (
        libm::sin(0.5 * (azi2 - azi1)),
        libm::cos(0.5 * (azi2 - azi1)),
    );
    let h = s_inc * s_inc + sines * s_azi * s_azi;
    let complement = c_mean * c_mean + sines * c_azi * c_azi;
    2.0 * libm::atan2(libm::sqrt(h.max(0.0)), libm::sqrt(complement.max(0.0)))
}

/// The ratio factor RF = 2/beta * tan(beta/2) of a dogleg beta (rad) in
/// [0, pi); its series below [`SERIES_THRESHOLD`]. RF -> 1 as beta -> 0.
pub fn ratio_factor(beta: f64) -> f64 {
    if beta < SERIES_THRESHOLD {
        let b2 = beta * beta;
        1.0 + b2 / 12.0 + b2 * b2 / 120.0
    } else {
        libm::tan(0.5 * beta) / (0.5 * beta)
    }
}

/// Dogleg severity in deg/30 m of a dogleg (rad) over a course length (m).
pub fn dogleg_severity_deg_per_30m(beta: f64, course_length: f64) -> f64 {
    beta / course_length * 30.0 / DEG
}

/// Dogleg severity in deg/100 ft of a dogleg (rad) over a course length (m).
pub fn dogleg_severity_deg_per_100ft(beta: f64, course_length: f64) -> f64 {
    beta / course_length * HUNDRED_FEET / DEG
}

/// The arc between two consecutive stations.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Segment<N: NorthReference> {
    from: Station<N>,
    to: Station<N>,
    dogleg: f64,
    /// The unit tangents at `from` and `to`, computed once: a simulated
    /// hole reads its plan's arcs twice per sample.
    start_tangent: Vector3<f64>,
    end_tangent: Vector3<f64>,
}

impl<N: NorthReference> Segment<N> {
    /// The arc from `from` to `to`: `to` must be deeper, and not point
    /// opposite to `from` (errors carry index 1, the second station).
    pub fn new(from: Station<N>, to: Station<N>) -> Result<Self, SurveyError> {
        // Validated depths are finite, so the length is a number (maybe
        // infinite when the depths are +-1e308 apart).
        let length = to.md() - from.md();
        if length <= 0.0 || !length.is_finite() {
            return Err(SurveyError::DepthNotIncreasing { index: 1 });
        }
        let beta = dogleg(
            from.inclination(),
            from.azimuth(),
            to.inclination(),
            to.azimuth(),
        );
        if beta > PI - OPPOSITE_MARGIN {
            return Err(SurveyError::OppositeDirections { index: 1 });
        }
        Ok(Self {
            from,
            to,
            dogleg: beta,
            start_tangent: tangent(from.inclination(), from.azimuth()),
            end_tangent: tangent(to.inclination(), to.azimuth()),
        })
    }

    pub fn from(&self) -> &Station<N> {
        &self.from
    }

    pub fn to(&self) -> &Station<N> {
        &self.to
    }

    /// Course length (m).
    pub fn length(&self) -> f64 {
        self.to.md() - self.from.md()
    }

    /// Dogleg (rad).
    pub fn dogleg(&self) -> f64 {
        self.dogleg
    }

    pub fn dogleg_severity_deg_per_30m(&self) -> f64 {
        dogleg_severity_deg_per_30m(self.dogleg, self.length())
    }

    pub fn dogleg_severity_deg_per_100ft(&self) -> f64 {
        dogleg_severity_deg_per_100ft(self.dogleg, self.length())
    }

    /// The chord (north, east, TVD increments, m): L/2 * RF * (t1 + t2).
    pub fn increment(&self) -> Vector3<f64> {
        self.chord(self.length(), self.dogleg, &self.end_tangent())
    }

    /// The station at measured depth `md` on the arc and the chord to it
    /// from `from`. The direction there is the slerp of t1 and t2 by the
    /// fraction f of the course: (sin((1-f) beta) t1 + sin(f beta) t2) /
    /// sin beta, which turns by f beta at a constant rate in the arc's
    /// plane; the chord is that of the partial arc. At the stations' own
    /// depths the stations come back unchanged.
    pub fn at(&self, md: f64) -> Result<(Station<N>, Vector3<f64>), SurveyError> {
        if !(self.from.md()..=self.to.md()).contains(&md) {
            return Err(SurveyError::InterpolationDepth);
        }
        if md == self.from.md() {
            return Ok((self.from, Vector3::zeros()));
        }
        if md == self.to.md() {
            return Ok((self.to, self.increment()));
        }
        let f = (md - self.from.md()) / self.length();
        let t1 = self.start_tangent();
        let t = if self.dogleg == 0.0 {
            t1
        } else {
            let s = libm::sin(self.dogleg);
            (t1 * libm::sin((1.0 - f) * self.dogleg)
                + self.end_tangent() * libm::sin(f * self.dogleg))
                / s
        };
        let horizontal = libm::sqrt(t.x * t.x + t.y * t.y);
        let inclination = libm::atan2(horizontal, t.z);
        let azimuth = if horizontal > 0.0 {
            wrap_two_pi(libm::atan2(t.y, t.x))
        } else {
            self.from.azimuth()
        };
        let station = Station::new(md, inclination, azimuth)?;
        Ok((
            station,
            self.chord(md - self.from.md(), f * self.dogleg, &t),
        ))
    }

    /// The unit tangent at `from` (north, east, down).
    pub fn start_tangent(&self) -> Vector3<f64> {
        self.start_tangent
    }

    /// The unit tangent at `to`.
    pub fn end_tangent(&self) -> Vector3<f64> {
        self.end_tangent
    }

    /// Chord of an arc of `length` and dogleg `beta` from `from`'s direction
    /// to `end`.
    fn chord(&self, length: f64, beta: f64, end: &Vector3<f64>) -> Vector3<f64> {
        (self.start_tangent() + end) * (0.5 * length * ratio_factor(beta))
    }
}
