//! The continuous trajectory of a drilling run (`survey CAPTURE
//! --trajectory`): the 20 Hz solutions' attitude every few decimetres of
//! MD, positioned by minimum curvature from the survey's tie-on, with the
//! stations' covariance model ([`super::drilling`]).

use super::drilling::{covariance, with_tie_on, DrillingSurvey};
use super::{compute, AzimuthReference, InputStation, LengthUnit, Row, StationFile, TieOnInput};
use crate::formats::depth_log::DepthLog;
use crate::survey::iscwsa::probe_station::AngleSigma;
use crate::survey::iscwsa::{ErrorTerm, Site};
use anyhow::{bail, Result};
use mwd_core::protocol::frame::{nav_flags, nav_mode};
use mwd_core::protocol::NavSolution;

/// One point of the continuous trajectory.
#[derive(Clone, Copy, Debug)]
pub struct TrajectoryPoint {
    pub time_s: f64,
    /// 1-sigma of inclination and azimuth (rad; azimuth +inf undetermined).
    pub sigma_inc: f64,
    pub sigma_azi: f64,
    pub row: Row,
    pub azimuth_determined: bool,
    pub position_determined: bool,
}

/// The trajectory every `step_m` of MD from the survey's tie-on to the
/// deepest MD the solutions reach: at each MD the attitude of the first
/// navigation solution whose (log) MD reaches it (at 30 m/h the MD moves
/// 0.4 mm per 20 Hz sample), positioned by minimum curvature from the
/// tie-on, with the covariance model of the stations (module docs).
pub fn trajectory(
    solutions: impl IntoIterator<Item = NavSolution>,
    depth: &DepthLog,
    survey: &DrillingSurvey,
    tie: TieOnInput,
    terms: &[ErrorTerm],
    site: &Site,
    step_m: f64,
) -> Result<Vec<TrajectoryPoint>> {
    if !(step_m.is_finite() && step_m > 0.0) {
        bail!("the trajectory step must be a positive number of metres");
    }
    let Some(tie_row) = survey.rows.first() else {
        bail!("no tie-on station");
    };
    let start_time = tie_row.time_s;
    let mut points: Vec<(f64, f64, NavSolution)> = Vec::new();
    let mut next_md = tie_row.row.md_m + step_m;
    for s in solutions {
        let t = s.time_us as f64 * 1e-6;
        let usable = s.mode == nav_mode::NAVIGATING
            && s.flags & nav_flags::SOLUTION_INVALID == 0
            && s.attitude.iter().all(|a| a.is_finite())
            && s.attitude_std[1].is_finite();
        if t <= start_time || !usable {
            continue;
        }
        let Some(md) = depth.md_at(t) else { continue };
        let md = md + survey.md_offset_m;
        while md >= next_md {
            points.push((t, next_md, s));
            next_md += step_m;
        }
    }
    let tie_in = tie_row.row.input;
    let mut inputs = vec![tie_in];
    let mut sig = vec![[
        f64::from(tie_row.survey.angles_std[0]),
        f64::from(tie_row.survey.angles_std[1]),
    ]];
    let mut determined = vec![tie_row.azimuth_determined];
    for (t, md, s) in &points {
        let [_, pitch, heading] = s.attitude.map(f64::from);
        inputs.push(InputStation {
            md: *md,
            inc_deg: (std::f64::consts::FRAC_PI_2 + pitch).to_degrees(),
            azi_deg: heading.rem_euclid(std::f64::consts::TAU).to_degrees(),
            toolface_deg: Some(
                f64::from(s.attitude[0])
                    .rem_euclid(std::f64::consts::TAU)
                    .to_degrees(),
            ),
            time_s: Some(*t),
        });
        sig.push([f64::from(s.attitude_std[1]), f64::from(s.attitude_std[2])]);
        determined.push(s.attitude_std[2].is_finite());
    }
    let file = StationFile {
        unit: LengthUnit::Metre,
        stations: inputs,
    };
    let (rows, _) = compute(
        &file,
        AzimuthReference::True,
        TieOnInput { md: None, ..tie },
        None,
    )?;
    let sigmas: Vec<Option<AngleSigma>> = sig
        .iter()
        .zip(&determined)
        .map(|(s, &d)| {
            d.then_some(AngleSigma {
                inc: s[0],
                azi: s[1],
                corr_inc_azi: f64::NAN,
                azi_before: None,
                link: None,
            })
        })
        .collect();
    let mut covs = covariance(&rows, &sigmas, terms, site, None)?;
    with_tie_on(&mut covs, &tie);
    Ok(rows
        .into_iter()
        .enumerate()
        .map(|(k, mut row)| {
            row.cov = covs.get(k).map(|c| c.total);
            TrajectoryPoint {
                time_s: row.input.time_s.unwrap_or(f64::NAN),
                sigma_inc: sig[k][0],
                sigma_azi: sig[k][1],
                row,
                azimuth_determined: determined[k],
                position_determined: k < covs.len(),
            }
        })
        .collect())
}
