//! Streaming decoder: feed it bytes as they arrive (any chunking); it
//! returns frames and keeps counts of what it had to throw away.
//!
//! Resynchronisation needs no special state: every 0x00 ends a chunk, and a
//! chunk either decodes (COBS, CRC-32C, version, kind, length) or is
//! discarded whole. Garbage, a truncated frame or a bit flip therefore costs
//! the chunk it sits in and nothing after the next delimiter. Lost frames are
//! counted from gaps in the sequence numbers, runs (probe restarts) from
//! boot events, and a large gap is checked against the sample counters of
//! the raw and navigation frames around it; a frame received again is a
//! duplicate (dropped), one that comes late a reordered frame (its loss
//! taken back) (`docs/protocol.md`, "Losses").

mod recent;

use super::codec::{decode_body, FrameError};
use super::frame::{EventKind, Frame, FrameKind, Payload, MAX_BODY_LEN};
use super::wire::{wire_len, DELIMITER};
use crate::timing::SAMPLE_PERIOD_US;
use recent::{Behind, RecentFrames};

/// Largest chunk kept between delimiters: the longest valid encoded body.
/// A longer run of non-zero bytes cannot be a frame and is dropped.
pub const MAX_CHUNK_LEN: usize = wire_len(MAX_BODY_LEN) - 2;

/// What the decoder has seen. Corrupt chunks and lost frames are different
/// things: one corrupt chunk may hide several frames (garbage that swallowed
/// delimiters), and a frame may be lost without any corrupt byte (a UART
/// overrun that dropped it whole).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct DecoderStats {
    /// Good frames by kind, indexed by `FrameKind::index`: raw sample,
    /// navigation, event, station survey.
    pub frames: [u64; FrameKind::COUNT],
    /// Good frames with a kind this decoder does not know (newer probe),
    /// and the uplink's replies (kind 5: [`Decoder::unknown_body`]).
    pub unknown_kind: u64,
    /// Chunks whose CRC failed.
    pub crc_errors: u64,
    /// Chunks that were not valid COBS, too short, too long, of the wrong
    /// length for their kind, or of another protocol version.
    pub malformed: u64,
    /// Of those, chunks with a good CRC but another version.
    pub unsupported_version: u64,
    /// Frames missing according to sequence-number gaps (less those that
    /// came late: `reordered`).
    pub lost: u64,
    /// Frames received again, the same bytes with a number just received:
    /// dropped (not handed on, not in `frames`), neither a loss nor a
    /// restart.
    pub duplicated: u64,
    /// Frames that came after a later one, when they had been counted
    /// lost: handed on out of order, and no longer counted in `lost`.
    pub reordered: u64,
    /// Probe restarts: a boot event after other frames, or (its boot event
    /// lost) a sample counter or sequence that went backwards.
    pub sequence_restarts: u64,
    /// Bytes of all discarded chunks (garbage).
    pub garbage_bytes: u64,
    /// All bytes fed.
    pub bytes: u64,
}

impl DecoderStats {
    /// All good frames.
    pub fn good_frames(&self) -> u64 {
        self.frames.iter().sum::<u64>() + self.unknown_kind
    }

    /// Discarded chunks.
    pub fn corrupt(&self) -> u64 {
        self.crc_errors + self.malformed
    }
}

/// The streaming decoder. 336 bytes on the host, its 104-byte chunk buffer
/// and 14 counts among them: fits the probe as well as the host.
#[derive(Debug, Clone)]
pub struct Decoder {
    chunk: [u8; MAX_CHUNK_LEN],
    len: usize,
    /// The current chunk outgrew `chunk`: discard it at the next delimiter.
    overflowed: bool,
    /// Length of the body in `chunk` of a good frame of a kind this
    /// decoder does not know, until the next byte: [`Decoder::unknown_body`].
    unknown_body_len: Option<usize>,
    expected_seq: Option<u16>,
    /// The last few numbers up to `expected_seq - 1`: duplicates and
    /// reordered frames.
    recent: RecentFrames,
    /// The last raw or navigation frame of the current run, and what was
    /// counted since: the cross-check's anchor.
    last_counted: Option<Counted>,
    since_counted: SinceCounted,
    stats: DecoderStats,
}

/// A frame with a sample counter: its sequence number, counter and time.
#[derive(Debug, Clone, Copy)]
struct Counted {
    seq: u16,
    counter: u32,
    time_us: u64,
}

/// What the sequence rule counted since the last frame with a sample
/// counter, so that the next one's counter can correct it.
#[derive(Debug, Clone, Copy, Default)]
struct SinceCounted {
    good_frames: u64,
    lost: u64,
    restarts: u64,
}

impl Default for Decoder {
    fn default() -> Self {
        Self::new()
    }
}

/// Gaps of at least this size are taken as the sequence going backwards.
const BACKWARDS: u16 = 0x8000;

/// Frames lost between two frames with a sample counter (raw or
/// navigation) from which the count is checked against their counters: 64
/// frames, 1.6 s of the probe's traffic. Below it the sequence numbers
/// alone are exact unless the counters say the 16-bit sequence wrapped in
/// between (an outage of 65536 k + m frames, m < 64); above it the
/// sequence may have wrapped (an outage of more than 32767 frames) or the
/// probe restarted with its boot event lost.
const CROSS_CHECK_GAP: u64 = 64;

/// Frames the probe sends per sample: a raw and a navigation frame
/// (events are rare). Only used to count whole wraps of the sequence.
const FRAMES_PER_SAMPLE: u64 = 2;

impl Decoder {
    pub const fn new() -> Self {
        Self {
            chunk: [0; MAX_CHUNK_LEN],
            len: 0,
            overflowed: false,
            unknown_body_len: None,
            expected_seq: None,
            recent: RecentFrames::new(),
            last_counted: None,
            since_counted: SinceCounted {
                good_frames: 0,
                lost: 0,
                restarts: 0,
            },
            stats: DecoderStats {
                frames: [0; FrameKind::COUNT],
                unknown_kind: 0,
                crc_errors: 0,
                malformed: 0,
                unsupported_version: 0,
                lost: 0,
                duplicated: 0,
                reordered: 0,
                sequence_restarts: 0,
                garbage_bytes: 0,
                bytes: 0,
            },
        }
    }

    pub fn stats(&self) -> &DecoderStats {
        &self.stats
    }

    /// Feeds one byte; returns a frame when this byte completed a good one.
    pub fn push(&mut self, byte: u8) -> Option<Frame> {
        self.stats.bytes += 1;
        self.unknown_body_len = None;
        if byte != DELIMITER {
            match self.chunk.get_mut(self.len) {
                Some(slot) if !self.overflowed => {
                    *slot = byte;
                    self.len += 1;
                }
                _ => {
                    self.overflowed = true;
                    self.len = self.len.saturating_add(1);
                }
            }
            return None;
        }
        let frame = self.finish_chunk();
        self.len = 0;
        self.overflowed = false;
        frame
    }

    /// The body (CRC checked) of a good frame of a kind this decoder does
    /// not know, when the last byte pushed completed one: the uplink's
    /// replies (`uplink::reply::decode_reply_body`) are read from here.
    pub fn unknown_body(&self) -> Option<&[u8]> {
        self.chunk.get(..self.unknown_body_len?)
    }

    /// Feeds a slice, handing every good frame to `on_frame`.
    pub fn feed(&mut self, bytes: &[u8], mut on_frame: impl FnMut(Frame)) {
        for b in bytes {
            if let Some(frame) = self.push(*b) {
                on_frame(frame);
            }
        }
    }

    /// Counts a chunk left open at the end of a capture as garbage.
    pub fn finish(&mut self) {
        if self.len > 0 {
            self.discard(false);
            self.len = 0;
            self.overflowed = false;
        }
    }

    fn discard(&mut self, crc_error: bool) {
        if crc_error {
            self.stats.crc_errors += 1;
        } else {
            self.stats.malformed += 1;
        }
        self.stats.garbage_bytes += self.len as u64;
    }

    fn finish_chunk(&mut self) -> Option<Frame> {
        if self.len == 0 {
            return None; // Between two delimiters: nothing was sent.
        }
        if self.overflowed {
            self.discard(false);
            return None;
        }
        let Some(chunk) = self.chunk.get_mut(..self.len) else {
            self.discard(false);
            return None;
        };
        let Ok(body_len) = cobs::decode_in_place(chunk) else {
            self.discard(false);
            return None;
        };
        let result = chunk.get(..body_len).map(decode_body);
        let crc = body_crc(chunk, body_len);
        match result {
            Some(Ok(frame)) => {
                if !self.note_sequence(frame.seq, Some(&frame.payload), crc) {
                    return None;
                }
                let index = frame.payload.kind().index();
                if let Some(count) = self.stats.frames.get_mut(index) {
                    *count += 1;
                }
                Some(frame)
            }
            Some(Err(FrameError::UnknownKind { seq, .. })) => {
                if self.note_sequence(seq, None, crc) {
                    self.unknown_body_len = Some(body_len);
                    self.stats.unknown_kind += 1;
                }
                None
            }
            Some(Err(FrameError::BadCrc)) => {
                self.discard(true);
                None
            }
            Some(Err(FrameError::UnsupportedVersion(_))) => {
                self.stats.unsupported_version += 1;
                self.discard(false);
                None
            }
            Some(Err(FrameError::TooShort | FrameError::BadLength)) | None => {
                self.discard(false);
                None
            }
        }
    }

    /// The loss rule of `docs/protocol.md` ("Losses"): sequence gaps, a
    /// boot event starting a new run, gaps checked against the sample
    /// counters of the raw and navigation frames around them, and a frame
    /// just behind the newest told apart as a duplicate or a late one
    /// rather than a restart. Whether the frame is handed on: all but
    /// duplicates.
    fn note_sequence(&mut self, seq: u16, payload: Option<&Payload>, crc: u32) -> bool {
        // A boot event always starts a run: a probe that boots again soon
        // after sends the same bytes (number 0, time 0), and hiding a
        // restart as a duplicate would lose it.
        let starts_run = payload.is_some_and(|p| starts_a_run(seq, p));
        if let (Some(expected), false) = (self.expected_seq, starts_run) {
            match self.recent.behind(expected.wrapping_sub(1), seq, crc) {
                Some(Behind::Duplicate) => {
                    self.stats.duplicated += 1;
                    return false;
                }
                Some(Behind::Reordered) => {
                    self.take_back_loss(seq);
                    return true;
                }
                None => {}
            }
        }
        if starts_run {
            // The probe numbers its first frame, the boot event, 0: a new
            // run. What its previous run sent after the last frame seen
            // cannot be known.
            if self.expected_seq.is_some() {
                self.stats.sequence_restarts += 1;
            }
            self.expected_seq = Some(seq.wrapping_add(1));
            self.recent.advance(seq, crc, 0, true);
            self.last_counted = None;
            self.since_counted = SinceCounted::default();
            return true;
        }
        let mut skipped = 0;
        let mut unknown_before = true;
        if let Some(expected) = self.expected_seq {
            let gap = seq.wrapping_sub(expected);
            if gap >= BACKWARDS {
                self.stats.sequence_restarts += 1;
                self.since_counted.restarts += 1;
            } else {
                self.stats.lost += u64::from(gap);
                self.since_counted.lost += u64::from(gap);
                skipped = gap;
                unknown_before = false;
            }
        }
        self.expected_seq = Some(seq.wrapping_add(1));
        self.recent.advance(seq, crc, skipped, unknown_before);
        let (counter, time_us) = match payload {
            Some(Payload::Raw(raw)) => (raw.sample_counter, raw.time_us),
            Some(Payload::Nav(nav)) => (nav.sample_counter, nav.time_us),
            _ => {
                self.since_counted.good_frames += 1;
                return true;
            }
        };
        let counted = Counted {
            seq,
            counter,
            time_us,
        };
        if let Some(anchor) = self.last_counted {
            self.cross_check(anchor, counted);
        }
        self.last_counted = Some(counted);
        self.since_counted = SinceCounted::default();
        true
    }

    /// Checks what the sequence counted since the last frame with a sample
    /// counter (`anchor`: its number and counter) against this frame's
    /// counter, when frames were lost from [`CROSS_CHECK_GAP`] on, the
    /// sequence went backwards, or the counters say the sequence wrapped
    /// (with nothing else to show it: an outage of 65536 k + m frames, m
    /// under the gap) and the time stamps agree with them.
    fn cross_check(&mut self, anchor: Counted, now: Counted) {
        let since = self.since_counted;
        let (seq, counter) = (now.seq, now.counter);
        let advance = u64::from(seq.wrapping_sub(anchor.seq));
        let samples = counter.saturating_sub(anchor.counter);
        let by_counter = FRAMES_PER_SAMPLE * u64::from(samples);
        // Whole times the 16-bit sequence wrapped in between, as the
        // counters say (to the nearest: events add frames, the probe's own
        // skips take some away).
        let wraps = (by_counter.saturating_sub(advance) + 0x8000) / 0x1_0000;
        let wrapped = wraps > 0 && time_agrees(anchor.time_us, now.time_us, samples);
        if since.lost < CROSS_CHECK_GAP && since.restarts == 0 && !wrapped {
            return;
        }
        // Undo what the sequence alone said since the anchor.
        self.stats.lost = self.stats.lost.saturating_sub(since.lost);
        self.stats.sequence_restarts = self.stats.sequence_restarts.saturating_sub(since.restarts);
        let numbers = advance + wraps * 0x1_0000;
        if counter <= anchor.counter || numbers == 0 {
            // The sample counter went back (or stayed): a restart whose
            // boot event was lost; the frames lost around it cannot be
            // counted.
            self.stats.sequence_restarts += 1;
            self.recent.forget_lost();
        } else {
            // The same run: every number in between was sent.
            self.stats.lost += (numbers - 1).saturating_sub(since.good_frames);
        }
    }

    /// A frame counted lost came late: it is not lost after all.
    fn take_back_loss(&mut self, seq: u16) {
        self.stats.lost = self.stats.lost.saturating_sub(1);
        self.stats.reordered += 1;
        let after_anchor = self.last_counted.is_none_or(|anchor| {
            let after = seq.wrapping_sub(anchor.seq);
            after != 0 && after < BACKWARDS
        });
        if after_anchor {
            // Counted lost since the anchor: the next cross-check counts it
            // received.
            self.since_counted.lost = self.since_counted.lost.saturating_sub(1);
            self.since_counted.good_frames += 1;
        }
    }
}

/// Whether the time stamps `from_us` to `to_us` span `samples` sample
/// periods, give or take an eighth: the counters alone are not believed
/// to say that the sequence wrapped with no gap to show it.
fn time_agrees(from_us: u64, to_us: u64, samples: u32) -> bool {
    let expected = u64::from(samples) * SAMPLE_PERIOD_US;
    to_us
        .checked_sub(from_us)
        .is_some_and(|elapsed| elapsed.abs_diff(expected) <= expected / 8)
}

/// The CRC-32C that ends a frame's body (checked already): two frames with
/// the same number and CRC are taken as the same bytes.
fn body_crc(chunk: &[u8], body_len: usize) -> u32 {
    chunk
        .get(body_len.saturating_sub(4)..body_len)
        .and_then(|bytes| bytes.try_into().ok())
        .map_or(0, u32::from_le_bytes)
}

/// Whether a frame starts a probe run: a boot event numbered 0 and stamped
/// 0 us, the first frame a probe sends after it starts
/// (`firmware::app::SharedProbe::announce_boot`). The one rule for the
/// decoder's restarts and the host's replay.
pub fn starts_a_run(seq: u16, payload: &Payload) -> bool {
    matches!(payload, Payload::Event(e) if e.kind == EventKind::Boot && e.time_us == 0 && seq == 0)
}

#[cfg(test)]
mod tests;
