//! Streaming decoder: feed it bytes as they arrive (any chunking); it
//! returns frames and keeps counts of what it had to throw away.
//!
//! Resynchronisation needs no special state: every 0x00 ends a chunk, and a
//! chunk either decodes (COBS, CRC-32C, version, kind, length) or is
//! discarded whole. Garbage, a truncated frame or a bit flip therefore costs
//! the chunk it sits in and nothing after the next delimiter. Lost frames are
//! counted from gaps in the sequence numbers, runs (probe restarts) from
//! boot events, and a large gap is checked against the raw frames' sample
//! counters (`docs/protocol.md`, "Losses").

use super::codec::{decode_body, FrameError};
use super::frame::{EventKind, Frame, FrameKind, Payload, MAX_BODY_LEN};
use super::wire::{wire_len, DELIMITER};

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
    /// Frames missing according to sequence-number gaps.
    pub lost: u64,
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

/// The streaming decoder. About 140 bytes: fits the probe as well as the host.
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
    /// Sequence number and sample counter of the last raw frame of the
    /// current run, and what was counted since: the cross-check's anchor.
    last_raw: Option<(u16, u32)>,
    since_raw: SinceRaw,
    stats: DecoderStats,
}

/// What the sequence rule counted since the last raw frame, so that the
/// next raw frame's sample counter can correct it.
#[derive(Debug, Clone, Copy, Default)]
struct SinceRaw {
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

/// Frames lost between two raw frames from which the count is checked
/// against their sample counters: 64 frames, 1.6 s of the probe's traffic.
/// Below it the sequence numbers alone are exact; above it the 16-bit
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
            last_raw: None,
            since_raw: SinceRaw {
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
        match result {
            Some(Ok(frame)) => {
                self.note_sequence(frame.seq, Some(&frame.payload));
                let index = frame.payload.kind().index();
                if let Some(count) = self.stats.frames.get_mut(index) {
                    *count += 1;
                }
                Some(frame)
            }
            Some(Err(FrameError::UnknownKind { seq, .. })) => {
                self.unknown_body_len = Some(body_len);
                self.note_sequence(seq, None);
                self.stats.unknown_kind += 1;
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
    /// boot event starting a new run, large gaps checked against the sample
    /// counters of the raw frames around them.
    fn note_sequence(&mut self, seq: u16, payload: Option<&Payload>) {
        if payload.is_some_and(|p| starts_a_run(seq, p)) {
            // The probe numbers its first frame, the boot event, 0: a new
            // run. What its previous run sent after the last frame seen
            // cannot be known.
            if self.expected_seq.is_some() {
                self.stats.sequence_restarts += 1;
            }
            self.expected_seq = Some(seq.wrapping_add(1));
            self.last_raw = None;
            self.since_raw = SinceRaw::default();
            return;
        }
        if let Some(expected) = self.expected_seq {
            let gap = seq.wrapping_sub(expected);
            if gap >= BACKWARDS {
                self.stats.sequence_restarts += 1;
                self.since_raw.restarts += 1;
            } else {
                self.stats.lost += u64::from(gap);
                self.since_raw.lost += u64::from(gap);
            }
        }
        self.expected_seq = Some(seq.wrapping_add(1));
        let Some(Payload::Raw(raw)) = payload else {
            self.since_raw.good_frames += 1;
            return;
        };
        let counter = raw.sample_counter;
        if let Some((raw_seq, raw_counter)) = self.last_raw {
            let since = self.since_raw;
            if since.lost >= CROSS_CHECK_GAP || since.restarts > 0 {
                // Undo what the sequence alone said since the last raw frame.
                self.stats.lost -= since.lost;
                self.stats.sequence_restarts -= since.restarts;
                if counter <= raw_counter {
                    // The sample counter went back: a restart whose boot
                    // event was lost; the frames lost around it cannot be
                    // counted.
                    self.stats.sequence_restarts += 1;
                } else {
                    // The same run: the counter tells how many times the
                    // 16-bit sequence wrapped in between.
                    let advance = u64::from(seq.wrapping_sub(raw_seq));
                    let by_counter = FRAMES_PER_SAMPLE * u64::from(counter - raw_counter);
                    let wraps = (by_counter.saturating_sub(advance) + 0x8000) / 0x1_0000;
                    let sent_between = advance + wraps * 0x1_0000 - 1;
                    self.stats.lost += sent_between.saturating_sub(since.good_frames);
                }
            }
        }
        self.last_raw = Some((seq, counter));
        self.since_raw = SinceRaw::default();
    }
}

/// Whether a frame starts a probe run: a boot event numbered 0 and stamped
/// 0 us, the first frame a probe sends after it starts
/// (`firmware::app::SharedProbe::announce_boot`). The one rule for the
/// decoder's restarts and the host's replay.
pub fn starts_a_run(seq: u16, payload: &Payload) -> bool {
    matches!(payload, Payload::Event(e) if e.kind == EventKind::Boot && e.time_us == 0 && seq == 0)
}

#[cfg(test)]
mod tests {
    use super::super::example::boot_event;
    use super::super::frame::{Event, EventKind, Payload, NO_PART};
    use super::super::wire::{FrameEncoder, MAX_WIRE_LEN};
    use super::*;

    fn event(n: u32) -> Payload {
        Payload::Event(Event {
            time_us: u64::from(n) * 50_000,
            kind: EventKind::SensorFault,
            part: NO_PART,
            code: 3,
            value: n,
        })
    }

    fn encode_all(enc: &mut FrameEncoder, count: u32, out: &mut [u8]) -> usize {
        let mut n = 0;
        for i in 0..count {
            n += enc.encode(&event(i), &mut out[n..]).unwrap();
        }
        n
    }

    #[test]
    fn decodes_back_to_back_frames_in_any_chunking() {
        let mut stream = [0u8; 8 * MAX_WIRE_LEN];
        let n = encode_all(&mut FrameEncoder::new(), 8, &mut stream);
        for chunk in [1, 3, 7, 64, n] {
            let mut dec = Decoder::new();
            let mut seen = 0u32;
            for piece in stream[..n].chunks(chunk) {
                dec.feed(piece, |f| {
                    assert_eq!(f.payload, event(seen));
                    seen += 1;
                });
            }
            assert_eq!(seen, 8);
            assert_eq!(dec.stats().frames, [0, 0, 8, 0]);
            assert_eq!(dec.stats().corrupt(), 0);
            assert_eq!(dec.stats().lost, 0);
        }
    }

    #[test]
    fn resynchronises_after_garbage_and_truncation() {
        let mut stream = [0u8; 8 * MAX_WIRE_LEN];
        let n = encode_all(&mut FrameEncoder::new(), 3, &mut stream);
        let mut dec = Decoder::new();
        let mut got = 0;
        // Garbage first (no delimiter), then a frame cut after 10 bytes.
        dec.feed(&[0x55; 300], |_| got += 1);
        dec.feed(&stream[1..11], |_| got += 1);
        dec.feed(&stream[..n], |_| got += 1);
        assert_eq!(got, 3);
        let s = dec.stats();
        assert_eq!(
            s.malformed + s.crc_errors,
            1,
            "one chunk: garbage + cut frame"
        );
        assert_eq!(s.garbage_bytes, 310);
    }

    #[test]
    fn counts_sequence_gaps_and_restarts() {
        let mut buf = [0u8; MAX_WIRE_LEN];
        let mut dec = Decoder::new();
        for seq in [10u16, 11, 14, 15, 2, 3] {
            let n = super::super::wire::encode_frame(seq, &event(0), &mut buf).unwrap();
            dec.feed(&buf[..n], |_| {});
        }
        assert_eq!(dec.stats().lost, 2);
        assert_eq!(dec.stats().sequence_restarts, 1);
        assert_eq!(dec.stats().good_frames(), 6);
    }

    fn raw(counter: u32) -> Payload {
        Payload::Raw(super::super::frame::RawSample {
            sample_counter: counter,
            ..Default::default()
        })
    }

    /// Decodes frames given as (sequence number, payload).
    fn stats_of(frames: impl IntoIterator<Item = (u16, Payload)>) -> DecoderStats {
        let mut buf = [0u8; MAX_WIRE_LEN];
        let mut dec = Decoder::new();
        for (seq, payload) in frames {
            let n = super::super::wire::encode_frame(seq, &payload, &mut buf).unwrap();
            dec.feed(&buf[..n], |_| {});
        }
        *dec.stats()
    }

    /// A probe run: its boot event, then `samples` raw and navigation
    /// frames (the navigation ones stand in as events here), from `from`.
    fn run(samples: u32) -> impl Iterator<Item = (u16, Payload)> {
        core::iter::once((0, boot_event())).chain((0..samples).flat_map(|n| {
            let seq = (1 + 2 * n) as u16;
            [(seq, raw(n)), (seq.wrapping_add(1), event(n))]
        }))
    }

    #[test]
    fn a_reboot_after_a_long_run_is_a_restart_not_a_loss() {
        // 18000 samples (15 min, 36001 frames) twice, as `cat a.bin a.bin`.
        let stats = stats_of(run(18_000).chain(run(18_000)));
        assert_eq!((stats.lost, stats.sequence_restarts), (0, 1), "{stats:?}");
    }

    #[test]
    fn a_reboot_whose_boot_event_was_lost_is_found_by_the_sample_counter() {
        let stats = stats_of(run(18_000).chain(run(100).skip(1)));
        assert_eq!(stats.sequence_restarts, 1, "{stats:?}");
        assert_eq!(stats.lost, 0, "{stats:?}");
    }

    #[test]
    fn an_outage_longer_than_the_sequence_is_counted_from_the_sample_counter() {
        // 40000 samples (80000 frames, more than the 16-bit sequence) lost
        // after sample 100, then 5 % more lost in small gaps.
        let frames = run(50_000).filter(|(_, p)| match p {
            Payload::Raw(r) => !(101..40_101).contains(&r.sample_counter),
            Payload::Event(e) if e.kind != EventKind::Boot => !(101..40_101).contains(&e.value),
            _ => true,
        });
        let stats = stats_of(frames);
        assert_eq!(
            (stats.lost, stats.sequence_restarts),
            (80_000, 0),
            "{stats:?}"
        );
        // Small gaps stay exact without any raw frame to check them.
        let stats = stats_of(run(100).filter(|(seq, _)| seq % 20 != 7));
        assert_eq!((stats.lost, stats.sequence_restarts), (10, 0), "{stats:?}");
    }

    /// A kind this decoder does not know (a newer probe's) is skipped, not
    /// counted as corrupt, and its sequence number keeps the loss count
    /// exact: the rule that lets a version-1 decoder that predates kind 4
    /// (station survey) read a capture that holds them.
    #[test]
    fn an_unknown_kind_is_skipped_and_its_sequence_number_counted() {
        use super::super::crc::crc32c;
        let mut buf = [0u8; MAX_WIRE_LEN];
        let mut dec = Decoder::new();
        let mut seen = 0;
        for seq in 0..3u16 {
            let mut body = [0u8; MAX_BODY_LEN];
            let n = super::super::codec::encode_body(seq, &event(0), &mut body).unwrap();
            if seq == 1 {
                body[1] = 0x77;
                let crc = crc32c(&body[..n - 4]).to_le_bytes();
                body[n - 4..n].copy_from_slice(&crc);
            }
            buf[0] = 0;
            let len = cobs::try_encode(&body[..n], &mut buf[1..]).unwrap();
            buf[len + 1] = 0;
            dec.feed(&buf[..len + 2], |_| seen += 1);
        }
        let s = dec.stats();
        assert_eq!((seen, s.unknown_kind, s.lost, s.corrupt()), (2, 1, 0, 0));
    }

    #[test]
    fn a_station_survey_decodes_and_is_counted() {
        let mut buf = [0u8; MAX_WIRE_LEN];
        let station = super::super::example::station_survey();
        let n = super::super::wire::encode_frame(5, &station, &mut buf).unwrap();
        let mut dec = Decoder::new();
        let mut got = None;
        dec.feed(&buf[..n], |f| got = Some(f.payload));
        assert_eq!(got, Some(station));
        assert_eq!(dec.stats().frames, [0, 0, 0, 1]);
    }

    #[test]
    fn open_chunk_at_end_counts_as_garbage() {
        let mut dec = Decoder::new();
        dec.feed(&[1, 2, 3], |_| {});
        dec.finish();
        assert_eq!(dec.stats().garbage_bytes, 3);
        assert_eq!(dec.stats().malformed, 1);
    }
}
