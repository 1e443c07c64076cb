//! Positions of a run of stations from a tie-on point, station by station,
//! with no heap: an iterator over the stations' slice.

use super::{GridConvergence, GridNorth, NorthReference, Segment, Station, SurveyError, TrueNorth};
use core::marker::PhantomData;
use nalgebra::{Matrix3, Vector3};

/// The known position the survey starts from: the position of its first
/// station. North and east in the reference `N`, TVD down, all m, with the
/// 3x3 covariance of (north, east, TVD) in m^2.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TieOn<N: NorthReference> {
    md: f64,
    nev: Vector3<f64>,
    covariance: Matrix3<f64>,
    north: PhantomData<N>,
}

impl<N: NorthReference> TieOn<N> {
    /// A tie-on: every number finite, the covariance symmetric with
    /// variances of 0 or more.
    pub fn new(
        md: f64,
        tvd: f64,
        north: f64,
        east: f64,
        covariance: Matrix3<f64>,
    ) -> Result<Self, SurveyError> {
        if !md.is_finite() {
            return Err(SurveyError::MeasuredDepth);
        }
        if !(tvd.is_finite() && north.is_finite() && east.is_finite()) {
            return Err(SurveyError::TieOnPosition);
        }
        let symmetric = covariance == covariance.transpose();
        let finite = covariance.iter().all(|x| x.is_finite());
        if !(symmetric && finite && covariance.diagonal().iter().all(|&v| v >= 0.0)) {
            return Err(SurveyError::TieOnCovariance);
        }
        Ok(Self {
            md,
            nev: Vector3::new(north, east, tvd),
            covariance,
            north: PhantomData,
        })
    }

    /// A tie-on at the origin (a wellhead at MD 0), known exactly.
    pub fn origin() -> Self {
        Self {
            md: 0.0,
            nev: Vector3::zeros(),
            covariance: Matrix3::zeros(),
            north: PhantomData,
        }
    }

    pub fn md(&self) -> f64 {
        self.md
    }

    /// (north, east, TVD), m.
    pub fn nev(&self) -> Vector3<f64> {
        self.nev
    }

    /// Covariance of (north, east, TVD), m^2.
    pub fn covariance(&self) -> &Matrix3<f64> {
        &self.covariance
    }

    fn rotated<M: NorthReference>(&self, c: f64, s: f64) -> TieOn<M> {
        // (n, e) -> (n c + e s, e c - n s); TVD unchanged.
        let r = Matrix3::new(c, s, 0.0, -s, c, 0.0, 0.0, 0.0, 1.0);
        TieOn {
            md: self.md,
            nev: r * self.nev,
            covariance: r * self.covariance * r.transpose(),
            north: PhantomData,
        }
    }
}

impl TieOn<TrueNorth> {
    /// The tie-on with north and east along grid north and east.
    pub fn to_grid(&self, convergence: GridConvergence) -> TieOn<GridNorth> {
        let (c, s) = convergence.cos_sin();
        self.rotated(c, s)
    }
}

impl TieOn<GridNorth> {
    /// The tie-on with north and east along true north and east.
    pub fn to_true(&self, convergence: GridConvergence) -> TieOn<TrueNorth> {
        let (c, s) = convergence.cos_sin();
        self.rotated(c, -s)
    }
}

/// A station with its position.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurveyPoint<N: NorthReference> {
    pub station: Station<N>,
    /// (north, east, TVD), m.
    pub nev: Vector3<f64>,
    /// Dogleg severity of the arc ending here, deg/30 m (0 at the tie-on).
    pub dls_deg_per_30m: f64,
}

impl<N: NorthReference> SurveyPoint<N> {
    pub fn north(&self) -> f64 {
        self.nev.x
    }

    pub fn east(&self) -> f64 {
        self.nev.y
    }

    pub fn tvd(&self) -> f64 {
        self.nev.z
    }

    /// The horizontal displacement along the direction of azimuth
    /// `direction` (rad, from the same north) from the origin of north and
    /// east: N cos(direction) + E sin(direction).
    pub fn vertical_section(&self, direction: f64) -> f64 {
        self.nev.x * libm::cos(direction) + self.nev.y * libm::sin(direction)
    }
}

/// The positions of `stations` from `tie_on` by minimum curvature, one item
/// per station: the first station must be at the tie-on's MD, and MD must
/// strictly increase. After an error the iterator ends.
pub fn positions<'a, N: NorthReference>(
    tie_on: &TieOn<N>,
    stations: &'a [Station<N>],
) -> Positions<'a, N> {
    Positions {
        walker: Walker::new(tie_on),
        stations,
        index: 0,
        failed: false,
    }
}

/// The station and position at measured depth `md` on the minimum
/// curvature path of `stations` from `tie_on` (see [`Segment::at`]); the
/// stations' own depths give the stations. An error from the stations up to
/// `md`, or [`SurveyError::InterpolationDepth`] when `md` is outside them.
pub fn interpolate<N: NorthReference>(
    tie_on: &TieOn<N>,
    stations: &[Station<N>],
    md: f64,
) -> Result<SurveyPoint<N>, SurveyError> {
    let mut previous: Option<SurveyPoint<N>> = None;
    for point in positions(tie_on, stations) {
        let point = point?;
        if point.station.md() >= md {
            let Some(before) = previous else {
                return if point.station.md() == md {
                    Ok(point)
                } else {
                    Err(SurveyError::InterpolationDepth)
                };
            };
            if point.station.md() == md {
                return Ok(point);
            }
            let segment = Segment::new(before.station, point.station)?;
            let (station, chord) = segment.at(md)?;
            return Ok(SurveyPoint {
                station,
                nev: before.nev + chord,
                dls_deg_per_30m: point.dls_deg_per_30m,
            });
        }
        previous = Some(point);
    }
    Err(SurveyError::InterpolationDepth)
}

/// Minimum curvature one station at a time: the positions of a survey
/// whose stations arrive as a stream (a file of a million stations, read
/// once), holding only the last station. [`positions`] walks a slice with
/// it.
#[derive(Clone, Debug)]
pub struct Walker<N: NorthReference> {
    md: f64,
    nev: Vector3<f64>,
    previous: Option<Station<N>>,
    /// Index of the next station (in the errors).
    index: usize,
}

impl<N: NorthReference> Walker<N> {
    /// Starts at `tie_on`: the first station must be at its MD.
    pub fn new(tie_on: &TieOn<N>) -> Self {
        Self {
            md: tie_on.md,
            nev: tie_on.nev,
            previous: None,
            index: 0,
        }
    }

    /// The next station's position; MD must strictly increase.
    pub fn step(&mut self, station: Station<N>) -> Result<SurveyPoint<N>, SurveyError> {
        let index = self.index;
        let Some(previous) = self.previous else {
            if station.md() != self.md {
                return Err(SurveyError::TieOnDepth);
            }
            self.previous = Some(station);
            self.index += 1;
            return Ok(SurveyPoint {
                station,
                nev: self.nev,
                dls_deg_per_30m: 0.0,
            });
        };
        let segment = Segment::new(previous, station).map_err(|e| match e {
            SurveyError::DepthNotIncreasing { .. } => SurveyError::DepthNotIncreasing { index },
            SurveyError::OppositeDirections { .. } => SurveyError::OppositeDirections { index },
            other => other,
        })?;
        self.nev += segment.increment();
        self.previous = Some(station);
        self.index += 1;
        Ok(SurveyPoint {
            station,
            nev: self.nev,
            dls_deg_per_30m: segment.dogleg_severity_deg_per_30m(),
        })
    }
}

/// The iterator of [`positions`].
#[derive(Clone, Debug)]
pub struct Positions<'a, N: NorthReference> {
    walker: Walker<N>,
    stations: &'a [Station<N>],
    index: usize,
    failed: bool,
}

impl<N: NorthReference> Iterator for Positions<'_, N> {
    type Item = Result<SurveyPoint<N>, SurveyError>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.failed || self.index >= self.stations.len() {
            return None;
        }
        let item = self.walker.step(self.stations[self.index]);
        self.failed = item.is_err();
        self.index += 1;
        Some(item)
    }
}
