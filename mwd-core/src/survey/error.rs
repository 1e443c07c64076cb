//! Why a survey computation was refused.

/// A survey input out of its range, or survey stations that do not form a
/// path. Each message names the field and its range.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SurveyError {
    /// A measured depth is NaN or infinite.
    MeasuredDepth,
    /// An inclination is NaN or outside [0, pi].
    Inclination,
    /// An azimuth is NaN or infinite.
    Azimuth,
    /// A grid convergence is NaN or beyond +-pi/2.
    Convergence,
    /// A tie-on's TVD, north or east is NaN or infinite.
    TieOnPosition,
    /// A tie-on's covariance is not finite, not symmetric, or has a negative
    /// variance.
    TieOnCovariance,
    /// The first station is not at the tie-on's measured depth.
    TieOnDepth,
    /// Station `index` is not deeper (in measured depth) than the one before.
    DepthNotIncreasing { index: usize },
    /// Two stations point in opposite directions (dogleg of 180 deg): no
    /// circular arc joins them.
    OppositeDirections { index: usize },
    /// An interpolation depth outside the segment's measured depths.
    InterpolationDepth,
}

impl core::fmt::Display for SurveyError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::MeasuredDepth => f.write_str("a measured depth must be a finite number of metres"),
            Self::Inclination => {
                f.write_str("an inclination must be a number from 0 to pi rad (0 to 180 deg)")
            }
            Self::Azimuth => f.write_str("an azimuth must be a finite number of radians"),
            Self::Convergence => f.write_str(
                "a grid convergence must be a number from -pi/2 to pi/2 rad (-90 to 90 deg)",
            ),
            Self::TieOnPosition => {
                f.write_str("a tie-on's TVD, north and east must be finite numbers of metres")
            }
            Self::TieOnCovariance => f.write_str(
                "a tie-on's NEV covariance must be finite and symmetric with variances of 0 m^2 or more",
            ),
            Self::TieOnDepth => {
                f.write_str("the first station's measured depth must equal the tie-on's")
            }
            Self::DepthNotIncreasing { index } => write!(
                f,
                "station {index}'s measured depth must be greater than station {}'s",
                index.saturating_sub(1)
            ),
            Self::OppositeDirections { index } => write!(
                f,
                "station {index}'s dogleg must be less than 180 deg: it points opposite to station {}",
                index.saturating_sub(1)
            ),
            Self::InterpolationDepth => f.write_str(
                "an interpolation's measured depth must lie between the segment's two stations",
            ),
        }
    }
}

impl core::error::Error for SurveyError {}
