//! What a replay reports, file or live: the capture's summary, the parity
//! of the replayed solutions and station surveys with the probe's, the
//! uplink commands, where the replay went out of step, the last attitude;
//! and the verdict the exit status tells (`host-sim replay --help`).

use crate::formats::capture::CaptureSummary;
use crate::formats::display;
use crate::replay::commands::CommandRow;
use crate::replay::{ReplayRow, ReplaySummary, StationRow, StationSummary, StepLoss};
use std::fmt::Write as _;
use std::path::Path;

/// What a replay reports: the rows themselves went to `--csv` as they
/// settled, so a capture of any length keeps only this.
pub struct Replayed {
    /// Where the capture came from (the file, or the serial port).
    pub source: String,
    pub capture: CaptureSummary,
    /// How many rows the replay made, and the newest.
    pub rows: usize,
    pub last_row: Option<ReplayRow>,
    pub summary: ReplaySummary,
    pub step_losses: Vec<StepLoss>,
    /// The replies to uplink commands and what the replay did with each.
    pub commands: Vec<CommandRow>,
    /// Replayed station surveys and their comparison; `None` for a live
    /// session (its stations are listed from the probe's frames only).
    pub stations: Option<(Vec<StationRow>, StationSummary)>,
}

/// How the replay compares with the probe, worst first.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// Replayed solutions, station surveys, commands or navigation modes
    /// differ from the probe's.
    Different,
    /// Everything compared was identical, but some of the probe's could
    /// not be compared.
    Incomplete,
    /// Everything compared was identical and nothing left unchecked (or
    /// the replay was post-processed: differences are then expected).
    Parity,
}

/// The report's text (standard output), the verdict, and what to say
/// about it on standard error (a difference is an error, an incomplete
/// comparison a warning).
pub struct ReplayReport {
    pub text: String,
    pub verdict: Verdict,
    pub note: Option<String>,
}

impl Replayed {
    /// The summary both modes end with, the CSV written to `csv` (if any)
    /// and the verdict. A replay `post_processed` with another calibration
    /// or site than the probe's is not a parity check: its verdict is
    /// parity.
    pub fn report(&self, csv: Option<&Path>, post_processed: bool) -> ReplayReport {
        let summary = &self.summary;
        let mut text = self.parity_text();
        let (stations_differ, stations_unchecked) = self.stations_text(&mut text);
        if let Some(last) = &self.last_row {
            let s = &last.solution;
            let [r, p, h] = s.attitude.map(f64::from);
            let _ = writeln!(
                text,
                "last attitude    roll {:.3} pitch {:.3} deg, azimuth {}",
                r.to_degrees(),
                p.to_degrees(),
                display::azimuth_text(h, f64::from(s.attitude_std[2]), 2)
            );
        }
        if let Some(out) = csv {
            let _ = writeln!(
                text,
                "csv              {} ({} rows)",
                out.display(),
                self.rows
            );
        }
        if post_processed && (summary.mismatched > 0 || stations_differ > 0) {
            text += "post-processed   with another calibration or site than the probe's \
                     defaults: differences from the probe's solutions are expected, not a \
                     parity failure\n";
        }
        let (verdict, note) = self.verdict(stations_differ, stations_unchecked, post_processed);
        ReplayReport {
            text,
            verdict,
            note,
        }
    }

    /// The verdict of a parity check and what to say about it, given how
    /// many station surveys differ and how many could not be compared; a
    /// replay `post_processed` has no differences (they are expected) but
    /// is incomplete when frames were lost.
    fn verdict(
        &self,
        stations_differ: u64,
        stations_unchecked: u64,
        post_processed: bool,
    ) -> (Verdict, Option<String>) {
        let summary = &self.summary;
        let lost = self.capture.stats.lost;
        let differences = self
            .step_losses
            .iter()
            .filter(|l| l.reason.is_a_difference())
            .count();
        if !post_processed && (summary.mismatched > 0 || stations_differ > 0 || differences > 0) {
            let note = format!(
                "{} replayed solutions and {stations_differ} station surveys differ from the \
                 probe's; {differences} commands or navigation modes differ (see \"out of step\")",
                summary.mismatched
            );
            return (Verdict::Different, Some(note));
        }
        if lost > 0 {
            let note = format!(
                "{lost} frames lost in the capture could not be compared; {} probe solutions and \
                 {stations_unchecked} probe station surveys could not be compared either",
                summary.unchecked
            );
            return (Verdict::Incomplete, Some(note));
        }
        if post_processed {
            // What was not compared is out of step with another
            // calibration or site: expected, as the differences are.
            return (Verdict::Parity, None);
        }
        if stations_unchecked > 0 {
            let note = format!("{stations_unchecked} probe station surveys could not be compared");
            return (Verdict::Incomplete, Some(note));
        }
        if summary.unchecked > 0 || !self.step_losses.is_empty() {
            let note = format!(
                "{} probe solutions could not be compared (see \"out of step\")",
                summary.unchecked
            );
            return (Verdict::Incomplete, Some(note));
        }
        (Verdict::Parity, None)
    }

    /// The capture, the solutions' parity, the commands and the losses of
    /// step.
    fn parity_text(&self) -> String {
        let summary = &self.summary;
        let mut text = String::new();
        let _ = writeln!(text, "capture          {}", self.source);
        let _ = writeln!(text, "{}", self.capture);
        let _ = writeln!(text, "raw frames       {}", summary.raw_frames);
        let _ = writeln!(text, "degraded samples {}", summary.degraded);
        let _ = writeln!(text, "probe solutions  {}", summary.probe_solutions);
        let _ = writeln!(
            text,
            "probe restarts   {} (the replay restarted with it)",
            summary.restarts
        );
        let lost = self.capture.stats.lost;
        let _ = writeln!(
            text,
            "replay parity    {} identical, {} different, {} not compared{}",
            summary.matched,
            summary.mismatched,
            summary.unchecked + lost,
            if lost > 0 {
                format!(" ({lost} of them frames lost in the capture)")
            } else {
                String::new()
            }
        );
        for command in &self.commands {
            let _ = writeln!(text, "uplink           {command}");
        }
        for loss in &self.step_losses {
            let _ = writeln!(text, "out of step      {loss}");
        }
        text
    }

    /// The stations' parity, each replayed station; returns how many
    /// differ and how many could not be compared.
    fn stations_text(&self, text: &mut String) -> (u64, u64) {
        let Some((rows, s)) = &self.stations else {
            text.push_str(
                "station parity   not replayed live (the probe's stations are listed above)\n",
            );
            return (0, 0);
        };
        let _ = writeln!(
            text,
            "station parity   {} replayed, {} from the probe: {} identical, {} different, \
             {} not compared",
            s.replayed, s.probe, s.matched, s.mismatched, s.unchecked
        );
        for row in rows {
            let parity = match (row.in_step, row.matches_probe) {
                (false, _) => "not compared",
                (true, Some(true)) => "identical to the probe's",
                (true, Some(false)) => "DIFFERENT from the probe's",
                (true, None) => "no probe frame",
            };
            let _ = writeln!(
                text,
                "replayed {} [{parity}]",
                display::station_text(&row.station)
            );
        }
        (s.mismatched, s.unchecked)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn replayed(summary: ReplaySummary, stations: Option<StationSummary>) -> Replayed {
        Replayed {
            source: "run.bin".into(),
            capture: CaptureSummary::default(),
            rows: 0,
            last_row: None,
            summary,
            step_losses: Vec::new(),
            commands: Vec::new(),
            stations: stations.map(|s| (Vec::new(), s)),
        }
    }

    #[test]
    fn identical_and_complete_is_parity() {
        let r = replayed(ReplaySummary::default(), Some(StationSummary::default()));
        let report = r.report(None, false);
        assert_eq!(report.verdict, Verdict::Parity);
        assert!(report.note.is_none());
        assert!(report.text.starts_with("capture          run.bin\n"));
        assert!(report.text.contains("station parity   0 replayed"));
    }

    #[test]
    fn differences_come_before_what_was_not_compared() {
        let summary = ReplaySummary {
            mismatched: 2,
            unchecked: 5,
            ..ReplaySummary::default()
        };
        let report = replayed(summary, None).report(Some(Path::new("out.csv")), false);
        assert_eq!(report.verdict, Verdict::Different);
        assert!(report
            .note
            .is_some_and(|n| n.starts_with("2 replayed solutions")));
        assert!(report.text.contains("not replayed live"));
        assert!(report.text.ends_with("csv              out.csv (0 rows)\n"));
    }

    #[test]
    fn stations_not_compared_are_incomplete() {
        let stations = StationSummary {
            unchecked: 1,
            ..StationSummary::default()
        };
        let report = replayed(ReplaySummary::default(), Some(stations)).report(None, false);
        assert_eq!(report.verdict, Verdict::Incomplete);
        assert_eq!(
            report.note.as_deref(),
            Some("1 probe station surveys could not be compared")
        );
    }

    #[test]
    fn frames_lost_are_counted_as_not_compared_and_incomplete_even_post_processed() {
        let mut r = replayed(ReplaySummary::default(), Some(StationSummary::default()));
        r.capture.stats.lost = 2;
        for post_processed in [false, true] {
            let report = r.report(None, post_processed);
            assert_eq!(report.verdict, Verdict::Incomplete, "{post_processed}");
            assert!(report
                .text
                .contains("0 identical, 0 different, 2 not compared (2 of them frames lost"));
            assert!(report
                .note
                .is_some_and(|n| n.starts_with("2 frames lost in the capture")));
        }
    }

    #[test]
    fn post_processing_is_never_a_parity_failure() {
        let summary = ReplaySummary {
            mismatched: 1,
            ..ReplaySummary::default()
        };
        let report = replayed(summary, None).report(None, true);
        assert_eq!(report.verdict, Verdict::Parity);
        assert!(report.note.is_none());
        assert!(report
            .text
            .contains("post-processed   with another calibration"));
    }
}
