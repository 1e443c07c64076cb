//! `host-sim study drilling-coverage`: N seeded runs of a simulated
//! lateral ([`super::drilling_run`]) on all cores, and whether the probe's
//! printed sigmas cover its errors, against the acceptance bands of
//! docs/drilling-survey.md: station azimuths within 2 sigma where
//! determined (>= 93 %), inclination and toolface within 2 sigma
//! (95 +- 3 %), TD inside the predicted 95 % horizontal ellipse
//! (95 +- 3 % of runs).

use super::drilling_run::{failures, outcomes, run, RunConfig, RunOutcome};
use super::stats::{rms, rms_and_median_sigma};
use super::{Interruption, StudyRuns};
use crate::survey::listing::drilling::{station_valid, UNCALIBRATED_NOTE};
use crate::survey::listing::ellipse::scale_2d;
use mwd_core::protocol::frame::station_flags;
use serde::Serialize;

/// A fraction and its binomial standard error.
#[derive(Clone, Copy, Debug, Default, Serialize, PartialEq)]
pub struct Fraction {
    pub inside: usize,
    pub total: usize,
    /// `None` with no cases: undetermined, never 0.
    pub fraction: Option<f64>,
    pub standard_error: Option<f64>,
}

impl Fraction {
    pub(crate) fn of(inside: usize, total: usize) -> Self {
        let p = (total > 0).then(|| inside as f64 / total as f64);
        // The binomial (Wald) standard error sqrt(p (1 - p) / n) says 0 at
        // none or all of n, which no finite count shows: not valid there.
        let valid = inside > 0 && inside < total;
        Self {
            inside,
            total,
            fraction: p,
            standard_error: p
                .filter(|_| valid)
                .map(|p| (p * (1.0 - p) / total as f64).sqrt()),
        }
    }

    /// "95.0 +- 1.5 % (190/200)"; at none or all of the cases "100.0 %
    /// (9/9)", without a standard error (not valid there); `None` without
    /// cases.
    pub fn text(&self) -> Option<String> {
        let p = 100.0 * self.fraction?;
        let (k, n) = (self.inside, self.total);
        Some(match self.standard_error {
            Some(se) => format!("{p:.1} +- {:.1} % ({k}/{n})", 100.0 * se),
            None => format!("{p:.1} % ({k}/{n})"),
        })
    }
}

/// The study's results.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Summary {
    /// The runs done (all of them unless `interrupted`).
    pub runs: usize,
    /// Set when the study was stopped (Ctrl-C) before its last run.
    pub interrupted: Option<Interruption>,
    pub failed_runs: Vec<String>,
    pub stations: usize,
    pub invalid_stations: usize,
    pub undetermined_azimuth_stations: usize,
    pub azimuth_within_2_sigma: Fraction,
    pub inclination_within_2_sigma: Fraction,
    pub toolface_within_2_sigma: Fraction,
    /// Runs whose TD lies inside the predicted 95 % horizontal ellipse.
    pub td_inside_95_ellipse: Fraction,
    /// Runs without a TD check, by reason.
    pub td_unchecked: Vec<(String, usize)>,
    /// RMS errors over the counted stations (deg) and TD (m); `None`
    /// without cases.
    pub rms_inclination_deg: Option<f64>,
    pub rms_azimuth_deg: Option<f64>,
    pub rms_toolface_deg: Option<f64>,
    pub rms_td_horizontal_m: Option<f64>,
    pub samples: usize,
    pub wall_s: f64,
    /// The same counts by station number (1 = the window's): where along
    /// the well the bounds hold or fail.
    pub by_station: Vec<StationCoverage>,
    /// Stations flagged "uncalibrated" (the runs' probe without the
    /// calibration of its parts, `RunOutcome::uncalibrated`): their sigmas
    /// do not cover the parts' uncalibrated errors. Left out at 0.
    #[serde(skip_serializing_if = "is_zero")]
    pub uncalibrated_stations: usize,
}

/// Serde's test for the counts left out at 0.
fn is_zero(n: &usize) -> bool {
    *n == 0
}

/// Coverage of the stations with one station number across the runs.
#[derive(Clone, Debug, Default, Serialize)]
pub struct StationCoverage {
    pub station: u16,
    pub inclination_within_2_sigma: Fraction,
    pub azimuth_within_2_sigma: Fraction,
    pub toolface_within_2_sigma: Fraction,
    pub azimuth_undetermined: usize,
    pub rms_toolface_deg: Option<f64>,
    /// Mean toolface error (deg): a bias the sigmas cannot cover.
    pub mean_toolface_error_deg: Option<f64>,
    pub median_toolface_sigma_deg: Option<f64>,
    /// The same of the determined azimuths.
    pub rms_azimuth_deg: Option<f64>,
    pub median_azimuth_sigma_deg: Option<f64>,
    /// Of this station's surveys, those flagged "uncalibrated" (left out
    /// at 0).
    #[serde(skip_serializing_if = "is_zero")]
    pub uncalibrated: usize,
}

/// Runs the seeds of `runs` (on its threads);
/// `progress` after each run. Setting `stop` (Ctrl-C) ends it
/// early: the runs under way finish, and the summary is over the runs
/// done ([`Summary::interrupted`]).
pub fn study(config: &RunConfig, runs: &StudyRuns) -> Summary {
    let started = std::time::Instant::now();
    let results = runs.run(|seed| run(config, seed));
    summary_of(&results, runs.runs, started.elapsed().as_secs_f64())
}

/// The summary of `results` (the runs done, in seed order) of a study of
/// `runs` runs that took `wall_s`: one process's, or its shards' merged
/// (`super::coverage_shard`).
pub fn summary_of(
    results: &[(u64, Result<RunOutcome, String>)],
    runs: usize,
    wall_s: f64,
) -> Summary {
    let mut summary = summarise(results);
    summary.interrupted = Interruption::of(results.len(), runs);
    summary.wall_s = wall_s;
    summary
}

fn summarise(results: &[(u64, Result<RunOutcome, String>)]) -> Summary {
    let mut s = Summary {
        runs: results.len(),
        ..Summary::default()
    };
    let (mut inc, mut azi, mut tf, mut td) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let mut inside = [0usize; 4];
    let mut totals = [0usize; 4];
    let k2 = scale_2d(0.95).powi(2);
    let mut unchecked: std::collections::BTreeMap<String, usize> = Default::default();
    let mut by_station: std::collections::BTreeMap<u16, StationTally> = Default::default();
    s.failed_runs = failures(results);
    for o in outcomes(results) {
        s.samples += o.samples;
        for st in &o.stations {
            s.stations += 1;
            s.uncalibrated_stations += usize::from(o.uncalibrated);
            let sd = st.survey.angles_std.map(f64::from);
            if !station_valid(&st.survey) || !sd[0].is_finite() || !sd[2].is_finite() {
                s.invalid_stations += 1;
                continue;
            }
            let number = st.survey.station;
            let slot = by_station.entry(number).or_default();
            slot.uncalibrated += usize::from(o.uncalibrated);
            let mut count = |i: usize, err: f64, sigma: f64, list: &mut Vec<f64>| {
                let within = usize::from(err.abs() <= 2.0 * sigma);
                totals[i] += 1;
                inside[i] += within;
                slot.inside[i] += within;
                slot.totals[i] += 1;
                list.push(err.to_degrees());
            };
            count(0, st.error[0], sd[0], &mut inc);
            count(2, st.error[2], sd[2], &mut tf);
            slot.toolface
                .push((st.error[2].to_degrees(), sd[2].to_degrees()));
            if st.survey.flags & station_flags::AZIMUTH_UNDETERMINED != 0 || !sd[1].is_finite() {
                s.undetermined_azimuth_stations += 1;
                slot.undetermined += 1;
            } else {
                count(1, st.error[1], sd[1], &mut azi);
                slot.azimuth
                    .push((st.error[1].to_degrees(), sd[1].to_degrees()));
            }
        }
        match (&o.td, &o.td_note) {
            (Some(t), _) => {
                totals[3] += 1;
                inside[3] += usize::from(t.d2 <= k2);
                td.push(t.error_ne[0].hypot(t.error_ne[1]));
            }
            (None, _) => *unchecked.entry(o.td_unchecked_kind()).or_default() += 1,
        }
    }
    s.inclination_within_2_sigma = Fraction::of(inside[0], totals[0]);
    s.azimuth_within_2_sigma = Fraction::of(inside[1], totals[1]);
    s.toolface_within_2_sigma = Fraction::of(inside[2], totals[2]);
    s.td_inside_95_ellipse = Fraction::of(inside[3], totals[3]);
    s.td_unchecked = unchecked.into_iter().collect();
    s.rms_inclination_deg = rms(&inc);
    s.rms_azimuth_deg = rms(&azi);
    s.rms_toolface_deg = rms(&tf);
    s.rms_td_horizontal_m = rms(&td);
    s.by_station = by_station
        .into_iter()
        .map(|(station, t)| t.coverage(station))
        .collect();
    s
}

/// One station number's counts while summarising.
#[derive(Default)]
struct StationTally {
    inside: [usize; 3],
    totals: [usize; 3],
    undetermined: usize,
    uncalibrated: usize,
    /// (error, its sigma), deg: toolface, determined azimuth.
    toolface: Vec<(f64, f64)>,
    azimuth: Vec<(f64, f64)>,
}

impl StationTally {
    fn coverage(self, station: u16) -> StationCoverage {
        let n = self.toolface.len();
        let mean = (n > 0).then(|| self.toolface.iter().map(|(e, _)| e).sum::<f64>() / n as f64);
        let (rms_toolface_deg, median_toolface_sigma_deg) = rms_and_median_sigma(&self.toolface);
        let (rms_azimuth_deg, median_azimuth_sigma_deg) = rms_and_median_sigma(&self.azimuth);
        StationCoverage {
            station,
            inclination_within_2_sigma: Fraction::of(self.inside[0], self.totals[0]),
            azimuth_within_2_sigma: Fraction::of(self.inside[1], self.totals[1]),
            toolface_within_2_sigma: Fraction::of(self.inside[2], self.totals[2]),
            azimuth_undetermined: self.undetermined,
            rms_toolface_deg,
            mean_toolface_error_deg: mean,
            median_toolface_sigma_deg,
            rms_azimuth_deg,
            median_azimuth_sigma_deg,
            uncalibrated: self.uncalibrated,
        }
    }
}

fn percent(f: &Fraction) -> String {
    f.text().unwrap_or_else(|| "undetermined (no cases)".into())
}

fn opt(v: Option<f64>, unit: &str) -> String {
    v.map_or_else(
        || "undetermined (no cases)".into(),
        |v| format!("{v:.4} {unit}"),
    )
}

/// The terminal table.
pub fn table(s: &Summary) -> String {
    let mut rows = vec![
        (
            "runs",
            format!("{} ({} failed)", s.runs, s.failed_runs.len()),
        ),
        ("stations", s.stations.to_string()),
    ];
    if s.uncalibrated_stations > 0 {
        rows.push((
            "  flagged uncalibrated",
            format!(
                "{} (the probe without the calibration of its parts: their sigmas do not cover its uncalibrated errors)",
                s.uncalibrated_stations
            ),
        ));
    }
    rows.extend([
        ("  invalid (not counted)", s.invalid_stations.to_string()),
        (
            "  azimuth undetermined",
            s.undetermined_azimuth_stations.to_string(),
        ),
        (
            "azimuth within 2 sigma (>= 93 %)",
            percent(&s.azimuth_within_2_sigma),
        ),
        (
            "inclination within 2 sigma (95 +- 3 %)",
            percent(&s.inclination_within_2_sigma),
        ),
        (
            "toolface within 2 sigma (95 +- 3 %)",
            percent(&s.toolface_within_2_sigma),
        ),
        (
            "TD inside the 95 % ellipse (95 +- 3 %)",
            percent(&s.td_inside_95_ellipse),
        ),
        ("RMS inclination error", opt(s.rms_inclination_deg, "deg")),
        ("RMS azimuth error", opt(s.rms_azimuth_deg, "deg")),
        ("RMS toolface error", opt(s.rms_toolface_deg, "deg")),
        ("RMS TD horizontal error", opt(s.rms_td_horizontal_m, "m")),
        ("samples", s.samples.to_string()),
        ("wall time", format!("{:.1} s", s.wall_s)),
    ]);
    for (reason, n) in &s.td_unchecked {
        rows.push(("TD not checked", format!("{n} runs: {reason}")));
    }
    for e in s.failed_runs.iter().take(5) {
        rows.push(("failed", e.clone()));
    }
    let mut out = String::new();
    if let Some(i) = &s.interrupted {
        out.push_str(&format!(
            "INTERRUPTED after {} of {} runs: every figure below is over the runs done\n\n",
            i.jobs_done, i.jobs
        ));
    }
    if s.uncalibrated_stations > 0 {
        out.push_str(&format!("{UNCALIBRATED_NOTE}\n\n"));
    }
    out.extend(rows.iter().map(|(k, v)| format!("{k:<42} {v}\n")));
    out.push_str("\nby station: within 2 sigma (inclination, azimuth where determined, toolface); azimuth error RMS against its median sigma; toolface error mean and RMS against its median sigma\n");
    for c in &s.by_station {
        let short = |f: &Fraction| {
            f.fraction
                .map_or_else(|| "  -  ".into(), |p| format!("{:5.1}", 100.0 * p))
        };
        let deg = |v: Option<f64>| v.map_or_else(|| "-".into(), |v| format!("{v:.3}"));
        let flagged = if c.uncalibrated > 0 {
            format!("  flagged uncalibrated in {}", c.uncalibrated)
        } else {
            String::new()
        };
        out.push_str(&format!(
            "  station {:>3}: inc {} %  azi {} % ({} undetermined, RMS {} sigma {})  tf {} %  tf error mean {} RMS {} sigma {} deg{flagged}\n",
            c.station,
            short(&c.inclination_within_2_sigma),
            short(&c.azimuth_within_2_sigma),
            c.azimuth_undetermined,
            deg(c.rms_azimuth_deg),
            deg(c.median_azimuth_sigma_deg),
            short(&c.toolface_within_2_sigma),
            deg(c.mean_toolface_error_deg),
            deg(c.rms_toolface_deg),
            deg(c.median_toolface_sigma_deg),
        ));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::Fraction;

    #[test]
    fn a_fraction_has_a_standard_error_only_where_it_is_valid() {
        let f = Fraction::of(190, 200);
        assert_eq!(f.text().as_deref(), Some("95.0 +- 1.5 % (190/200)"));
        // All or none of n: the binomial formula's 0 is no spread any
        // finite count shows, so there is none.
        for (k, text) in [(9, "100.0 % (9/9)"), (0, "0.0 % (0/9)")] {
            let f = Fraction::of(k, 9);
            assert_eq!(f.standard_error, None);
            assert_eq!(f.text().as_deref(), Some(text));
        }
        let none = Fraction::of(0, 0);
        assert_eq!((none.fraction, none.text()), (None, None));
    }
}
