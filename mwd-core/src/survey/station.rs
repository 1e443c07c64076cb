//! A survey station: measured depth and the direction of the hole there.

use super::{GridConvergence, GridNorth, NorthReference, SurveyError, TrueNorth};
use crate::conventions::wrap_two_pi;
use core::f64::consts::PI;
use core::marker::PhantomData;

/// A validated station: MD finite, inclination in [0, pi], azimuth in
/// [0, 2 pi) from the north `N`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Station<N: NorthReference> {
    md: f64,
    inclination: f64,
    azimuth: f64,
    north: PhantomData<N>,
}

/// A station with its azimuth from true north.
pub type TrueStation = Station<TrueNorth>;
/// A station with its azimuth from grid north.
pub type GridStation = Station<GridNorth>;

impl<N: NorthReference> Station<N> {
    /// Measured depth (m), inclination (rad, 0 = down, in [0, pi]) and
    /// azimuth (rad, any finite value; normalised to [0, 2 pi)).
    pub fn new(md: f64, inclination: f64, azimuth: f64) -> Result<Self, SurveyError> {
        if !md.is_finite() {
            return Err(SurveyError::MeasuredDepth);
        }
        if !(0.0..=PI).contains(&inclination) {
            return Err(SurveyError::Inclination);
        }
        if !azimuth.is_finite() {
            return Err(SurveyError::Azimuth);
        }
        Ok(Self {
            md,
            inclination,
            azimuth: wrap_two_pi(azimuth),
            north: PhantomData,
        })
    }

    /// Measured depth along the hole, m.
    pub fn md(&self) -> f64 {
        self.md
    }

    /// Inclination from vertical down, rad in [0, pi].
    pub fn inclination(&self) -> f64 {
        self.inclination
    }

    /// Azimuth clockwise from north `N`, rad in [0, 2 pi).
    pub fn azimuth(&self) -> f64 {
        self.azimuth
    }

    /// The same direction with the azimuth replaced (already in [0, 2 pi)).
    fn with_azimuth<M: NorthReference>(&self, azimuth: f64) -> Station<M> {
        Station {
            md: self.md,
            inclination: self.inclination,
            azimuth,
            north: PhantomData,
        }
    }
}

impl Station<TrueNorth> {
    /// The station with its azimuth from grid north.
    pub fn to_grid(&self, convergence: GridConvergence) -> Station<GridNorth> {
        self.with_azimuth(convergence.grid_azimuth(self.azimuth))
    }
}

impl Station<GridNorth> {
    /// The station with its azimuth from true north.
    pub fn to_true(&self, convergence: GridConvergence) -> Station<TrueNorth> {
        self.with_azimuth(convergence.true_azimuth(self.azimuth))
    }
}
