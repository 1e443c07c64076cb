//! Live replay of the probe's UART stream (`host-sim replay --port`): bytes
//! are decoded as they arrive, each raw frame goes through the probe's
//! navigation code at once (`replay::Replayer`), and a one-line status is
//! shown at most a few times per second, the way an engineer watches a
//! probe on the bench. When the stream ends the caller gets the same
//! capture, rows and summary as a file replay.
//!
//! The source is any `Read`: a serial port (`serialport`), a pseudo-terminal
//! of QEMU's probe, or a test's byte slice. A read timeout is not the end of
//! the stream; end of file, a read error (a pty whose other side closed
//! reports EIO, a USB adapter pulled reports an I/O error) or the time limit
//! is, and so are a silence longer than `--silence`, SIGINT/SIGTERM and
//! `--duration`. The bytes (`--save`) and the replayed rows (`--csv`) are
//! written as they arrive, so an interrupted session keeps them.

use std::fmt;
use std::io::{self, ErrorKind, Read, Write};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use mwd_core::calibration::ProbeCalibration;
use mwd_core::config::default_still_settings;
use mwd_core::conventions::{DrillingAngles, Euler};
use mwd_core::earth::Position;
use mwd_core::probe::TieIn;
use mwd_core::protocol::uplink::StillSettings;
use mwd_core::protocol::{Decoder, DecoderStats, NavSolution};

use crate::formats::capture::CaptureSummary;
use crate::formats::display;
use crate::replay::replayer::Replayer;
use crate::replay::report::Replayed;
use crate::replay::rows::ReplaySummary;
use crate::replay::rows_csv::CSV_HEADER;

/// Why a live replay stopped.
#[derive(Debug)]
pub enum StreamEnd {
    /// The source reported end of file.
    EndOfFile,
    /// The source failed; a closed pty or a vanished port lands here.
    Closed(io::Error),
    /// `--duration` elapsed.
    TimeLimit,
    /// No byte for the silence limit.
    Silent(Duration),
    /// Asked to stop (SIGINT, SIGTERM).
    Interrupted,
    /// Writing the CSV or the saved bytes failed: what was written so far
    /// is kept.
    OutputFailed(io::Error),
}

impl fmt::Display for StreamEnd {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::EndOfFile => write!(f, "end of file"),
            Self::Closed(e) => write!(f, "port closed ({e})"),
            Self::TimeLimit => write!(f, "time limit reached"),
            Self::Silent(d) => write!(f, "no byte for {:.1} s", d.as_secs_f64()),
            Self::Interrupted => write!(f, "interrupted"),
            Self::OutputFailed(e) => write!(f, "writing output failed ({e})"),
        }
    }
}

/// What the running display shows: the latest replayed solution and the
/// link so far.
#[derive(Debug, Clone, Copy)]
pub struct LiveStatus {
    pub solution: NavSolution,
    pub link: DecoderStats,
    pub replay: ReplaySummary,
}

impl fmt::Display for LiveStatus {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let s = &self.solution;
        let deg = |a: f32| f64::from(a).to_degrees();
        let [roll, pitch, heading] = s.attitude.map(f64::from);
        // Drilling terms come from the one module that owns the conventions;
        // NaN (no estimate yet) stays NaN, an azimuth only shows when
        // determined (`display`).
        let drilling = DrillingAngles::from_euler(&Euler::new(roll, pitch, heading));
        let toolface = if roll.is_finite() {
            display::deg_0_360(roll)
        } else {
            f64::NAN
        };
        let azimuth = display::nav_azimuth_text(s, 2);
        let l = &self.link;
        write!(
            f,
            "t {:8.2} s {} | roll {:7.2} pitch {:7.2} deg | inc {:6.2} tf {:6.2} deg az {azimuth} | \
             frames {} lost {} crc {} restarts {} | parity {}/{}",
            s.time_us as f64 * 1e-6,
            display::mode_name(s.mode),
            deg(s.attitude[0]),
            deg(s.attitude[1]),
            drilling.inclination.to_degrees(),
            toolface,
            l.good_frames(),
            l.lost,
            l.crc_errors,
            l.sequence_restarts,
            self.replay.matched,
            self.replay.matched + self.replay.mismatched,
        )?;
        if self.replay.unchecked > 0 {
            write!(f, " ({} unchecked)", self.replay.unchecked)?;
        }
        Ok(())
    }
}

/// Settings of a live replay.
#[derive(Debug, Clone, Copy)]
pub struct LiveOptions {
    /// Stop after this long (wall clock) even if the stream goes on.
    pub duration: Option<Duration>,
    /// Stop when no byte came for this long, counted from the first byte
    /// (before it the replay waits: a probe may be powered up late).
    pub silence: Option<Duration>,
    /// Shortest time between two status lines.
    pub display_interval: Duration,
    /// The probe's sensor calibration, for the replay (identity: none).
    pub calibration: ProbeCalibration,
    /// The probe's still settings, for the replay (default: the constants).
    pub still: StillSettings,
    /// The probe's configured tie-in, for the replay (`Replayer::with_tie_in`).
    pub tie_in: Option<TieIn>,
}

impl Default for LiveOptions {
    fn default() -> Self {
        Self {
            duration: None,
            silence: None,
            display_interval: Duration::from_millis(250),
            calibration: ProbeCalibration::default(),
            still: default_still_settings(),
            tie_in: None,
        }
    }
}

/// Where a live replay writes as it goes: the bytes as they arrive
/// (`--save`) and the replayed rows as they settle (`--csv`, header
/// included), each flushed at once so that nothing is lost when the
/// session ends however it ends.
#[derive(Default)]
pub struct LiveSinks<'a> {
    pub save: Option<&'a mut dyn Write>,
    pub csv: Option<&'a mut dyn Write>,
    /// Set (by a signal handler) to end the session cleanly.
    pub stop: Option<&'a AtomicBool>,
}

/// The result of a live replay: what a file replay gives (its source
/// the port, its stations listed from the probe's frames only), and why
/// it ended. A session of any length keeps only this: the rows went to
/// the CSV sink as they settled.
pub struct LiveOutcome {
    pub replayed: Replayed,
    pub end: StreamEnd,
}

/// Reads `source` until the stream ends, replaying every raw frame as it
/// arrives, writing to `sinks` as it goes, and calling `show` with the
/// running status at most once per `options.display_interval`.
pub fn run(
    mut source: impl Read,
    position: Position,
    options: LiveOptions,
    mut sinks: LiveSinks<'_>,
    mut show: impl FnMut(&LiveStatus),
) -> LiveOutcome {
    let started = Instant::now();
    let mut last_byte: Option<Instant> = None;
    let mut last_shown: Option<Instant> = None;
    let mut decoder = Decoder::new();
    let mut replayer = Replayer::with_settings(position, options.calibration, options.still)
        .with_tie_in(options.tie_in);
    let mut capture = CaptureSummary::default();
    let mut latest: Option<NavSolution> = None;
    let mut buf = [0u8; 4096];
    if let Some(csv) = sinks.csv.as_mut() {
        if let Err(e) = writeln!(csv, "{}", CSV_HEADER).and_then(|()| csv.flush()) {
            return outcome(decoder, capture, replayer, StreamEnd::OutputFailed(e));
        }
    }
    let end = loop {
        if sinks.stop.is_some_and(|s| s.load(Ordering::Relaxed)) {
            break StreamEnd::Interrupted;
        }
        if options.duration.is_some_and(|d| started.elapsed() >= d) {
            break StreamEnd::TimeLimit;
        }
        if let (Some(limit), Some(t)) = (options.silence, last_byte) {
            if t.elapsed() >= limit {
                break StreamEnd::Silent(limit);
            }
        }
        let n = match source.read(&mut buf) {
            Ok(0) => break StreamEnd::EndOfFile,
            Ok(n) => n,
            // A quiet line: keep waiting (and check the limits).
            Err(e) if matches!(e.kind(), ErrorKind::TimedOut | ErrorKind::WouldBlock) => 0,
            Err(e) if e.kind() == ErrorKind::Interrupted => 0,
            Err(e) => break StreamEnd::Closed(e),
        };
        if n > 0 {
            last_byte = Some(Instant::now());
        }
        if let Some(save) = sinks.save.as_mut() {
            if let Err(e) = save.write_all(&buf[..n]).and_then(|()| save.flush()) {
                break StreamEnd::OutputFailed(e);
            }
        }
        crate::formats::capture::feed(&mut decoder, &buf[..n], |item| {
            capture.note(item.received());
            if let Some(solution) = replayer.push_received(item.received()) {
                latest = Some(solution);
            }
        });
        if let Err(e) = replayer.write_settled(sinks.csv.as_deref_mut(), false) {
            break StreamEnd::OutputFailed(e);
        }
        let due = last_shown.is_none_or(|t| t.elapsed() >= options.display_interval);
        if let (true, Some(solution)) = (due, latest) {
            show(&LiveStatus {
                solution,
                link: *decoder.stats(),
                replay: *replayer.summary(),
            });
            last_shown = Some(Instant::now());
        }
    };
    // Raw frames the replay held for their navigation frame are replayed.
    replayer.end_of_stream();
    let end = match replayer.write_settled(sinks.csv.as_deref_mut(), true) {
        Err(e) if !matches!(end, StreamEnd::OutputFailed(_)) => StreamEnd::OutputFailed(e),
        _ => end,
    };
    outcome(decoder, capture, replayer, end)
}

fn outcome(
    mut decoder: Decoder,
    mut capture: CaptureSummary,
    mut replayer: Replayer,
    end: StreamEnd,
) -> LiveOutcome {
    decoder.finish();
    capture.stats = *decoder.stats();
    replayer.end_of_stream();
    let step_losses = replayer.step_losses().to_vec();
    let commands = replayer.commands().to_vec();
    let rows = replayer.rows_replayed();
    let last_row = replayer.last_row().copied();
    let (_, summary) = replayer.finish();
    LiveOutcome {
        replayed: Replayed {
            // the stream's name is the caller's (a port, a pipe)
            source: String::new(),
            capture,
            rows,
            last_row,
            summary,
            step_losses,
            commands,
            stations: None,
        },
        end,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::formats::capture::CaptureWriter;
    use crate::replay;
    use mwd_core::protocol::frame::raw_flags;
    use mwd_core::protocol::{Payload, RawPart, RawSample};
    use mwd_core::sensor_units::{m_s2_to_accel_count, PART_MOUNTINGS, STANDARD_GRAVITY_M_S2};

    /// Hands out a byte stream in small pieces with a timeout between
    /// them, then fails the way a closed pty does.
    struct Trickle {
        bytes: Vec<u8>,
        at: usize,
        timed_out: bool,
    }

    impl Read for Trickle {
        fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
            self.timed_out = !self.timed_out;
            if self.timed_out {
                return Err(ErrorKind::TimedOut.into());
            }
            if self.at == self.bytes.len() {
                return Err(io::Error::from_raw_os_error(5));
            }
            let n = buf.len().min(37).min(self.bytes.len() - self.at);
            buf[..n].copy_from_slice(&self.bytes[self.at..self.at + n]);
            self.at += n;
            Ok(n)
        }
    }

    fn still_capture(samples: u32) -> Vec<u8> {
        let mut writer = CaptureWriter::new(Vec::new());
        for n in 0..samples {
            let parts = PART_MOUNTINGS.map(|m| RawPart {
                accel: m
                    .body_to_sensor([0.0, 0.0, STANDARD_GRAVITY_M_S2])
                    .map(m_s2_to_accel_count),
                flags: raw_flags::GYRO_VALID | raw_flags::ACCEL_VALID,
                ..RawPart::default()
            });
            let raw = RawSample {
                time_us: u64::from(n) * 50_000,
                sample_counter: n,
                parts,
            };
            writer.write(&Payload::Raw(raw)).unwrap();
        }
        writer.finish().unwrap()
    }

    #[test]
    fn a_trickled_stream_replays_like_the_whole_file_and_ends_on_close() {
        let bytes = still_capture(120);
        let source = Trickle {
            bytes: bytes.clone(),
            at: 0,
            timed_out: false,
        };
        let options = LiveOptions {
            duration: None,
            display_interval: Duration::ZERO,
            ..LiveOptions::default()
        };
        let mut shown = Vec::new();
        let outcome = run(
            source,
            Position::paper_site(),
            options,
            LiveSinks::default(),
            |s| shown.push(s.to_string()),
        );
        assert!(
            matches!(outcome.end, StreamEnd::Closed(_)),
            "{}",
            outcome.end
        );
        let whole = crate::formats::capture::decode_bytes(&bytes);
        assert_eq!(outcome.replayed.capture.stats, whole.stats);
        assert_eq!(outcome.replayed.capture.stats.frames[0], 120);
        let (rows, summary) = replay::replay(&whole.frames, Position::paper_site());
        assert_eq!(outcome.replayed.summary, summary);
        assert_eq!(outcome.replayed.rows, rows.len());
        let last = rows.last().map(|r| r.solution.sample_counter);
        assert_eq!(
            outcome.replayed.last_row.map(|r| r.solution.sample_counter),
            last
        );
        // Display lines carry the link figures; the last one saw every frame.
        let last = shown.last().expect("a status line");
        assert!(last.contains("frames 120 lost 0 crc 0"), "{last}");
        assert!(last.contains("inc "), "{last}");
    }

    #[test]
    fn a_time_limit_ends_a_stream_that_never_closes() {
        let endless = io::repeat(0u8);
        let options = LiveOptions {
            duration: Some(Duration::from_millis(50)),
            ..LiveOptions::default()
        };
        let outcome = run(
            endless,
            Position::paper_site(),
            options,
            LiveSinks::default(),
            |_| {},
        );
        assert!(matches!(outcome.end, StreamEnd::TimeLimit));
        assert_eq!(outcome.replayed.rows, 0);
        assert!(outcome.replayed.capture.stats.bytes > 0);
    }

    /// Hands out `bytes` in pieces, then stays silent (read timeouts) and
    /// sets `stop` after `stop_after` silent reads (a signal arriving).
    struct ThenSilent<'a> {
        bytes: Vec<u8>,
        at: usize,
        silent_reads: usize,
        stop_after: Option<(usize, &'a AtomicBool)>,
    }

    impl Read for ThenSilent<'_> {
        fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
            if self.at < self.bytes.len() {
                let n = buf.len().min(100).min(self.bytes.len() - self.at);
                buf[..n].copy_from_slice(&self.bytes[self.at..self.at + n]);
                self.at += n;
                return Ok(n);
            }
            self.silent_reads += 1;
            if let Some((after, stop)) = self.stop_after {
                if self.silent_reads >= after {
                    stop.store(true, Ordering::Relaxed);
                }
            }
            std::thread::sleep(Duration::from_millis(1));
            Err(ErrorKind::TimedOut.into())
        }
    }

    #[test]
    fn an_interrupt_ends_cleanly_with_every_row_and_byte_written() {
        let bytes = still_capture(150);
        let stop = AtomicBool::new(false);
        let source = ThenSilent {
            bytes: bytes.clone(),
            at: 0,
            silent_reads: 0,
            stop_after: Some((3, &stop)),
        };
        let (mut csv, mut saved) = (Vec::new(), Vec::new());
        let sinks = LiveSinks {
            save: Some(&mut saved),
            csv: Some(&mut csv),
            stop: Some(&stop),
        };
        let outcome = run(
            source,
            Position::paper_site(),
            LiveOptions::default(),
            sinks,
            |_| {},
        );
        assert!(
            matches!(outcome.end, StreamEnd::Interrupted),
            "{}",
            outcome.end
        );
        assert_eq!(saved, bytes);
        assert_eq!(outcome.replayed.rows, 150);
        let text = String::from_utf8(csv).unwrap();
        assert_eq!(text.lines().count(), 1 + 150);
        assert!(text.starts_with(replay::CSV_HEADER));
    }

    /// A sink that records what had been written when the source is read:
    /// rows must reach it while the stream goes on, not at its end.
    #[test]
    fn rows_are_written_while_the_stream_goes_on() {
        use std::sync::{Arc, Mutex};
        #[derive(Clone, Default)]
        struct Shared(Arc<Mutex<Vec<u8>>>);
        impl Write for Shared {
            fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
                self.0.lock().unwrap().extend_from_slice(buf);
                Ok(buf.len())
            }
            fn flush(&mut self) -> io::Result<()> {
                Ok(())
            }
        }
        struct Watching {
            inner: Trickle,
            csv: Shared,
            lines_seen: Vec<usize>,
        }
        impl Read for Watching {
            fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
                let lines = self
                    .csv
                    .0
                    .lock()
                    .unwrap()
                    .iter()
                    .filter(|b| **b == b'\n')
                    .count();
                self.lines_seen.push(lines);
                self.inner.read(buf)
            }
        }
        let csv = Shared::default();
        let mut watching = Watching {
            inner: Trickle {
                bytes: still_capture(200),
                at: 0,
                timed_out: false,
            },
            csv: csv.clone(),
            lines_seen: Vec::new(),
        };
        let mut sink = csv.clone();
        let sinks = LiveSinks {
            csv: Some(&mut sink),
            ..LiveSinks::default()
        };
        let outcome = run(
            &mut watching,
            Position::paper_site(),
            LiveOptions::default(),
            sinks,
            |_| {},
        );
        assert_eq!(outcome.replayed.rows, 200);
        // Without probe solutions to wait for, a row settles once 64 later
        // samples came: by the last read, all but those were written.
        let before_end = *watching.lines_seen.last().unwrap();
        assert!(before_end >= 1 + 200 - 65, "{before_end}");
        assert_eq!(
            csv.0
                .lock()
                .unwrap()
                .iter()
                .filter(|b| **b == b'\n')
                .count(),
            201
        );
    }

    #[test]
    fn a_silent_stream_ends_the_session() {
        let source = ThenSilent {
            bytes: still_capture(30),
            at: 0,
            silent_reads: 0,
            stop_after: None,
        };
        let options = LiveOptions {
            silence: Some(Duration::from_millis(30)),
            ..LiveOptions::default()
        };
        let outcome = run(
            source,
            Position::paper_site(),
            options,
            LiveSinks::default(),
            |_| {},
        );
        assert!(
            matches!(outcome.end, StreamEnd::Silent(_)),
            "{}",
            outcome.end
        );
        assert_eq!(outcome.replayed.rows, 30);
    }

    #[test]
    fn the_status_line_shows_placeholders_and_no_undetermined_azimuth() {
        let solution = NavSolution {
            attitude: [0.1, -0.2, -1.0],
            attitude_std: [0.01, 0.01, f32::INFINITY],
            ..NavSolution::default()
        };
        let status = LiveStatus {
            solution,
            link: DecoderStats::default(),
            replay: ReplaySummary::default(),
        };
        let line = status.to_string();
        assert!(line.contains("az undetermined |"), "{line}");
        assert!(!line.contains("-57.30"), "{line}");
        let mut lost = status;
        lost.solution.flags = mwd_core::protocol::frame::nav_flags::HEADING_LOST;
        let line = lost.to_string();
        assert!(
            line.contains("az undetermined (heading lost: needs a tie-in) |"),
            "{line}"
        );
        let mut coarse = status;
        coarse.solution.attitude = [f32::NAN; 3];
        coarse.solution.attitude_std = [f32::NAN; 3];
        let line = coarse.to_string();
        assert!(line.contains("az n/a"), "{line}");
        assert!(line.contains("roll     NaN"), "{line}");
        let mut determined = status;
        determined.solution.attitude_std[2] = 0.01;
        let line = determined.to_string();
        assert!(line.contains("az 302.70 +- 0.57 deg"), "{line}");
        assert!(line.contains("tf   5.73"), "{line}");
    }
}
