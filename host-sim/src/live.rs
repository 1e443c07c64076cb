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
//! is.

use mwd_core::calibration::ProbeCalibration;
use mwd_core::probe::Navigator;
use std::fmt;
use std::io::{self, ErrorKind, Read};
use std::time::{Duration, Instant};

use mwd_core::conventions::{DrillingAngles, Euler};
use mwd_core::earth::Position;
use mwd_core::protocol::frame::nav_mode;
use mwd_core::protocol::{Decoder, DecoderStats, Frame, NavSolution};

use crate::capture::Capture;
use crate::replay::{ReplayRow, ReplaySummary, Replayer};

/// Why a live replay stopped.
#[derive(Debug)]
pub enum StreamEnd {
    /// The source reported end of file.
    EndOfFile,
    /// The source failed; a closed pty or a vanished port lands here.
    Closed(io::Error),
    /// `--duration` elapsed.
    TimeLimit,
}

impl fmt::Display for StreamEnd {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::EndOfFile => write!(f, "end of file"),
            Self::Closed(e) => write!(f, "port closed ({e})"),
            Self::TimeLimit => write!(f, "time limit reached"),
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
        // Drilling terms come from the one module that owns the conventions.
        let drilling = DrillingAngles::from_euler(&Euler::new(roll, pitch, heading));
        let l = &self.link;
        write!(
            f,
            "t {:8.2} s {} | roll {:7.2} pitch {:7.2} hdg {:7.2} (+/-{:.2}) deg | \
             inc {:6.2} az {:6.2} tf {:6.2} deg | frames {} lost {} crc {} | parity {}/{}",
            s.time_us as f64 * 1e-6,
            mode_name(s.mode),
            deg(s.attitude[0]),
            deg(s.attitude[1]),
            deg(s.attitude[2]),
            deg(s.attitude_std[2]),
            drilling.inclination.to_degrees(),
            drilling.azimuth.to_degrees(),
            drilling.toolface.to_degrees(),
            l.good_frames(),
            l.lost,
            l.crc_errors,
            self.replay.matched,
            self.replay.matched + self.replay.mismatched,
        )
    }
}

/// The navigation mode as a short word for the display.
pub fn mode_name(mode: u8) -> &'static str {
    match mode {
        nav_mode::INITIALISING => "init  ",
        nav_mode::COARSE_ALIGNMENT => "coarse",
        nav_mode::FINE_ALIGNMENT => "fine  ",
        nav_mode::NAVIGATING => "nav   ",
        _ => "?     ",
    }
}

/// Settings of a live replay.
#[derive(Debug, Clone, Copy)]
pub struct LiveOptions {
    /// Stop after this long (wall clock) even if the stream goes on.
    pub duration: Option<Duration>,
    /// Shortest time between two status lines.
    pub display_interval: Duration,
    /// The probe's sensor calibration, for the replay (identity: none).
    pub calibration: ProbeCalibration,
}

impl Default for LiveOptions {
    fn default() -> Self {
        Self {
            duration: None,
            display_interval: Duration::from_millis(250),
            calibration: ProbeCalibration::default(),
        }
    }
}

/// The result of a live replay: as a file replay gives, and why it ended.
pub struct LiveOutcome {
    pub capture: Capture,
    pub rows: Vec<ReplayRow>,
    pub summary: ReplaySummary,
    pub end: StreamEnd,
}

/// Reads `source` until the stream ends, replaying every raw frame as it
/// arrives and calling `show` with the running status at most once per
/// `options.display_interval`.
pub fn run(
    mut source: impl Read,
    position: Position,
    options: LiveOptions,
    mut show: impl FnMut(&LiveStatus),
) -> LiveOutcome {
    let started = Instant::now();
    let mut last_shown: Option<Instant> = None;
    let mut decoder = Decoder::new();
    let mut replayer =
        Replayer::with_navigator(Navigator::with_calibration(position, options.calibration));
    let mut frames: Vec<Frame> = Vec::new();
    let mut latest: Option<NavSolution> = None;
    let mut buf = [0u8; 4096];
    let end = loop {
        if options.duration.is_some_and(|d| started.elapsed() >= d) {
            break StreamEnd::TimeLimit;
        }
        let n = match source.read(&mut buf) {
            Ok(0) => break StreamEnd::EndOfFile,
            Ok(n) => n,
            // A quiet line: keep waiting (and check the time limit).
            Err(e) if matches!(e.kind(), ErrorKind::TimedOut | ErrorKind::WouldBlock) => 0,
            Err(e) if e.kind() == ErrorKind::Interrupted => 0,
            Err(e) => break StreamEnd::Closed(e),
        };
        let first_new = frames.len();
        decoder.feed(&buf[..n], |frame| frames.push(frame));
        for frame in &frames[first_new..] {
            if let Some(solution) = replayer.push(frame) {
                latest = Some(solution);
            }
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
    decoder.finish();
    let stats = *decoder.stats();
    let (rows, summary) = replayer.finish();
    LiveOutcome {
        capture: Capture { frames, stats },
        rows,
        summary,
        end,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::capture::CaptureWriter;
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
        let outcome = run(source, Position::paper_site(), options, |s| {
            shown.push(s.to_string())
        });
        assert!(
            matches!(outcome.end, StreamEnd::Closed(_)),
            "{}",
            outcome.end
        );
        let whole = crate::capture::decode_bytes(&bytes);
        assert_eq!(outcome.capture.stats, whole.stats);
        assert_eq!(outcome.capture.stats.frames[0], 120);
        let (rows, summary) = replay::replay(&whole.frames, Position::paper_site());
        assert_eq!(outcome.summary, summary);
        assert_eq!(outcome.rows.len(), rows.len());
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
        let outcome = run(endless, Position::paper_site(), options, |_| {});
        assert!(matches!(outcome.end, StreamEnd::TimeLimit));
        assert_eq!(outcome.rows.len(), 0);
        assert!(outcome.capture.stats.bytes > 0);
    }
}
