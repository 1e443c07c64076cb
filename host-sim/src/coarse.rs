//! Coarse alignment of a recorded or simulated static run: calibration,
//! splitting into static segments (toolface positions), and the core's
//! levelling and heading estimators, with a report for people.
use crate::samples_csv::Record;
use anyhow::{bail, Result};
use mwd_core::alignment::{
    analytical, gyrocompass, level_segment, AlignmentConfig, HeadingEstimate, LevelEstimate,
    SegmentSums, StaticSegment, COVERAGE_FACTOR, MAX_SEGMENTS,
};
use mwd_core::attitude::level;
use mwd_core::calibration::ProbeCalibration;
use mwd_core::conventions::{wrap_pi, DrillingAngles, Euler, DEG};
use std::fmt::Write as _;
use std::ops::Range;

/// Samples per block when looking for static segments (1 s at 20 Hz).
const BLOCK: usize = 20;
/// Blocks whose mean roll moves more than this from the previous block's
/// belong to a toolface change (rad).
const TOOLFACE_CHANGE: f64 = 2.0 * DEG;
/// Shortest static segment worth keeping (blocks).
const MIN_SEGMENT_BLOCKS: usize = 3;

/// Applies the probe's calibration to one record as the probe does
/// ([`ProbeCalibration::correct`]): the file's one accelerometer triad
/// stands for both parts' (each corrected with its own calibration, then
/// averaged), the gyros on body x and z.
pub fn calibrated(record: &Record, calibration: &ProbeCalibration) -> Record {
    let s = &record.sample;
    let triad: [f64; 3] = s.specific_force.into();
    Record {
        sample: calibration.correct(s.rate_x(), s.rate_z(), &[triad; 2]),
        ..record.clone()
    }
}

/// The static segment of a run of records: their means.
pub fn segment(records: &[Record]) -> StaticSegment {
    let mut sums = SegmentSums::default();
    for r in records {
        sums.add(&r.sample);
    }
    sums.segment()
}

/// Finds the static segments of a run: 1 s blocks, split where the mean
/// roll moves (toolface indexing), trimmed by a block at each end so the
/// turns are left out. At most [`MAX_SEGMENTS`].
pub fn find_segments(records: &[Record]) -> Vec<Range<usize>> {
    let blocks: Vec<Range<usize>> = (0..records.len() / BLOCK)
        .map(|b| b * BLOCK..(b + 1) * BLOCK)
        .collect();
    let roll =
        |range: &Range<usize>| level(&segment(&records[range.clone()]).mean.specific_force).roll;
    let mut runs: Vec<Range<usize>> = Vec::new();
    let mut start = 0;
    for b in 1..=blocks.len() {
        let split = b == blocks.len()
            || wrap_pi(roll(&blocks[b]) - roll(&blocks[b - 1])).abs() > TOOLFACE_CHANGE;
        if split {
            runs.push(start..b);
            start = b;
        }
    }
    let single = runs.len() == 1;
    runs.into_iter()
        .filter_map(|run| {
            // A whole-file static run keeps every block; runs next to a turn
            // lose the block at each end.
            let (first, last) = if single {
                (run.start, run.end)
            } else {
                (run.start + 1, run.end.saturating_sub(1))
            };
            (last >= first + MIN_SEGMENT_BLOCKS).then(|| first * BLOCK..last * BLOCK)
        })
        .take(MAX_SEGMENTS)
        .collect()
}

/// The result of a coarse alignment, per segment and overall.
#[derive(Clone, Debug)]
pub struct CoarseReport {
    pub spans: Vec<Range<usize>>,
    pub times: Vec<(f64, f64)>,
    pub levels: Vec<LevelEstimate>,
    pub heading: HeadingEstimate,
    /// Eq. 30 on the first segment, for comparison.
    pub analytical: Option<HeadingEstimate>,
    /// Truth at the end of each segment, when the file has it.
    pub truth: Vec<Option<Euler>>,
}

/// Coarse alignment of calibrated records over the given segments.
pub fn align(
    records: &[Record],
    spans: &[Range<usize>],
    config: &AlignmentConfig,
) -> Result<CoarseReport> {
    if spans.is_empty() {
        bail!("no static segment of at least {MIN_SEGMENT_BLOCKS} s found");
    }
    let mut segments = Vec::new();
    let mut levels = Vec::new();
    let mut times = Vec::new();
    let mut truth = Vec::new();
    for span in spans {
        let Some(run) = records.get(span.clone()) else {
            bail!(
                "segment {}..{} is outside the {} samples",
                span.start,
                span.end,
                records.len()
            );
        };
        let seg = segment(run);
        let lev = level_segment(&seg, config)
            .map_err(|e| anyhow::anyhow!("levelling samples {}..{}: {e}", span.start, span.end))?;
        segments.push(seg);
        levels.push(lev);
        times.push((
            run.first().map_or(0.0, |r| r.time),
            run.last().map_or(0.0, |r| r.time),
        ));
        truth.push(run.last().and_then(|r| r.truth));
    }
    let heading =
        gyrocompass(&segments, config).map_err(|e| anyhow::anyhow!("gyrocompassing: {e}"))?;
    let analytical = analytical(&segments[0], config).ok();
    Ok(CoarseReport {
        spans: spans.to_vec(),
        times,
        levels,
        heading,
        analytical,
        truth,
    })
}

fn deg(v: f64) -> f64 {
    v / DEG
}

impl CoarseReport {
    /// A table for people: per segment the levelling with 2-sigma bounds,
    /// drilling angles, and the heading with its bound and flags, next to
    /// the truth when known.
    pub fn render(&self) -> String {
        let k = COVERAGE_FACTOR;
        let mut s = String::new();
        let _ = writeln!(s, "Bounds are +-{k} sigma (about 95 %). Angles in degrees.");
        let _ = writeln!(
            s,
            "{:<4} {:>15} {:>18} {:>18} {:>8} {:>8} {:>18}",
            "seg", "time (s)", "roll", "pitch", "incl.", "toolface", "truth r/p/h"
        );
        for (i, lev) in self.levels.iter().enumerate() {
            let (t0, t1) = self.times[i];
            let d = DrillingAngles::from_euler(&Euler::new(lev.roll.value, lev.pitch.value, 0.0));
            let truth = self.truth[i].map_or("-".to_string(), |t| {
                format!(
                    "{:.3}/{:.3}/{:.2}",
                    deg(t.roll),
                    deg(t.pitch),
                    deg(t.heading)
                )
            });
            let roll = if lev.roll_valid {
                format!(
                    "{:8.4} +-{:.4}",
                    deg(lev.roll.value),
                    deg(k * lev.roll.sigma)
                )
            } else {
                "undefined (vertical)".to_string()
            };
            let _ = writeln!(
                s,
                "{:<4} {:>15} {:>18} {:>18} {:>8.3} {:>8.3} {:>18}",
                i + 1,
                format!("{t0:.2}-{t1:.2}"),
                roll,
                format!(
                    "{:8.4} +-{:.4}",
                    deg(lev.pitch.value),
                    deg(k * lev.pitch.sigma)
                ),
                deg(d.inclination),
                deg(d.toolface),
                truth
            );
        }
        let _ = writeln!(s);
        let _ = writeln!(
            s,
            "Heading by gyrocompassing over {} segment(s):",
            self.levels.len()
        );
        let _ = write!(
            s,
            "{}",
            describe_heading(
                &self.heading,
                self.levels.len(),
                self.truth.last().copied().flatten()
            )
        );
        if let Some(a) = &self.analytical {
            let _ = writeln!(
                s,
                "Heading by analytical alignment (eq. 30), segment 1 only:"
            );
            let _ = write!(
                s,
                "{}",
                describe_heading(a, 1, self.truth.first().copied().flatten())
            );
        }
        s
    }
}

/// Heading, azimuth, bound, flags and error against truth, as text.
/// `segments`: how many static segments the estimate used; gyro biases are
/// only separable from earth rate (and printed) with more than one.
pub fn describe_heading(h: &HeadingEstimate, segments: usize, truth: Option<Euler>) -> String {
    let mut s = String::new();
    let azimuth = DrillingAngles::from_euler(&Euler::new(0.0, 0.0, h.heading.value)).azimuth;
    if !h.heading.sigma.is_finite() {
        let _ = writeln!(s, "  no solution: the gyro means are inconsistent with the earth rate (noise or bias dominates)");
    } else if h.determined {
        let _ = writeln!(
            s,
            "  azimuth {:9.3} +-{:.3} (sigma {:.3})",
            deg(azimuth),
            deg(h.bound()),
            deg(h.heading.sigma)
        );
    } else {
        let _ = writeln!(
            s,
            "  azimuth {:9.3}, undetermined: sigma {:.1} exceeds {:.0} (bound +-180)",
            deg(azimuth),
            deg(h.heading.sigma),
            deg(mwd_core::alignment::MAX_DETERMINED_SIGMA)
        );
    }
    if let Some(alt) = h.alternative {
        let alt_az = DrillingAngles::from_euler(&Euler::new(0.0, 0.0, alt)).azimuth;
        let _ = writeln!(
            s,
            "  {} candidate {:.3} (north/south ambiguity; give --prior-heading to choose)",
            if h.ambiguous {
                "ambiguous: equally likely"
            } else {
                "other"
            },
            deg(alt_az),
        );
    }
    if h.ill_conditioned {
        let _ = writeln!(s, "  ill-conditioned: tool heading near east/west, earth rate barely changes with heading");
    }
    if segments > 1 {
        let _ = writeln!(
            s,
            "  estimated gyro bias x {:.2} z {:.2} deg/h",
            h.gyro_bias.x / DEG * 3600.0,
            h.gyro_bias.z / DEG * 3600.0
        );
    }
    if let Some(t) = truth {
        let err = wrap_pi(h.heading.value - t.heading);
        let _ = writeln!(
            s,
            "  truth {:.3}, error {:+.3}{}",
            deg(DrillingAngles::from_euler(&t).azimuth),
            deg(err),
            if err.abs() <= h.bound() {
                " (within bound)"
            } else {
                " (OUTSIDE bound)"
            }
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::{Motion, SensorModel, SensorSimulator, Trajectory};
    use mwd_core::earth::Position;
    use mwd_core::timing::SAMPLE_INTERVAL_S as SAMPLE_INTERVAL;

    fn records(traj: Trajectory, model: SensorModel, seconds: f64) -> Vec<Record> {
        let n = (seconds / SAMPLE_INTERVAL).round() as usize;
        SensorSimulator::new(traj, model, SAMPLE_INTERVAL)
            .take(n)
            .map(|s| Record::from(&s))
            .collect()
    }

    #[test]
    fn toolface_indexing_is_split_into_two_static_segments() {
        let traj = Trajectory {
            position: Position::paper_site(),
            start: Euler::new(0.3, -0.1, 0.2),
            motion: Motion::ToolfaceSteps {
                step: std::f64::consts::PI,
                turn_rate: 30.0 * DEG,
                dwell: 20.0,
                steps: 1,
            },
        };
        let recs = records(traj.clone(), SensorModel::ideal(), traj.scripted_duration());
        let spans = find_segments(&recs);
        assert_eq!(spans.len(), 2, "{spans:?}");
        // Each segment lies inside a dwell (0-20 s, 26-46 s).
        assert!(recs[spans[0].end - 1].time <= 20.0);
        assert!(recs[spans[1].start].time >= 26.0);
    }

    #[test]
    fn a_static_file_is_one_segment() {
        let recs = records(
            Trajectory::paper_static(Euler::default()),
            SensorModel::scc1300(2),
            60.0,
        );
        assert_eq!(find_segments(&recs), vec![0..1200]);
    }
}
