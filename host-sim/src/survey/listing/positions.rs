//! The listing's rows: each station of a station file positioned by
//! minimum curvature from the tie-on (`mwd_core::survey`, true north; grid
//! azimuths turned by the convergence), with its dogleg severity and
//! vertical section, and a place for its NEV covariance.

use super::ellipse::Ellipse;
use crate::formats::station_csv::{InputStation, LengthUnit, StationFile};
use crate::survey::iscwsa::{self, Cov6};
use anyhow::{anyhow, bail, Context, Result};
use mwd_core::survey::{positions, GridConvergence, Station, SurveyPoint, TieOn, TrueNorth};
use nalgebra::Matrix3;

/// North reference of the file's azimuths.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AzimuthReference {
    True,
    /// Grid azimuths with this convergence (rad): true = grid + convergence.
    Grid(f64),
}

/// The tie-on, in the file's unit (north and east along true north).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TieOnInput {
    pub md: Option<f64>,
    pub tvd: f64,
    pub north: f64,
    pub east: f64,
    /// Its NEV position covariance in the file's unit squared (`Cov6`:
    /// nn, ee, vv, ne, nv, ev); `None`: exact.
    pub covariance: Option<Cov6>,
}

impl TieOnInput {
    /// The tie-on's position covariance in m^2, from the file's `unit`
    /// squared.
    pub fn covariance_m2(&self, unit: LengthUnit) -> Option<Cov6> {
        let k2 = unit.to_m().powi(2);
        self.covariance.map(|c| c.map(|v| v * k2))
    }

    /// Whether this places the stations as the surface default does: N 0,
    /// E 0, TVD 0 at the first station's MD (whatever its uncertainty).
    pub fn is_surface(&self) -> bool {
        self.md.is_none() && self.tvd == 0.0 && self.north == 0.0 && self.east == 0.0
    }
}

/// What the listings and the JSON say of the tie-on's uncertainty.
pub fn tie_on_note(tie_m2: Option<&Cov6>, unit: LengthUnit) -> String {
    let sigma = |v: f64| unit.from_m(v.max(0.0).sqrt());
    match tie_m2 {
        Some(c) => format!(
            "tie-on position 1-sigma N {:.2} {u}, E {:.2} {u}, TVD {:.2} {u} (the parent well's \
             where this well leaves it; in every station's covariance)",
            sigma(c[0]),
            sigma(c[1]),
            sigma(c[2]),
            u = unit.symbol()
        ),
        None => "tie-on taken as exact: no parent-well uncertainty given (the job's \
                 survey.tie_on.sigma or covariance, or --tie-on-sigma); the sigmas are this \
                 survey's alone"
            .into(),
    }
}

/// A station's covariance with the tie-on's added (m^2). The parent well's
/// error where the lateral leaves it moves every station of the lateral by
/// the same vector, so it adds whole to each station's own covariance
/// (fully correlated between stations); the lateral's own errors are
/// independent of the parent's survey.
pub fn plus_tie_on(cov: Cov6, tie_m2: Option<&Cov6>) -> Cov6 {
    match tie_m2 {
        Some(t) => std::array::from_fn(|j| cov[j] + t[j]),
        None => cov,
    }
}

/// A station with its position (metres, true north) and, with a model, its
/// covariance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Row {
    pub input: InputStation,
    pub md_m: f64,
    pub inc_deg: f64,
    /// True azimuth, deg.
    pub azi_deg: f64,
    pub tvd_m: f64,
    pub north_m: f64,
    pub east_m: f64,
    pub dls_deg_per_30m: f64,
    pub vsec_m: f64,
    /// NEV covariance (m^2) when an error model was run and is valid here.
    pub cov: Option<Cov6>,
}

impl Row {
    pub fn ellipse(&self) -> Option<Ellipse> {
        self.cov.as_ref().map(Ellipse::from_cov)
    }

    /// The station as the ISCWSA model takes it (radians).
    pub fn iscwsa_station(&self) -> iscwsa::Station {
        iscwsa::Station {
            md: self.md_m,
            inc: self.inc_deg.to_radians(),
            azi: self.azi_deg.to_radians(),
            tvd: self.tvd_m,
            toolface: self.input.toolface_deg.map(f64::to_radians),
        }
    }
}

/// A station of a file in `unit` as minimum curvature takes it: MD in
/// metres, angles in radians, azimuth from true north.
pub fn true_station(
    s: &InputStation,
    unit: LengthUnit,
    reference: AzimuthReference,
) -> Result<Station<TrueNorth>> {
    let azi = s.azi_deg.to_radians();
    let azi = match reference {
        AzimuthReference::True => azi,
        AzimuthReference::Grid(c) => GridConvergence::new(c)
            .map_err(|e| anyhow!("convergence: {e:?}"))?
            .true_azimuth(azi),
    };
    Station::<TrueNorth>::new(s.md * unit.to_m(), s.inc_deg.to_radians(), azi)
        .map_err(|e| anyhow!("station at MD {}: {e:?}", s.md))
}

/// The tie-on of a file in `unit` whose first station is at MD
/// `first_md` (the file's unit), in metres.
pub fn tie_on_m(tie: &TieOnInput, unit: LengthUnit, first_md: f64) -> Result<TieOn<TrueNorth>> {
    let k = unit.to_m();
    if let Some(md) = tie.md {
        if md != first_md {
            bail!(
                "the tie-on MD {md} is not the first station's MD {first_md}: the first station is the tie-on"
            );
        }
    }
    let tie_cov = tie
        .covariance_m2(unit)
        .map_or_else(Matrix3::zeros, |c| iscwsa::cov_matrix(&c));
    TieOn::<TrueNorth>::new(
        first_md * k,
        tie.tvd * k,
        tie.north * k,
        tie.east * k,
        tie_cov,
    )
    .map_err(|e| anyhow!("tie-on: {e:?}"))
}

/// A station's row: its position and dogleg severity from minimum
/// curvature, its vertical section along `direction` (rad); no covariance
/// yet.
pub fn row(input: &InputStation, p: &SurveyPoint<TrueNorth>, direction: f64) -> Row {
    Row {
        input: *input,
        md_m: p.station.md(),
        inc_deg: p.station.inclination().to_degrees(),
        azi_deg: p.station.azimuth().to_degrees(),
        tvd_m: p.tvd(),
        north_m: p.north(),
        east_m: p.east(),
        dls_deg_per_30m: p.dls_deg_per_30m,
        vsec_m: p.vertical_section(direction),
        cov: None,
    }
}

/// The azimuth (rad, in [0, 2 pi)) of a point from the origin of north
/// and east: the default vertical-section direction; 0 at the origin.
pub fn closure_azimuth(p: &SurveyPoint<TrueNorth>) -> f64 {
    let (n, e) = (p.north(), p.east());
    if n == 0.0 && e == 0.0 {
        0.0
    } else {
        e.atan2(n).rem_euclid(std::f64::consts::TAU)
    }
}

/// Positions by minimum curvature from the tie-on (true north), with the
/// vertical section (from the origin of north and east) along
/// `vsec_azimuth` (rad; `None`: the closure azimuth of the last station
/// from that origin).
pub fn compute(
    file: &StationFile,
    reference: AzimuthReference,
    tie: TieOnInput,
    vsec_azimuth: Option<f64>,
) -> Result<(Vec<Row>, f64)> {
    let first = file.stations.first().context("no stations")?;
    let tie_on = tie_on_m(&tie, file.unit, first.md)?;
    let stations = file
        .stations
        .iter()
        .map(|s| true_station(s, file.unit, reference))
        .collect::<Result<Vec<_>>>()?;
    let points = positions(&tie_on, &stations)
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| anyhow!("minimum curvature: {e:?}"))?;
    let last = points.last().context("no stations")?;
    let direction = vsec_azimuth.unwrap_or_else(|| closure_azimuth(last));
    let rows = points
        .iter()
        .zip(&file.stations)
        .map(|(p, input)| row(input, p, direction))
        .collect();
    Ok((rows, direction))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::formats::station_csv::read_stations;

    fn file(text: &str) -> StationFile {
        read_stations(text.as_bytes()).unwrap()
    }

    #[test]
    fn grid_azimuths_and_tie_on() {
        let f = file("md_m,inc_deg,azi_deg,toolface_deg,time_s\n100,90,0,10,1\n200,90,0,,2\n");
        assert_eq!(f.stations[0].toolface_deg, Some(10.0));
        assert_eq!(f.stations[1].toolface_deg, None);
        let tie = TieOnInput {
            md: Some(100.0),
            tvd: 50.0,
            north: 10.0,
            east: -5.0,
            covariance: None,
        };
        let grid = AzimuthReference::Grid(2f64.to_radians());
        let (rows, vsec) = compute(&f, grid, tie, None).unwrap();
        assert!((rows[0].north_m - 10.0).abs() < 1e-12);
        assert!((rows[0].tvd_m - 50.0).abs() < 1e-12);
        // grid north + 2 deg convergence = true azimuth 2 deg
        assert!((rows[1].azi_deg - 2.0).abs() < 1e-9);
        let c = 2f64.to_radians();
        assert!((rows[1].north_m - (10.0 + 100.0 * c.cos())).abs() < 1e-9);
        assert!((rows[1].east_m - (-5.0 + 100.0 * c.sin())).abs() < 1e-9);
        assert!((rows[1].tvd_m - 50.0).abs() < 1e-9);
        // default vertical section: closure of the last station
        let closure = rows[1]
            .east_m
            .atan2(rows[1].north_m)
            .rem_euclid(std::f64::consts::TAU);
        assert!((vsec - closure).abs() < 1e-12);
        assert!((rows[1].vsec_m - rows[1].north_m.hypot(rows[1].east_m)).abs() < 1e-9);
        // the tie-on MD must be the first station's
        let bad = TieOnInput {
            md: Some(0.0),
            ..tie
        };
        assert!(compute(&f, AzimuthReference::True, bad, None).is_err());
    }
}
