//! The north an azimuth is measured from, carried in the types: a station,
//! tie-on or position in grid north cannot be mixed with one in true north.

use super::SurveyError;
use crate::conventions::wrap_two_pi;
use core::f64::consts::FRAC_PI_2;

/// Marker of an azimuth reference: [`TrueNorth`] or [`GridNorth`] (sealed).
pub trait NorthReference:
    sealed::Sealed + Clone + Copy + core::fmt::Debug + PartialEq + Default
{
}

mod sealed {
    pub trait Sealed {}
    impl Sealed for super::TrueNorth {}
    impl Sealed for super::GridNorth {}
}

/// Azimuths from true (geographic) north.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct TrueNorth;

/// Azimuths from the grid north of a map projection.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct GridNorth;

impl NorthReference for TrueNorth {}
impl NorthReference for GridNorth {}

/// The grid convergence at the well: the true azimuth of grid north, rad.
/// Grid azimuth = true azimuth - convergence.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridConvergence(f64);

impl GridConvergence {
    /// A convergence in radians, within +-pi/2 (real projections stay within
    /// a few degrees).
    pub fn new(angle: f64) -> Result<Self, SurveyError> {
        if (-FRAC_PI_2..=FRAC_PI_2).contains(&angle) {
            Ok(Self(angle))
        } else {
            Err(SurveyError::Convergence)
        }
    }

    pub fn angle(self) -> f64 {
        self.0
    }

    /// Grid azimuth of a true azimuth, in [0, 2 pi).
    pub fn grid_azimuth(self, true_azimuth: f64) -> f64 {
        wrap_two_pi(true_azimuth - self.0)
    }

    /// True azimuth of a grid azimuth, in [0, 2 pi).
    pub fn true_azimuth(self, grid_azimuth: f64) -> f64 {
        wrap_two_pi(grid_azimuth + self.0)
    }

    /// (cos, sin) of the convergence: a horizontal vector (n, e) in true
    /// north is (n c + e s, e c - n s) in grid north.
    pub(super) fn cos_sin(self) -> (f64, f64) {
        (libm::cos(self.0), libm::sin(self.0))
    }
}
