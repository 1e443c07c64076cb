//! Where the azimuth's printed sigma stops holding its error: at the
//! stations or in the drilling between them ([`super`]).
//!
//! Each determined station gives its azimuth error and sigma at its start
//! (the last solution before its first still sample,
//! `StationCheck::azimuth_error_before`) and at its end (the station's).
//! Normalised quantities follow, each with an RMS of 1 when the filter's
//! azimuth variance is right:
//!
//! * the station's correction, the azimuth estimate's change over it,
//!   `d = e_start - e_end`, against `s_start^2 - s_end^2`: a Kalman
//!   filter's correction is orthogonal to its error after it, so its
//!   variance is the variance it removes (the gyros' own random walk over
//!   a 5-min station, 0.25 deg for the SCC1300, is left out: a little on
//!   the high side of 1 where a station removes little);
//! * the drilling before it, the error's change from the previous
//!   station's end, against `s_start(k)^2 - s_end(k-1)^2`: the filter
//!   takes no azimuth information while drilling (the constraints' attitude
//!   rows are dropped, docs/filter-derivation.md 4d), so that growth is
//!   what its model adds. This one is 1 only when the change is
//!   uncorrelated with the error it starts from: a rate gyrocompass ties
//!   the heading error to the bias error that then drifts it, and a
//!   consistent filter scores above 1 (unit test below);
//! * so also the error over its sigma at each station's start and end,
//!   which needs no such assumption.
//!
//! The window's station (the first) is not counted as a correction nor
//! as a start: the tie-in replaces its heading.
//!
//! The mean fraction of the azimuth variance a station removes,
//! `1 - s_end^2 / s_start^2`, says how much the station weighs.

use crate::study::drilling_run::{RunOutcome, StationCheck};
use crate::study::stats::rms;
use crate::survey::listing::drilling::azimuth_usable;
use serde::Serialize;
use std::collections::BTreeMap;

/// The run's first station, at the window: the tie-in replaces its
/// heading (a survey's, not the station's measurement; before it the
/// solution is the alignment's), so its change is not a station's
/// correction. Its end starts the first drilling stretch.
const WINDOW_STATION: u16 = 1;

/// The azimuth's consistency through stations and drilling; `None` where
/// nothing was counted (undetermined, never 0).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct AzimuthConsistency {
    pub stations: usize,
    /// RMS of d / sqrt(s_start^2 - s_end^2) over the stations that
    /// removed variance.
    pub station_correction_ratio: Option<f64>,
    /// Mean of 1 - s_end^2 / s_start^2 over the same stations.
    pub station_variance_removed: Option<f64>,
    pub drilling_stretches: usize,
    /// RMS of the error's change over a drilling stretch against the
    /// square root of its variance's growth.
    pub drilling_growth_ratio: Option<f64>,
    /// RMS of the azimuth error over its sigma at the counted stations'
    /// starts (after the drilling) and at their ends: 1 when the sigma
    /// holds there, whatever the correlations. The growth ratio above
    /// reads the change alone, so it is 1 only when the change is
    /// uncorrelated with the error it starts from: a station that leaves
    /// its heading error tied to its gyro bias error (the SCC1300's rate
    /// gyrocompass) makes it larger with a consistent filter.
    pub start_error_ratio: Option<f64>,
    pub end_error_ratio: Option<f64>,
}

/// (error, sigma) at a determined station's start and end, rad.
fn start_and_end(st: &StationCheck) -> Option<((f64, f64), (f64, f64))> {
    let valid = azimuth_usable(&st.survey);
    let end = (st.error[1], f64::from(st.survey.angles_std[1]));
    let start = (st.azimuth_error_before?, st.azimuth_sigma_before?);
    let finite = [start.0, start.1, end.0, end.1]
        .iter()
        .all(|v| v.is_finite());
    let positive = start.1 > 0.0 && end.1 > 0.0;
    (valid && finite && positive).then_some((start, end))
}

/// One counted station's two normalised quantities.
struct Counted {
    station: u16,
    /// (correction / its sigma, fraction of the variance removed), where
    /// the station removed variance and is not the window's.
    correction: Option<(f64, f64)>,
    /// The drilling stretch that ended at this station, against its
    /// growth, where the station before it was counted.
    stretch: Option<f64>,
    /// The error over its sigma at the station's start (not at the
    /// window's: that is the alignment's heading, which the tie-in
    /// replaces) and at its end.
    start: Option<f64>,
    end: f64,
}

/// Every determined station's quantities over the runs that finished.
fn counted<'a>(runs: impl Iterator<Item = &'a RunOutcome>) -> Vec<Counted> {
    let mut out = Vec::new();
    for run in runs {
        let mut previous_end: Option<(u16, (f64, f64))> = None;
        for st in &run.stations {
            let Some((start, end)) = start_and_end(st) else {
                previous_end = None;
                continue;
            };
            let lost = start.1 * start.1 - end.1 * end.1;
            let correction = (lost > 0.0 && st.survey.station != WINDOW_STATION)
                .then(|| ((start.0 - end.0) / lost.sqrt(), lost / (start.1 * start.1)));
            // The stretch from the previous station's end, where that
            // station is the one before this.
            let stretch = previous_end.and_then(|(number, (e0, s0))| {
                let grown = start.1 * start.1 - s0 * s0;
                (number.wrapping_add(1) == st.survey.station && grown > 0.0)
                    .then(|| (start.0 - e0) / grown.sqrt())
            });
            out.push(Counted {
                station: st.survey.station,
                correction,
                stretch,
                start: (st.survey.station != WINDOW_STATION).then(|| start.0 / start.1),
                end: end.0 / end.1,
            });
            previous_end = Some((st.survey.station, end));
        }
    }
    out
}

fn consistency_of<'a>(counted: impl Iterator<Item = &'a Counted> + Clone) -> AzimuthConsistency {
    let corrections: Vec<(f64, f64)> = counted.clone().filter_map(|c| c.correction).collect();
    let stretches: Vec<f64> = counted.clone().filter_map(|c| c.stretch).collect();
    let starts: Vec<f64> = counted.clone().filter_map(|c| c.start).collect();
    let ends: Vec<f64> = counted.map(|c| c.end).collect();
    let ratios: Vec<f64> = corrections.iter().map(|c| c.0).collect();
    let n = corrections.len();
    AzimuthConsistency {
        stations: n,
        station_correction_ratio: rms(&ratios),
        station_variance_removed: (n > 0)
            .then(|| corrections.iter().map(|c| c.1).sum::<f64>() / n as f64),
        drilling_stretches: stretches.len(),
        drilling_growth_ratio: rms(&stretches),
        start_error_ratio: rms(&starts),
        end_error_ratio: rms(&ends),
    }
}

/// The consistency over the runs that finished, in all and per station
/// number (the drilling stretch counted at the station it ends at, in
/// station order: where along the well the sigma stops holding), from one
/// pass over the stations.
pub fn azimuth_consistency<'a>(
    runs: impl Iterator<Item = &'a RunOutcome>,
) -> (AzimuthConsistency, BTreeMap<u16, AzimuthConsistency>) {
    let all = counted(runs);
    let mut by_number: BTreeMap<u16, Vec<&Counted>> = BTreeMap::new();
    for c in &all {
        by_number.entry(c.station).or_default().push(c);
    }
    let by_station = by_number
        .into_iter()
        .map(|(n, stations)| (n, consistency_of(stations.into_iter())))
        .collect();
    (consistency_of(all.iter()), by_station)
}

#[cfg(test)]
mod tests {
    use super::*;
    use mwd_core::protocol::frame::station_flags;
    use mwd_core::protocol::StationSurvey;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;
    use rand_distr::{Distribution, StandardNormal};

    fn station(number: u16, start: (f64, f64), end: (f64, f64)) -> StationCheck {
        StationCheck {
            survey: StationSurvey {
                station: number,
                angles_std: [0.001, end.1 as f32, 0.001],
                ..StationSurvey::default()
            },
            error: [0.0, end.0, 0.0],
            truth_md: 0.0,
            azimuth_sigma_before: Some(start.1),
            azimuth_error_before: Some(start.0),
            link: None,
            position: None,
        }
    }

    fn run(stations: Vec<StationCheck>) -> RunOutcome {
        RunOutcome::of_stations(0, stations)
    }

    /// Runs of a scalar Kalman filter: random-walk growth `q` between
    /// stations, a station measuring the error with variance `r`, the
    /// filter told `r_told` (the truth is drawn with `r`).
    fn kalman_runs(r: f64, r_told: f64) -> Vec<RunOutcome> {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let mut normal = || -> f64 { StandardNormal.sample(&mut rng) };
        let q: f64 = 4.0;
        (0..400)
            .map(|_| {
                let (mut e, mut p): (f64, f64) = (normal(), 1.0);
                let stations = (1..=6)
                    .map(|k| {
                        e += q.sqrt() * normal();
                        p += q;
                        let start = (e, p.sqrt());
                        let z = e + r.sqrt() * normal();
                        let gain = p / (p + r_told);
                        e -= gain * z;
                        p *= 1.0 - gain;
                        station(k, start, (e, p.sqrt()))
                    })
                    .collect();
                run(stations)
            })
            .collect()
    }

    #[test]
    fn a_consistent_filter_scores_one_at_stations_and_between_them() {
        let runs = kalman_runs(3.0, 3.0);
        let c = azimuth_consistency(runs.iter()).0;
        // station 1 of each run is the window's: not a correction
        assert_eq!(c.stations, 2000);
        assert_eq!(c.drilling_stretches, 2000);
        let station = c.station_correction_ratio.unwrap();
        let drilling = c.drilling_growth_ratio.unwrap();
        assert!((station - 1.0).abs() < 0.05, "{station}");
        assert!((drilling - 1.0).abs() < 0.05, "{drilling}");
        let removed = c.station_variance_removed.unwrap();
        assert!(removed > 0.5 && removed < 0.8, "{removed}");
        for r in [c.start_error_ratio.unwrap(), c.end_error_ratio.unwrap()] {
            assert!((r - 1.0).abs() < 0.05, "{r}");
        }
    }

    #[test]
    fn a_station_measurement_noisier_than_the_filter_is_told_shows_at_the_stations() {
        // The correction's variance is gain^2 (p + r) against the told
        // gain^2 (p + r_told): at the steady prior p = 6, sqrt(12 / 9).
        let c = azimuth_consistency(kalman_runs(6.0, 3.0).iter()).0;
        let station = c.station_correction_ratio.unwrap();
        assert!(station > 1.1 && station < 1.3, "{station}");
        let drilling = c.drilling_growth_ratio.unwrap();
        assert!((drilling - 1.0).abs() < 0.05, "{drilling}");
    }

    #[test]
    fn undetermined_stations_and_missing_starts_are_not_counted() {
        let mut undetermined = station(2, (0.1, 0.2), (0.1, 0.1));
        undetermined.survey.flags = station_flags::AZIMUTH_UNDETERMINED;
        let mut no_start = station(3, (0.1, 0.2), (0.1, 0.1));
        no_start.azimuth_error_before = None;
        let runs = [run(vec![
            station(1, (0.1, 0.2), (0.1, 0.1)),
            undetermined,
            no_start,
            station(4, (0.3, 0.3), (0.0, 0.1)),
        ])];
        let c = azimuth_consistency(runs.iter()).0;
        // station 1 is the window's; station 4 is counted
        assert_eq!(c.stations, 1);
        // station 4 follows no counted station 3: no stretch
        assert_eq!(c.drilling_stretches, 0);
        assert_eq!(c.drilling_growth_ratio, None);
        let empty = azimuth_consistency([].iter()).0;
        assert_eq!(empty.station_correction_ratio, None);
        assert_eq!(empty.station_variance_removed, None);
    }

    #[test]
    fn the_by_station_breakdown_splits_the_same_counts() {
        let runs = kalman_runs(3.0, 3.0);
        let (all, by) = azimuth_consistency(runs.iter());
        assert_eq!(
            by.keys().copied().collect::<Vec<_>>(),
            vec![1, 2, 3, 4, 5, 6]
        );
        assert_eq!(by[&1].stations, 0, "the window's station corrects nothing");
        assert_eq!(
            by[&1].drilling_stretches, 0,
            "no stretch ends at the window"
        );
        assert_eq!(
            by[&1].start_error_ratio, None,
            "the window starts from the alignment"
        );
        let stations: usize = by.values().map(|c| c.stations).sum();
        let stretches: usize = by.values().map(|c| c.drilling_stretches).sum();
        assert_eq!(
            (stations, stretches),
            (all.stations, all.drilling_stretches)
        );
        // each station's own 400 ratios score one (a few percent of noise)
        for c in by.values().skip(1) {
            let r = c.drilling_growth_ratio.unwrap();
            assert!((r - 1.0).abs() < 0.12, "{r}");
        }
    }

    /// A consistent two-state filter (heading error and a constant gyro
    /// bias; a station measures their sum, as a rate gyrocompass does):
    /// after a station the two errors are anti-correlated, so the drift
    /// that follows, b T + w, partly undoes the heading error and the
    /// variance grows by less than the drift's own square. The growth
    /// ratio then reads above 1 while the sigma holds at every start and
    /// end: the start and end ratios are the consistency check.
    #[test]
    fn a_drift_tied_to_the_heading_error_lifts_the_growth_ratio_of_a_consistent_filter() {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let mut normal = || -> f64 { StandardNormal.sample(&mut rng) };
        let (t, q, r): (f64, f64, f64) = (1.0, 0.5, 0.2);
        let runs: Vec<RunOutcome> = (0..1000)
            .map(|_| {
                let (mut psi, mut b) = (normal(), normal());
                // P = [[pp, pb], [pb, bb]]
                let (mut pp, mut pb, mut bb): (f64, f64, f64) = (1.0, 0.0, 1.0);
                let stations = (1..=6)
                    .map(|k| {
                        psi += b * t + q.sqrt() * normal();
                        pp += 2.0 * t * pb + t * t * bb + q;
                        pb += t * bb;
                        let start = (psi, pp.sqrt());
                        // z = psi + b + v; the estimate's correction is fed
                        // back, so the errors become (I - k h^T) e - k v.
                        let v = r.sqrt() * normal();
                        let s = pp + 2.0 * pb + bb + r;
                        let (k1, k2) = ((pp + pb) / s, (pb + bb) / s);
                        let innovation = psi + b + v;
                        psi -= k1 * innovation;
                        b -= k2 * innovation;
                        let (c1, c2) = (pp + pb, pb + bb);
                        pp -= k1 * c1;
                        pb -= k1 * c2;
                        bb -= k2 * c2;
                        station(k, start, (psi, pp.sqrt()))
                    })
                    .collect();
                run(stations)
            })
            .collect();
        let c = azimuth_consistency(runs.iter()).0;
        let growth = c.drilling_growth_ratio.unwrap();
        assert!(growth > 1.15, "{growth}");
        for ratio in [c.start_error_ratio.unwrap(), c.end_error_ratio.unwrap()] {
            assert!((ratio - 1.0).abs() < 0.04, "{ratio}");
        }
    }
}
