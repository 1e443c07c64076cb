//! Wellbore surveys: stations (measured depth, inclination, azimuth), the
//! north reference of their azimuths, a tie-on point, and positions by the
//! minimum curvature method (the SPE / ISCWSA convention: the path between
//! two stations is the circular arc tangent to both stations' directions).
//!
//! Angles follow [`crate::conventions`]: inclination 0 = straight down,
//! azimuth clockwise from north in [0, 2 pi). Lengths in metres; positions
//! are north, east and true vertical depth (down positive), i.e. NEV.
//! f64 throughout, no heap.

mod error;
mod min_curvature;
mod path;
mod reference;
mod station;

pub use error::SurveyError;
pub use min_curvature::{
    dogleg, dogleg_severity_deg_per_100ft, dogleg_severity_deg_per_30m, ratio_factor, tangent,
    Segment, SERIES_THRESHOLD,
};
pub use path::{interpolate, positions, Positions, SurveyPoint, TieOn, Walker};
pub use reference::{GridConvergence, GridNorth, NorthReference, TrueNorth};
pub use station::{GridStation, Station, TrueStation};

#[cfg(test)]
mod tests;
