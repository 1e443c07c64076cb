//! Coarse alignment of a recorded or simulated static run: calibration,
//! splitting into static segments (toolface positions), and the core's
//! levelling and heading estimators, with a report for people.
use crate::formats::display::{azimuth_is_determined, azimuth_text, deg_0_360};
use crate::formats::samples_csv::Record;
use anyhow::{bail, Result};
use mwd_core::alignment::{
    analytical, gyrocompass, level_segment, AlignmentConfig, HeadingEstimate, LevelEstimate,
    SegmentSums, StaticSegment, COVERAGE_FACTOR, MAX_DETERMINED_SIGMA,
};
use mwd_core::calibration::ProbeCalibration;
use mwd_core::conventions::{wrap_pi, DrillingAngles, Euler, DEG};
use std::fmt::Write as _;
use std::ops::Range;

mod segmentation;
pub use segmentation::{segment_run, LeftOutReason, Segmentation, BLOCK, MIN_SEGMENT_BLOCKS};

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

/// The static segments of a run (see [`segment_run`]), at most
/// [`mwd_core::alignment::MAX_SEGMENTS`].
pub fn find_segments(records: &[Record]) -> Vec<Range<usize>> {
    segment_run(records).spans
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
    /// Samples of the run not used, with the reason (empty when the
    /// segments were given, not found).
    pub left_out: Vec<(Range<usize>, LeftOutReason)>,
    /// Samples in the run.
    pub total_samples: usize,
    /// Whether a heading prior chose between mirror candidates.
    pub prior_given: bool,
}

/// Coarse alignment of a whole run: its static segments found on the
/// physics ([`segment_run`]), every sample left out reported.
pub fn align_run(records: &[Record], config: &AlignmentConfig) -> Result<CoarseReport> {
    let segmentation = segment_run(records);
    let mut report = align(records, &segmentation.spans, config)?;
    report.left_out = segmentation.left_out;
    Ok(report)
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
        left_out: Vec::new(),
        total_samples: records.len(),
        prior_given: config.heading_prior.is_some(),
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
                deg_0_360(d.toolface),
                truth
            );
        }
        let _ = write!(s, "{}", self.render_left_out());
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
                self.truth.last().copied().flatten(),
                self.prior_given
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
                describe_heading(
                    a,
                    1,
                    self.truth.first().copied().flatten(),
                    self.prior_given
                )
            );
        }
        s
    }
}

impl CoarseReport {
    /// How many samples the segments use, and every sample left out with
    /// its reason (nothing is dropped silently).
    fn render_left_out(&self) -> String {
        let mut s = String::new();
        let used: usize = self.spans.iter().map(|r| r.len()).sum();
        let _ = writeln!(
            s,
            "Used {used} of {} samples in {} static segment(s).",
            self.total_samples,
            self.spans.len()
        );
        for (range, reason) in &self.left_out {
            let _ = writeln!(
                s,
                "  left out samples {}..{} ({} samples): {}",
                range.start,
                range.end,
                range.len(),
                reason.text()
            );
        }
        s
    }
}

/// Heading, azimuth, bound, flags and error against truth, as text.
/// `segments`: how many static segments the estimate used; gyro biases are
/// only separable from earth rate (and printed) with more than one.
/// `prior_given`: whether a heading prior chose between mirror candidates
/// (then the text does not ask for one). An undetermined azimuth is never
/// shown as a number ([`crate::formats::display`]), nor is its mirror candidate.
pub fn describe_heading(
    h: &HeadingEstimate,
    segments: usize,
    truth: Option<Euler>,
    prior_given: bool,
) -> String {
    let mut s = String::new();
    let sigma = h.heading.sigma;
    let determined = h.determined && azimuth_is_determined(sigma);
    if sigma.is_nan() || (!sigma.is_finite() && !h.heading.value.is_finite()) {
        let _ = writeln!(s, "  azimuth n/a: no solution (the gyro means are inconsistent with the earth rate; noise or bias dominates)");
    } else if determined {
        let _ = writeln!(
            s,
            "  azimuth {}, bound +-{:.3} (2 sigma)",
            azimuth_text(h.heading.value, sigma, 3),
            deg(h.bound())
        );
    } else {
        let _ = writeln!(
            s,
            "  azimuth undetermined: sigma {} exceeds {:.0} deg (bound +-180)",
            // Beyond a half turn a sigma says only "any heading".
            if sigma <= std::f64::consts::PI {
                format!("{:.1} deg", deg(sigma))
            } else {
                "over 180 deg".to_string()
            },
            deg(MAX_DETERMINED_SIGMA)
        );
    }
    if let (Some(alt), true) = (h.alternative, determined) {
        let choice = if prior_given {
            "north/south mirror; the prior chose the azimuth above"
        } else {
            "north/south mirror; give --prior-heading to choose"
        };
        let _ = writeln!(
            s,
            "  {} candidate {:.3} ({choice})",
            if h.ambiguous {
                "ambiguous: equally likely"
            } else {
                "other"
            },
            deg_0_360(alt),
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
        let truth_az = deg_0_360(t.heading);
        if determined {
            let err = wrap_pi(h.heading.value - t.heading);
            let _ = writeln!(
                s,
                "  truth {truth_az:.3}, error {:+.3}{}",
                deg(err),
                if err.abs() <= h.bound() {
                    " (within bound)"
                } else {
                    " (OUTSIDE bound)"
                }
            );
        } else {
            let _ = writeln!(
                s,
                "  truth {truth_az:.3} (no error: the azimuth is undetermined)"
            );
        }
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

    /// Two 20 s dwells at the paper's site, half a turn of toolface (6 s)
    /// between them.
    fn one_toolface_turn() -> Trajectory {
        Trajectory {
            position: Position::paper_site(),
            start: Euler::new(0.3, -0.1, 0.2),
            motion: Motion::ToolfaceSteps {
                step: std::f64::consts::PI,
                turn_rate: 30.0 * DEG,
                dwell: 20.0,
                steps: 1,
            },
        }
    }

    #[test]
    fn toolface_indexing_is_split_into_two_static_segments() {
        let traj = one_toolface_turn();
        let recs = records(traj.clone(), SensorModel::ideal(), traj.scripted_duration());
        let spans = find_segments(&recs);
        assert_eq!(spans.len(), 2, "{spans:?}");
        // Each segment lies inside a dwell (0-20 s, 26-46 s).
        assert!(recs[spans[0].end - 1].time <= 20.0);
        assert!(recs[spans[1].start].time >= 26.0);
    }

    fn estimate(value_deg: f64, sigma_deg: f64, determined: bool) -> HeadingEstimate {
        HeadingEstimate {
            heading: mwd_core::alignment::Uncertain {
                value: value_deg * DEG,
                sigma: sigma_deg * DEG,
            },
            alternative: Some((180.0 - value_deg) * DEG),
            ambiguous: true,
            ill_conditioned: false,
            determined,
            gyro_bias: Default::default(),
        }
    }

    /// "azimuth 147.106 +- 163.653" must read
    /// undetermined, with neither the estimate, its mirror nor an error
    /// shown as a number.
    #[test]
    fn an_undetermined_azimuth_is_not_shown_as_a_number() {
        let truth = Some(Euler::new(0.0, 0.0, 30.0 * DEG));
        let text = describe_heading(&estimate(147.106, 163.653, false), 1, truth, true);
        assert!(text.contains("azimuth undetermined"), "{text}");
        for number in ["147.1", "32.8", "117.1", "error +", "error -"] {
            assert!(!text.contains(number), "{number} in {text}");
        }
        let text = describe_heading(&estimate(147.106, 3.0, true), 1, truth, true);
        assert!(text.contains("147.106 +- 3.000 deg (1 sigma)"), "{text}");
    }

    /// With a prior given, the text does not ask for one.
    #[test]
    fn a_given_prior_is_not_asked_for() {
        let h = estimate(10.0, 3.0, true);
        let with = describe_heading(&h, 1, None, true);
        assert!(!with.contains("give --prior-heading"), "{with}");
        assert!(with.contains("the prior chose"), "{with}");
        let without = describe_heading(&h, 1, None, false);
        assert!(
            without.contains("give --prior-heading to choose"),
            "{without}"
        );
    }

    /// The report says how many samples were used and
    /// names every range left out with its reason.
    #[test]
    fn samples_left_out_are_reported() {
        let traj = one_toolface_turn();
        let mut recs = records(
            traj.clone(),
            SensorModel::scc1300(3),
            traj.scripted_duration(),
        );
        recs.truncate(recs.len() - 7);
        let config = AlignmentConfig::probe(traj.position.lat);
        let report = align_run(&recs, &config).expect("aligns");
        let text = report.render();
        let used: usize = report.spans.iter().map(|r| r.len()).sum();
        let left: usize = report.left_out.iter().map(|(r, _)| r.len()).sum();
        assert_eq!(used + left, recs.len(), "{text}");
        assert!(
            text.contains(&format!("Used {used} of {} samples", recs.len())),
            "{text}"
        );
        assert!(
            text.contains("left out samples") && text.contains("moving"),
            "{text}"
        );
        assert!(text.contains("fewer than a 1 s block"), "{text}");
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
