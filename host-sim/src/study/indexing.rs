//! Toolface indexing at a connection (`host-sim study indexing`): can a
//! connection's still time re-find the azimuth when it is split into
//! two or four dwells with the orienter turning the toolface 180 or 90 deg
//! between them (the MGWD paper's indexing)?
//!
//! Indexing turns the cross-axis gyros' biases against the earth rate:
//! at one toolface a gyro's bias and the horizontal earth rate it senses
//! are one number; at two toolfaces 180 deg apart the earth rate changes
//! sign in the body and the bias does not, so the heading is found free of
//! the bias (`mwd_core::alignment`, generalised gyrocompassing over the
//! dwells). What is left is the rate noise of each dwell's mean, which
//! splitting the still time does not reduce: with the SCC1300's 0.86
//! deg/sqrt(h) a 300 s mean is known to about 3 deg/h, about a third of
//! the horizontal earth rate at 46 deg latitude. The study measures it:
//! per grade and number of dwells, at the same total still time, seeded
//! runs of a still horizontal probe at a random azimuth and toolface,
//! each coarse-aligned as the probe aligns, the azimuth's error against
//! the printed sigma.

use crate::alignment::coarse;
use crate::sim::{Motion, SensorSimulator, Trajectory};
use crate::study::grade::Grade;
use anyhow::{bail, Result};
use mwd_core::alignment::AlignmentConfig;
use mwd_core::conventions::{wrap_pi, DrillingAngles, DEG};
use mwd_core::earth::Position;
use mwd_core::timing::SAMPLE_INTERVAL_S;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use serde::Serialize;
use std::f64::consts::TAU;
use std::ops::Range;

/// Samples left out at each end of a dwell (1 s): the turn's last and
/// first samples, which a probe's still detector would not call still.
const EDGE_SAMPLES: usize = 20;

/// The indexing studied: a connection's still time, how it is split, where.
#[derive(Clone, Debug, PartialEq)]
pub struct IndexingSetup {
    /// Still time of the connection, all dwells together (s).
    pub still_s: f64,
    /// The orienter's turn rate (rad/s).
    pub turn_rate: f64,
    /// Inclination of the hole (rad); the azimuth and toolface are drawn
    /// per run.
    pub inclination: f64,
    pub site: Position,
    /// 1-sigma (rad) of the azimuth the driller knows beforehand (the
    /// plan's, the last station's): it chooses between a horizontal
    /// tool's two mirror headings when the gyros cannot.
    pub prior_sigma: f64,
}

/// One run: the coarse alignment's azimuth against the truth.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct IndexedStation {
    /// Whether the alignment calls its heading determined (a sigma within
    /// `mwd_core::alignment::MAX_DETERMINED_SIGMA`); an undetermined one is
    /// no number.
    pub determined: bool,
    /// Estimate minus truth (rad).
    pub error: f64,
    /// The printed 1-sigma (rad).
    pub sigma: f64,
}

/// The sample ranges of `positions` dwells of `dwell_samples` each, with
/// `turn_samples` between them, less [`EDGE_SAMPLES`] at each end.
pub fn dwell_spans(positions: u32, dwell_samples: usize, turn_samples: usize) -> Vec<Range<usize>> {
    (0..positions as usize)
        .map(|k| {
            let start = k * (dwell_samples + turn_samples);
            start + EDGE_SAMPLES..start + dwell_samples.saturating_sub(EDGE_SAMPLES)
        })
        .collect()
}

/// One seeded station of `grade` with the still time in `positions`
/// dwells (1: no indexing), the toolface turned 360 / positions deg
/// between them.
pub fn indexed_station(
    grade: &Grade,
    positions: u32,
    setup: &IndexingSetup,
    seed: u64,
) -> Result<IndexedStation> {
    if !(1..=mwd_core::alignment::MAX_SEGMENTS as u32).contains(&positions) {
        bail!(
            "{positions} dwells: 1 to {} can be aligned",
            mwd_core::alignment::MAX_SEGMENTS
        );
    }
    // The geometry on a stream of its own: every grade and indexing sees
    // the same azimuths and toolfaces for a seed.
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x1DE5_0000_7F00_0005);
    let angles = DrillingAngles {
        inclination: setup.inclination,
        azimuth: rng.random_range(0.0..TAU),
        toolface: rng.random_range(0.0..TAU),
    };
    let prior_error = setup.prior_sigma * rng.sample::<f64, _>(StandardNormal);
    let start = angles.to_euler();
    let step = TAU / f64::from(positions);
    let dwell_s = setup.still_s / f64::from(positions);
    let turn_s = if positions > 1 {
        step / setup.turn_rate
    } else {
        0.0
    };
    let trajectory = Trajectory {
        position: setup.site,
        start,
        motion: Motion::ToolfaceSteps {
            step,
            turn_rate: setup.turn_rate,
            dwell: dwell_s,
            steps: positions as usize - 1,
        },
    };
    let dwell_samples = (dwell_s / SAMPLE_INTERVAL_S).round() as usize;
    let turn_samples = (turn_s / SAMPLE_INTERVAL_S).round() as usize;
    let total = positions as usize * dwell_samples + (positions as usize - 1) * turn_samples;
    let model = grade.sensor_model(seed);
    let calibration = model.deterministic.calibration();
    let records: Vec<_> = SensorSimulator::new(trajectory, model, SAMPLE_INTERVAL_S)
        .take(total)
        .map(|s| coarse::calibrated(&(&s).into(), &calibration))
        .collect();
    let config = AlignmentConfig {
        noise: grade.noise_budget(),
        ..AlignmentConfig::probe(setup.site.lat)
            .with_heading_prior(Some(start.heading + prior_error))
    };
    let spans = dwell_spans(positions, dwell_samples, turn_samples);
    let report = coarse::align(&records, &spans, &config)?;
    let heading = report.heading;
    Ok(IndexedStation {
        determined: heading.determined,
        error: wrap_pi(heading.heading.value - start.heading),
        sigma: heading.heading.sigma,
    })
}

/// A grade's stations at one indexing.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct IndexingSummary {
    pub grade: String,
    /// Dwells per connection (1: no indexing).
    pub positions: u32,
    pub runs: usize,
    /// Runs whose heading the alignment called determined.
    pub determined: usize,
    /// Over the determined runs: the azimuth error's RMS (deg), the median
    /// printed sigma (deg), and the share within 2 sigma.
    pub azimuth_rms_deg: Option<f64>,
    pub median_sigma_deg: Option<f64>,
    pub within_2_sigma: Option<f64>,
    /// Runs that failed (with the first failure's message).
    pub failed: usize,
    pub first_failure: Option<String>,
}

/// The summary of `stations` (seeded outcomes) of `grade` at `positions`.
pub fn summarize(
    grade: &str,
    positions: u32,
    stations: &[(u64, Result<IndexedStation, String>)],
) -> IndexingSummary {
    let done: Vec<&IndexedStation> = stations
        .iter()
        .filter_map(|(_, r)| r.as_ref().ok())
        .collect();
    let determined: Vec<&IndexedStation> = done.iter().copied().filter(|s| s.determined).collect();
    let n = determined.len();
    let (rms, median, within) = if n == 0 {
        (None, None, None)
    } else {
        let rms = (determined.iter().map(|s| s.error * s.error).sum::<f64>() / n as f64).sqrt();
        let mut sigmas: Vec<f64> = determined.iter().map(|s| s.sigma).collect();
        sigmas.sort_by(f64::total_cmp);
        let median = sigmas[n / 2];
        let inside = determined
            .iter()
            .filter(|s| s.error.abs() <= 2.0 * s.sigma)
            .count();
        (
            Some(rms / DEG),
            Some(median / DEG),
            Some(inside as f64 / n as f64),
        )
    };
    IndexingSummary {
        grade: grade.to_string(),
        positions,
        runs: stations.len(),
        determined: n,
        azimuth_rms_deg: rms,
        median_sigma_deg: median,
        within_2_sigma: within,
        failed: stations.len() - done.len(),
        first_failure: stations.iter().find_map(|(_, r)| r.as_ref().err().cloned()),
    }
}

/// The table for people: per grade and indexing, determined runs and,
/// over them, the azimuth error RMS, the median sigma and the share within
/// 2 sigma ("-" where no run was determined: no number to give).
pub fn table(summaries: &[IndexingSummary]) -> String {
    let mut text = String::from(
        "grade           dwells   turned  determined  azimuth RMS (deg)  median sigma (deg)  within 2 sigma  failed\n",
    );
    let number =
        |v: Option<f64>, digits: usize| v.map_or("-".to_string(), |v| format!("{v:.digits$}"));
    for s in summaries {
        let turned = if s.positions > 1 {
            format!("{:.0} deg", 360.0 / f64::from(s.positions))
        } else {
            "-".to_string()
        };
        text.push_str(&format!(
            "{:<15} {:>6}  {:>7}  {:>10}  {:>17}  {:>18}  {:>14}  {:>6}\n",
            s.grade,
            s.positions,
            turned,
            format!("{}/{}", s.determined, s.runs),
            number(s.azimuth_rms_deg, 3),
            number(s.median_sigma_deg, 3),
            s.within_2_sigma
                .map_or("-".to_string(), |w| format!("{:.1} %", 100.0 * w)),
            s.failed,
        ));
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    fn setup() -> IndexingSetup {
        IndexingSetup {
            still_s: 300.0,
            turn_rate: 10.0 * DEG,
            inclination: 90.0 * DEG,
            site: Position::paper_site(),
            prior_sigma: 5.0 * DEG,
        }
    }

    #[test]
    fn dwells_leave_out_the_turns_and_a_second_at_each_end() {
        let spans = dwell_spans(2, 3000, 360);
        assert_eq!(spans, vec![20..2980, 3380..6340]);
        assert_eq!(dwell_spans(1, 6000, 0), vec![20..5980]);
    }

    fn stations(grade: &Grade, positions: u32, seeds: u64) -> IndexingSummary {
        let stations: Vec<_> = (1..=seeds)
            .map(|seed| {
                let station = indexed_station(grade, positions, &setup(), seed);
                (seed, station.map_err(|e| e.to_string()))
            })
            .collect();
        summarize(grade.name(), positions, &stations)
    }

    fn grade(name: &str) -> Grade {
        let mut grades = crate::study::grade::select(&[name.to_string()], &[]).unwrap();
        grades.remove(0)
    }

    #[test]
    fn a_quiet_gyro_finds_the_azimuth_at_a_connection_within_its_sigma() {
        // The navigation grade finds it to a fraction of a degree in 300 s,
        // indexed or not (a run near east or west may stay undetermined).
        let grade = grade("navigation");
        for positions in [1, 2, 4] {
            let s = stations(&grade, positions, 6);
            assert_eq!(s.failed, 0, "{s:?}");
            assert!(s.determined >= 5, "{s:?}");
            assert!(s.azimuth_rms_deg.unwrap() < 1.0, "{s:?}");
            assert!(s.within_2_sigma.unwrap() >= 0.8, "{s:?}");
        }
    }

    #[test]
    fn indexing_frees_a_mems_gyro_of_its_bias() {
        // One dwell: the high-end MEMS gyro's 0.5 deg/h bias and the earth
        // rate are one number; two dwells 180 deg apart tell them apart, and
        // more stations find their azimuth.
        let grade = grade("high-end-mems");
        let plain = stations(&grade, 1, 30);
        let indexed = stations(&grade, 2, 30);
        assert!(
            indexed.determined > plain.determined,
            "{plain:?} {indexed:?}"
        );
        assert!(
            indexed.median_sigma_deg.unwrap() < plain.median_sigma_deg.unwrap(),
            "{plain:?} {indexed:?}"
        );
    }

    #[test]
    fn more_dwells_than_the_alignment_takes_are_refused() {
        let grade = Grade::scc1300().unwrap();
        let too_many = mwd_core::alignment::MAX_SEGMENTS as u32 + 1;
        assert!(indexed_station(&grade, too_many, &setup(), 1).is_err());
        assert!(indexed_station(&grade, 0, &setup(), 1).is_err());
    }

    #[test]
    fn an_undetermined_azimuth_gives_no_number() {
        let stations = vec![(
            1,
            Ok(IndexedStation {
                determined: false,
                error: 1.0,
                sigma: 2.0,
            }),
        )];
        let s = summarize("g", 2, &stations);
        assert_eq!((s.determined, s.azimuth_rms_deg), (0, None));
        assert!(table(&[s]).contains("0/1"));
    }
}
