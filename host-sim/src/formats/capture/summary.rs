//! The summary `decode` and `replay` print of a capture: its loss
//! statistics, the time its raw samples span and the probe's station
//! surveys, gathered as the frames go by.

use std::fmt;

use mwd_core::protocol::frame::Payload;
use mwd_core::protocol::{DecoderStats, StationSurvey};

use super::items::Received;
use super::memory::Capture;

/// What `decode` and `replay` print of a capture: its loss statistics, the
/// time its raw samples span and the probe's station surveys, gathered as
/// the frames go by ([`note`](Self::note)).
#[derive(Debug, Clone, Default)]
pub struct CaptureSummary {
    /// Set by the owner at the end of the stream.
    pub stats: DecoderStats,
    /// The earliest and latest raw sample's time stamp, us.
    raw_span_us: Option<(u64, u64)>,
    /// The station survey frames, in order.
    pub stations: Vec<StationSurvey>,
}

impl CaptureSummary {
    /// Takes in one item of the capture.
    pub fn note(&mut self, received: Received) {
        let Received::Frame(frame) = received else {
            return;
        };
        match &frame.payload {
            Payload::Raw(r) => {
                let (first, last) = self.raw_span_us.unwrap_or((r.time_us, r.time_us));
                self.raw_span_us = Some((first.min(r.time_us), last.max(r.time_us)));
            }
            Payload::Station(st) => self.stations.push(*st),
            _ => {}
        }
    }

    /// The summary of a capture held in memory.
    pub fn of(capture: &Capture) -> Self {
        let mut summary = Self {
            stats: capture.stats,
            ..Self::default()
        };
        for frame in &capture.frames {
            summary.note(Received::Frame(frame));
        }
        summary
    }
}

impl fmt::Display for CaptureSummary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let s = &self.stats;
        let [raw, nav, event, station] = s.frames;
        writeln!(f, "bytes            {}", s.bytes)?;
        writeln!(
            f,
            "frames           {} good: raw sample {raw}, navigation {nav}, event {event}, \
             station survey {station}, unknown kind {}",
            s.good_frames(),
            s.unknown_kind
        )?;
        writeln!(
            f,
            "sequence gaps    {} frames lost, {} restarts, {} duplicated, {} reordered",
            s.lost, s.sequence_restarts, s.duplicated, s.reordered
        )?;
        writeln!(
            f,
            "corrupt          {} CRC failures, {} malformed ({} other version)",
            s.crc_errors, s.malformed, s.unsupported_version
        )?;
        write!(f, "garbage          {} bytes", s.garbage_bytes)?;
        if let Some((first, last)) = self.raw_span_us {
            write!(
                f,
                "\nraw samples span {:.3} s .. {:.3} s",
                first as f64 * 1e-6,
                last as f64 * 1e-6
            )?;
        }
        for st in &self.stations {
            write!(f, "\nprobe {}", crate::formats::display::station_text(st))?;
        }
        Ok(())
    }
}

impl fmt::Display for Capture {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        CaptureSummary::of(self).fmt(f)
    }
}
