//! The lateral study's statistics per grade and well
//! ([`super`]): named fields, serialised as they are, so other
//! columns (covariance analysis) and plots can be added beside them.
//!
//! Conventions: an RMS, percentile or median over no cases is `None`
//! (undetermined), never 0. Azimuth statistics are over the stations the
//! probe flags determined; the undetermined ones are counted. The
//! horizontal 1-sigma a covariance predicts is sqrt(trace) of its NE block
//! (the RMS radial error it implies), compared with the RMS of the radial
//! errors; the 95 % ellipse holds a TD when its squared Mahalanobis
//! distance is <= -2 ln 0.05 = 5.991 (chi-square, 2 degrees of freedom).

use super::consistency::{azimuth_consistency, AzimuthConsistency};
use super::correlation::{azimuth_lag_correlations, LagCorrelation};
use super::stations::{station_rows, StationRow};
use crate::study::drilling_coverage::Fraction;
use crate::study::drilling_run::{failures, outcomes, RunOutcome, StationCheck};
use crate::study::stats::{percentile, rms, rms_and_median_sigma};
use crate::survey::listing::drilling::station_valid;
use crate::survey::listing::ellipse::scale_2d;
use mwd_core::protocol::frame::station_flags;
use serde::Serialize;
use std::collections::BTreeMap;

/// The MGWD paper's design requirement (`/work/shared/paper/mgwd.md`):
/// attitude error under 0.1 deg, position error under 1 m per 1000 m.
pub const ATTITUDE_LIMIT_DEG: f64 = 0.1;
pub const POSITION_LIMIT_M_PER_1000_M: f64 = 1.0;

/// TD statistics over the runs whose TD was checked.
#[derive(Clone, Debug, Default, Serialize)]
pub struct TdSummary {
    pub runs_checked: usize,
    pub rms_horizontal_error_m: Option<f64>,
    /// Nearest-rank 95th percentile of the radial error.
    pub p95_horizontal_error_m: Option<f64>,
    /// RMS over runs of sqrt(trace of the predicted NE covariance).
    pub predicted_1_sigma_m: Option<f64>,
    pub predicted_2_sigma_m: Option<f64>,
    pub inside_95_ellipse: Fraction,
    /// RMS over runs of the 1-sigma semi-major axis, and per 1000 m of
    /// lateral (MD from the tie-on to TD).
    pub semi_major_1_sigma_m: Option<f64>,
    pub semi_major_1_sigma_per_1000_m: Option<f64>,
    /// Without the survey method ([`TdCheck::without_method`]): each TD
    /// error less minimum curvature's own through the true angles, against
    /// the covariance less the XCLA/XCLH terms. The method's error is the
    /// same in every run of one plan, so a Monte Carlo cannot check its
    /// terms; this checks the rest.
    pub without_method: TdWithoutMethod,
    /// The method's own TD error (RMS over runs, m) and its terms'
    /// predicted 1-sigma (RMS of sqrt(trace)).
    pub method_rms_error_m: Option<f64>,
    pub method_predicted_1_sigma_m: Option<f64>,
    /// The runs whose method error lies inside the 95 % ellipse of the
    /// method's terms alone: each run drills its own hole (its tortuosity,
    /// docs/drilling-simulation.md), so this checks XCLA and XCLH.
    pub method_inside_95_ellipse: Fraction,
}

/// The TD statistics without the survey method: the sensors' and the
/// depth log's part ([`TdSummary::without_method`]).
#[derive(Clone, Debug, Default, Serialize)]
pub struct TdWithoutMethod {
    pub rms_horizontal_error_m: Option<f64>,
    pub predicted_1_sigma_m: Option<f64>,
    pub inside_95_ellipse: Fraction,
}

/// Whether the requirement is met; `None`: undetermined (no cases).
#[derive(Clone, Debug, Default, Serialize)]
pub struct Requirement {
    /// The larger of the station inclination and azimuth RMS errors.
    pub attitude_error_deg: Option<f64>,
    /// Met when it is under the limit and no station's azimuth is
    /// undetermined or invalid (a withheld azimuth does not meet it).
    pub attitude_met: Option<bool>,
    pub rms_td_error_per_1000_m: Option<f64>,
    pub p95_td_error_per_1000_m: Option<f64>,
    /// Met when the RMS per 1000 m is under the limit and every run's TD
    /// was positioned (a run without a TD position: not met).
    pub position_met: Option<bool>,
}

/// Error growth along MD: the stations with one number across the runs.
#[derive(Clone, Debug, Default, Serialize)]
pub struct AlongMd {
    /// 1 = the window's station.
    pub station: u16,
    /// Mean true MD of the station over the runs (m).
    pub truth_md_m: f64,
    /// Stations with this number (valid).
    pub stations: usize,
    pub azimuth_undetermined: usize,
    pub rms_azimuth_error_deg: Option<f64>,
    pub median_azimuth_sigma_deg: Option<f64>,
    pub azimuth_within_2_sigma: Fraction,
    pub rms_inclination_error_deg: Option<f64>,
    pub median_inclination_sigma_deg: Option<f64>,
    pub inclination_within_2_sigma: Fraction,
    /// Stations with a determined survey position.
    pub positioned: usize,
    pub rms_horizontal_error_m: Option<f64>,
    pub median_horizontal_sigma_m: Option<f64>,
    /// This station's azimuth correction against the variance it removed,
    /// and the drilling stretch that ended at it against its growth, RMS
    /// over the runs (`super::consistency`; 1 when consistent).
    pub station_correction_ratio: Option<f64>,
    pub drilling_growth_ratio: Option<f64>,
    /// The azimuth error over its sigma at this station's start (after
    /// the drilling), RMS over the runs.
    pub start_error_ratio: Option<f64>,
}

/// One grade on one well.
#[derive(Clone, Debug, Default, Serialize)]
pub struct GradeWellSummary {
    pub grade: String,
    pub well: String,
    pub lateral_length_m: f64,
    pub runs: usize,
    pub failed_runs: Vec<String>,
    pub stations: usize,
    /// Flagged invalid (not counted anywhere else).
    pub invalid_stations: usize,
    pub azimuth_undetermined_stations: usize,
    /// Of those, the ones the probe flagged heading lost (station bit 8:
    /// lost since the tie-in, only a new one brings it back); the others
    /// were never found (before the tie-in).
    pub azimuth_lost_stations: usize,
    /// Ended because the gyros saw the tool turn while the still detector
    /// saw none (`station_flags::MOTION_SEEN`: a slide too smooth for the
    /// detector); counted with the others too.
    pub motion_seen_stations: usize,
    /// How far the heading holds: the measured depth (true MD, m) up to
    /// which at least 95 % of the runs kept every station valid with a
    /// determined azimuth; `None` when more than 5 % of the runs had none
    /// at their first station (or there were no runs).
    pub heading_held_to_md_m: Option<f64>,
    /// Runs whose every station had a determined azimuth.
    pub heading_held_runs: usize,
    pub rms_station_inclination_deg: Option<f64>,
    pub rms_station_azimuth_deg: Option<f64>,
    pub azimuth_within_2_sigma: Fraction,
    pub inclination_within_2_sigma: Fraction,
    pub td: TdSummary,
    /// The stations' azimuth errors' correlation by distance, Monte Carlo
    /// against the survey's chain (`super::correlation`).
    pub azimuth_correlation: Vec<LagCorrelation>,
    /// The azimuth sigma's consistency through the stations and the
    /// drilling between them (`super::consistency`).
    pub azimuth_consistency: AzimuthConsistency,
    /// Runs without a TD check, by reason.
    pub td_unchecked: Vec<(String, usize)>,
    pub requirement: Requirement,
    pub along_md: Vec<AlongMd>,
    /// Simulated samples (each one navigator epoch).
    pub samples: usize,
    /// Sum of the runs' wall times on their threads (s).
    pub run_wall_s: f64,
    /// Sum of their threads' CPU times (s); `None` when the system does
    /// not tell it for every run.
    pub run_cpu_s: Option<f64>,
    /// Navigator epochs (simulation included) per second of one core's
    /// CPU time; `None` without CPU times.
    pub epochs_per_core_second: Option<f64>,
    /// The same per second of wall time per thread (lower on a machine
    /// shared with other work).
    pub epochs_per_thread_wall_second: Option<f64>,
    /// Every run's stations (`--stations-csv`; not in the JSON).
    #[serde(skip)]
    pub station_rows: Vec<StationRow>,
}

/// One station number's values while summarising.
#[derive(Default)]
struct Tally {
    md: Vec<f64>,
    undetermined: usize,
    /// (|error|, sigma) of determined azimuths, deg.
    azimuth: Vec<(f64, f64)>,
    /// (|error|, sigma) of the inclinations, deg.
    inclination: Vec<(f64, f64)>,
    /// (radial error, sqrt trace), m.
    position: Vec<(f64, f64)>,
}

impl Tally {
    fn along(&self, station: u16) -> AlongMd {
        let within_2_sigma = |pairs: &[(f64, f64)]| {
            let inside = pairs.iter().filter(|(e, s)| *e <= 2.0 * s).count();
            Fraction::of(inside, pairs.len())
        };
        let (rms_azimuth_error_deg, median_azimuth_sigma_deg) = rms_and_median_sigma(&self.azimuth);
        let (rms_inclination_error_deg, median_inclination_sigma_deg) =
            rms_and_median_sigma(&self.inclination);
        let (rms_horizontal_error_m, median_horizontal_sigma_m) =
            rms_and_median_sigma(&self.position);
        AlongMd {
            station,
            truth_md_m: self.md.iter().sum::<f64>() / self.md.len().max(1) as f64,
            stations: self.md.len(),
            azimuth_undetermined: self.undetermined,
            rms_azimuth_error_deg,
            median_azimuth_sigma_deg,
            azimuth_within_2_sigma: within_2_sigma(&self.azimuth),
            rms_inclination_error_deg,
            median_inclination_sigma_deg,
            inclination_within_2_sigma: within_2_sigma(&self.inclination),
            positioned: self.position.len(),
            rms_horizontal_error_m,
            median_horizontal_sigma_m,
            station_correction_ratio: None,
            drilling_growth_ratio: None,
            start_error_ratio: None,
        }
    }
}

/// The summary of one grade's runs on one well (seed order).
pub fn summarise(
    grade: &str,
    well: &str,
    lateral_length_m: f64,
    results: &[(u64, Result<RunOutcome, String>)],
) -> GradeWellSummary {
    let mut s = GradeWellSummary {
        grade: grade.to_string(),
        well: well.to_string(),
        lateral_length_m,
        runs: results.len(),
        ..GradeWellSummary::default()
    };
    let (mut inc, mut azi) = (Vec::new(), Vec::new());
    let (mut azi_inside, mut inc_inside) = (0, 0);
    let (mut td_err, mut td_sigma, mut td_major) = (Vec::new(), Vec::new(), Vec::new());
    let mut td_inside = 0;
    // the split: (errors, sigmas, inside) without the method; the method's
    let (mut sensor_err, mut sensor_sigma, mut sensor_inside) = (Vec::new(), Vec::new(), 0);
    let (mut method_err, mut method_sigma, mut method_inside) = (Vec::new(), Vec::new(), 0);
    let k2 = scale_2d(0.95).powi(2);
    let mut unchecked: BTreeMap<String, usize> = BTreeMap::new();
    let mut by_station: BTreeMap<u16, Tally> = BTreeMap::new();
    let mut cpu = Some(0.0);
    let mut held_to: Vec<Option<f64>> = Vec::new();
    s.failed_runs = failures(results);
    for o in outcomes(results) {
        let (held, whole) = heading_held_to(&o.stations);
        held_to.push(held);
        s.heading_held_runs += usize::from(whole);
        s.samples += o.samples;
        s.run_wall_s += o.elapsed_s;
        cpu = cpu.zip(o.cpu_s).map(|(a, b)| a + b);
        for st in &o.stations {
            s.stations += 1;
            if st.survey.flags & station_flags::MOTION_SEEN != 0 {
                s.motion_seen_stations += 1;
            }
            let sd = st.survey.angles_std.map(f64::from);
            if !counted(st) {
                s.invalid_stations += 1;
                continue;
            }
            inc.push(st.error[0].to_degrees());
            inc_inside += usize::from(st.error[0].abs() <= 2.0 * sd[0]);
            let tally = by_station.entry(st.survey.station).or_default();
            tally.md.push(st.truth_md);
            tally
                .inclination
                .push((st.error[0].abs().to_degrees(), sd[0].to_degrees()));
            if !azimuth_determined(st) {
                s.azimuth_undetermined_stations += 1;
                if st.survey.flags & station_flags::HEADING_LOST != 0 {
                    s.azimuth_lost_stations += 1;
                }
                tally.undetermined += 1;
            } else {
                let e = st.error[1].abs();
                azi.push(e.to_degrees());
                azi_inside += usize::from(e <= 2.0 * sd[1]);
                tally.azimuth.push((e.to_degrees(), sd[1].to_degrees()));
            }
            if let Some(p) = &st.position {
                tally
                    .position
                    .push((p.error_horizontal(), p.sigma_horizontal()));
            }
        }
        match (&o.td, &o.td_note) {
            (Some(t), _) => {
                let p = t.position();
                td_err.push(p.error_horizontal());
                td_sigma.push(p.sigma_horizontal());
                td_major.push(p.semi_major());
                td_inside += usize::from(t.d2 <= k2);
                if let Some(m) = o.method_td_error_ne {
                    let rest = t.without_method(m);
                    sensor_err.push(rest.error_horizontal());
                    sensor_sigma.push(rest.sigma_horizontal());
                    sensor_inside += usize::from(rest.mahalanobis2().is_some_and(|d| d <= k2));
                    let own = t.method_only(m);
                    method_err.push(own.error_horizontal());
                    method_sigma.push(own.sigma_horizontal());
                    method_inside += usize::from(own.mahalanobis2().is_some_and(|d| d <= k2));
                }
            }
            (None, _) => *unchecked.entry(o.td_unchecked_kind()).or_default() += 1,
        }
    }
    s.heading_held_to_md_m = held_by_95_percent(held_to);
    s.rms_station_inclination_deg = rms(&inc);
    s.rms_station_azimuth_deg = rms(&azi);
    s.azimuth_within_2_sigma = Fraction::of(azi_inside, azi.len());
    s.inclination_within_2_sigma = Fraction::of(inc_inside, inc.len());
    let per_1000 = |v: Option<f64>| v.map(|v| v * 1000.0 / lateral_length_m);
    let predicted = rms(&td_sigma);
    let major = rms(&td_major);
    s.td = TdSummary {
        runs_checked: td_err.len(),
        rms_horizontal_error_m: rms(&td_err),
        p95_horizontal_error_m: percentile(&td_err, 0.95),
        predicted_1_sigma_m: predicted,
        predicted_2_sigma_m: predicted.map(|p| 2.0 * p),
        inside_95_ellipse: Fraction::of(td_inside, td_err.len()),
        semi_major_1_sigma_m: major,
        semi_major_1_sigma_per_1000_m: per_1000(major),
        without_method: TdWithoutMethod {
            rms_horizontal_error_m: rms(&sensor_err),
            predicted_1_sigma_m: rms(&sensor_sigma),
            inside_95_ellipse: Fraction::of(sensor_inside, sensor_err.len()),
        },
        method_rms_error_m: rms(&method_err),
        method_predicted_1_sigma_m: rms(&method_sigma),
        method_inside_95_ellipse: Fraction::of(method_inside, method_err.len()),
    };
    s.azimuth_correlation = azimuth_lag_correlations(outcomes(results));
    let by_number;
    (s.azimuth_consistency, by_number) = azimuth_consistency(outcomes(results));
    s.td_unchecked = unchecked.into_iter().collect();
    s.along_md = by_station
        .iter()
        .map(|(n, t)| {
            let consistency = by_number.get(n);
            AlongMd {
                station_correction_ratio: consistency.and_then(|c| c.station_correction_ratio),
                drilling_growth_ratio: consistency.and_then(|c| c.drilling_growth_ratio),
                start_error_ratio: consistency.and_then(|c| c.start_error_ratio),
                ..t.along(*n)
            }
        })
        .collect();
    let ok = s.runs > s.failed_runs.len();
    s.run_cpu_s = cpu.filter(|_| ok);
    s.epochs_per_core_second = s
        .run_cpu_s
        .filter(|c| *c > 0.0)
        .map(|c| s.samples as f64 / c);
    s.epochs_per_thread_wall_second = (s.run_wall_s > 0.0).then(|| s.samples as f64 / s.run_wall_s);
    s.requirement = requirement(&s);
    s.station_rows = station_rows(results);
    s
}

/// How far one run's heading held: the true MD of the last station of the
/// unbroken row of valid stations with a determined azimuth from its
/// first (`None`: not even the first), and whether that row is all of
/// them.
fn heading_held_to(stations: &[StationCheck]) -> (Option<f64>, bool) {
    let held = |st: &&StationCheck| counted(st) && azimuth_determined(st);
    let row: Vec<_> = stations.iter().take_while(held).collect();
    (
        row.last().map(|st| st.truth_md),
        row.len() == stations.len(),
    )
}

/// A station the summary counts: valid, with an inclination sigma (the
/// others are counted invalid).
fn counted(st: &StationCheck) -> bool {
    station_valid(&st.survey) && st.survey.angles_std[0].is_finite()
}

/// A counted station's azimuth is determined: not flagged undetermined,
/// its sigma finite.
fn azimuth_determined(st: &StationCheck) -> bool {
    st.survey.flags & station_flags::AZIMUTH_UNDETERMINED == 0
        && st.survey.angles_std[1].is_finite()
}

/// The depth at least 95 % of the runs held their heading to: the k-th
/// smallest of the runs' depths, k = floor(0.05 n) (so n - k >= 0.95 n
/// runs reached it); `None` (not held at the first station) sorts first.
fn held_by_95_percent(mut held_to: Vec<Option<f64>>) -> Option<f64> {
    held_to.sort_by(|a, b| match (a, b) {
        (Some(a), Some(b)) => a.total_cmp(b),
        _ => a.is_some().cmp(&b.is_some()),
    });
    let k = held_to.len() / 20;
    held_to.get(k).copied().flatten()
}

fn requirement(s: &GradeWellSummary) -> Requirement {
    let attitude = match (s.rms_station_inclination_deg, s.rms_station_azimuth_deg) {
        (Some(i), Some(a)) => Some(i.max(a)),
        _ => None,
    };
    let withheld = s.azimuth_undetermined_stations + s.invalid_stations > 0;
    let attitude_met = if s.stations == 0 {
        None
    } else if withheld {
        Some(false)
    } else {
        attitude.map(|a| a < ATTITUDE_LIMIT_DEG)
    };
    let ok_runs = s.runs - s.failed_runs.len();
    let per_1000 = |v: Option<f64>| v.map(|v| v * 1000.0 / s.lateral_length_m);
    let rms_per = per_1000(s.td.rms_horizontal_error_m);
    // a TD withheld (undetermined) or a failed run does not meet it, as a
    // withheld azimuth does not meet the attitude requirement
    let position_met = if ok_runs == 0 {
        None
    } else if s.td.runs_checked < ok_runs || ok_runs < s.runs {
        Some(false)
    } else {
        rms_per.map(|r| r < POSITION_LIMIT_M_PER_1000_M)
    };
    Requirement {
        attitude_error_deg: attitude,
        attitude_met,
        rms_td_error_per_1000_m: rms_per,
        p95_td_error_per_1000_m: per_1000(s.td.p95_horizontal_error_m),
        position_met,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::study::drilling_run::{PositionCheck, TdCheck};
    use mwd_core::protocol::StationSurvey;

    fn station(number: u16, azimuth_error_deg: f64, sigma_deg: f32) -> StationCheck {
        StationCheck {
            survey: StationSurvey {
                station: number,
                angles_std: [0.001, sigma_deg.to_radians(), 0.001],
                ..StationSurvey::default()
            },
            error: [0.0005, azimuth_error_deg.to_radians(), 0.0],
            truth_md: 3000.0 + f64::from(number) * 28.0,
            azimuth_error_before: None,
            azimuth_sigma_before: None,
            link: None,
            position: Some(PositionCheck {
                error_ne: [3.0, 4.0],
                cov_ne: [9.0, 16.0, 0.0],
            }),
        }
    }

    fn outcome(seed: u64, error_ne: [f64; 2], d2: f64) -> RunOutcome {
        RunOutcome {
            seed,
            stations: vec![station(1, 0.05, 0.5), station(2, 2.0, 0.5)],
            td: Some(TdCheck {
                error_ne,
                d2,
                cov_ne: [4.0, 1.0, 0.0],
                method_cov_ne: [0.0; 3],
            }),
            td_note: None,
            method_td_error_ne: None,
            samples: 1000,
            elapsed_s: 0.5,
            cpu_s: Some(0.25),
            uncalibrated: false,
        }
    }

    #[test]
    fn statistics_of_known_runs() {
        let results = vec![
            (1, Ok(outcome(1, [3.0, 4.0], 1.0))),
            (2, Ok(outcome(2, [0.0, 1.0], 7.0))),
            (3, Err("seed 3: broken".to_string())),
        ];
        let s = summarise("g", "w", 100.0, &results);
        assert_eq!((s.runs, s.failed_runs.len(), s.stations), (3, 1, 4));
        // azimuth errors 0.05, 2, 0.05, 2 deg; sigma 0.5: 2 of 4 within 2 sigma
        assert_eq!(
            (
                s.azimuth_within_2_sigma.inside,
                s.azimuth_within_2_sigma.total
            ),
            (2, 4)
        );
        let expected = ((0.05f64.powi(2) + 4.0) / 2.0).sqrt();
        assert!((s.rms_station_azimuth_deg.unwrap() - expected).abs() < 1e-9);
        // TD radial errors 5 and 1 m: RMS sqrt(13), p95 5, predicted sqrt(5)
        assert!((s.td.rms_horizontal_error_m.unwrap() - 13f64.sqrt()).abs() < 1e-12);
        assert_eq!(s.td.p95_horizontal_error_m, Some(5.0));
        assert!((s.td.predicted_1_sigma_m.unwrap() - 5f64.sqrt()).abs() < 1e-12);
        assert_eq!(s.td.semi_major_1_sigma_m, Some(2.0));
        assert_eq!(s.td.semi_major_1_sigma_per_1000_m, Some(20.0));
        assert_eq!(
            (s.td.inside_95_ellipse.inside, s.td.inside_95_ellipse.total),
            (1, 2)
        );
        assert_eq!(s.along_md.len(), 2);
        assert_eq!(s.along_md[1].station, 2);
        assert_eq!(s.along_md[1].rms_horizontal_error_m, Some(5.0));
        assert_eq!(s.along_md[1].median_horizontal_sigma_m, Some(5.0));
        assert_eq!(s.epochs_per_core_second, Some(4000.0));
        assert_eq!(s.epochs_per_thread_wall_second, Some(2000.0));
        // 2 deg of azimuth and 36 m per 1000 m: neither met; a failed run
        // leaves the position requirement unmet whatever the figures
        assert_eq!(s.requirement.attitude_met, Some(false));
        assert_eq!(s.requirement.position_met, Some(false));
    }

    #[test]
    fn undetermined_azimuths_are_counted_and_the_lost_ones_told_apart() {
        let mut run = outcome(1, [3.0, 4.0], 1.0);
        let mut never_found = station(3, 0.0, 0.5);
        never_found.survey.flags = station_flags::AZIMUTH_UNDETERMINED;
        let mut lost = station(4, 0.0, 0.5);
        lost.survey.flags = station_flags::AZIMUTH_UNDETERMINED | station_flags::HEADING_LOST;
        let mut lost_by_sigma = station(5, 0.0, f32::INFINITY);
        lost_by_sigma.survey.flags = station_flags::HEADING_LOST;
        run.stations.extend([never_found, lost, lost_by_sigma]);
        let s = summarise("g", "w", 100.0, &[(1, Ok(run))]);
        assert_eq!(s.stations, 5);
        assert_eq!(
            (s.azimuth_undetermined_stations, s.azimuth_lost_stations),
            (3, 2)
        );
        assert_eq!(s.azimuth_within_2_sigma.total, 2, "the determined ones");
    }

    #[test]
    fn the_methods_own_error_is_checked_against_its_terms_ellipse() {
        // the method's terms 1 m^2 north and east: 0.5 m north is inside
        // (d2 0.25), 3 m north outside (d2 9 > 5.991)
        let run = |seed, north| {
            let mut o = outcome(seed, [0.0, 0.0], 0.1);
            o.method_td_error_ne = Some([north, 0.0]);
            if let Some(t) = o.td.as_mut() {
                t.method_cov_ne = [1.0, 1.0, 0.0];
            }
            (seed, Ok(o))
        };
        let s = summarise("g", "w", 100.0, &[run(1, 0.5), run(2, 3.0)]);
        let f = &s.td.method_inside_95_ellipse;
        assert_eq!((f.inside, f.total), (1, 2));
    }

    #[test]
    fn the_method_split_takes_the_methods_error_and_terms_out() {
        let mut o = outcome(1, [3.0, 4.0], 1.0);
        // the method's own error 3 m north, its terms 1 m^2 north
        o.method_td_error_ne = Some([3.0, 0.0]);
        if let Some(t) = o.td.as_mut() {
            t.method_cov_ne = [1.0, 0.0, 0.0];
        }
        let mut p = outcome(2, [0.0, 0.5], 0.1);
        p.method_td_error_ne = Some([0.0, 0.0]);
        let s = summarise("g", "w", 100.0, &[(1, Ok(o)), (2, Ok(p))]);
        let w = &s.td.without_method;
        // run 1: 4 m east against 1 m^2 east: d2 = 16, outside; run 2:
        // 0.5 m against 1 m^2 (its covariance whole): inside
        assert!((w.rms_horizontal_error_m.unwrap() - (16.25f64 / 2.0).sqrt()).abs() < 1e-12);
        assert!((w.predicted_1_sigma_m.unwrap() - ((4.0f64 + 5.0) / 2.0).sqrt()).abs() < 1e-12);
        assert_eq!(
            (w.inside_95_ellipse.inside, w.inside_95_ellipse.total),
            (1, 2)
        );
        assert!((s.td.method_rms_error_m.unwrap() - (9.0f64 / 2.0).sqrt()).abs() < 1e-12);
        assert!((s.td.method_predicted_1_sigma_m.unwrap() - 0.5f64.sqrt()).abs() < 1e-12);
        // a run without the method's figure is left out of the split only
        let mut q = outcome(3, [0.0, 0.5], 0.1);
        q.method_td_error_ne = None;
        let s = summarise("g", "w", 100.0, &[(3, Ok(q))]);
        assert_eq!(s.td.runs_checked, 1);
        assert_eq!(s.td.without_method.inside_95_ellipse.total, 0);
        assert_eq!(s.td.without_method.rms_horizontal_error_m, None);
    }

    #[test]
    fn a_withheld_td_does_not_meet_the_position_requirement() {
        let mut o = outcome(1, [0.0, 0.01], 0.1);
        o.td = None;
        o.td_note = Some("TD position undetermined".into());
        let s = summarise("g", "w", 1000.0, &[(1, Ok(o))]);
        assert_eq!(s.td.rms_horizontal_error_m, None);
        assert_eq!(
            s.td_unchecked,
            [("TD position undetermined".to_string(), 1)]
        );
        assert_eq!(s.requirement.position_met, Some(false));
        // and a clean one under the limit meets it
        let s = summarise("g", "w", 1000.0, &[(1, Ok(outcome(1, [0.3, 0.4], 0.1)))]);
        assert_eq!(s.requirement.position_met, Some(true));
    }

    #[test]
    fn no_cases_are_undetermined_never_zero() {
        let s = summarise("g", "w", 100.0, &[(1, Err("seed 1: x".into()))]);
        assert_eq!(s.rms_station_azimuth_deg, None);
        assert_eq!(s.td.rms_horizontal_error_m, None);
        assert_eq!(s.td.inside_95_ellipse.fraction, None);
        assert_eq!(s.requirement.attitude_met, None);
        assert_eq!(s.requirement.position_met, None);
        assert_eq!(s.epochs_per_core_second, None);
    }

    #[test]
    fn the_heading_holds_to_the_depth_95_percent_of_the_runs_reach() {
        // station 3 undetermined: the row ends at station 2
        let mut stations: Vec<StationCheck> = (1..=4).map(|n| station(n, 0.1, 0.5)).collect();
        assert_eq!(heading_held_to(&stations), (Some(3112.0), true));
        stations[2].survey.flags |= station_flags::AZIMUTH_UNDETERMINED;
        assert_eq!(heading_held_to(&stations), (Some(3056.0), false));
        stations[0].survey.angles_std[1] = f32::INFINITY;
        assert_eq!(heading_held_to(&stations), (None, false));
        // 20 runs: one short of TD still leaves 95 % at TD; two do not
        let mut runs = vec![Some(4000.0); 19];
        runs.push(Some(3100.0));
        assert_eq!(held_by_95_percent(runs.clone()), Some(4000.0));
        runs[0] = Some(3500.0);
        assert_eq!(held_by_95_percent(runs.clone()), Some(3500.0));
        // a run that never had it counts as the shortest
        runs[0] = None;
        runs[1] = None;
        assert_eq!(held_by_95_percent(runs), None);
        assert_eq!(held_by_95_percent(Vec::new()), None);
    }
}
