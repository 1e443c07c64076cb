//! Streaming decoder: feed it bytes as they arrive (any chunking); it
//! returns frames and keeps counts of what it had to throw away.
//!
//! Resynchronisation needs no special state: every 0x00 ends a chunk, and a
//! chunk either decodes (COBS, CRC-32C, version, kind, length) or is
//! discarded whole. Garbage, a truncated frame or a bit flip therefore costs
//! the chunk it sits in and nothing after the next delimiter. Lost frames are
//! counted from gaps in the sequence numbers.

use super::frame::{decode_body, Frame, FrameError, MAX_BODY_LEN};
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
    /// navigation, event.
    pub frames: [u64; 3],
    /// Good frames with a kind this decoder does not know (newer probe).
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
    /// Times the sequence went backwards (probe restart or duplicate).
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
    expected_seq: Option<u16>,
    stats: DecoderStats,
}

impl Default for Decoder {
    fn default() -> Self {
        Self::new()
    }
}

/// Gaps of at least this size are taken as the sequence going backwards.
const BACKWARDS: u16 = 0x8000;

impl Decoder {
    pub const fn new() -> Self {
        Self {
            chunk: [0; MAX_CHUNK_LEN],
            len: 0,
            overflowed: false,
            expected_seq: None,
            stats: DecoderStats {
                frames: [0; 3],
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
                self.note_sequence(frame.seq);
                let index = frame.payload.kind().index();
                if let Some(count) = self.stats.frames.get_mut(index) {
                    *count += 1;
                }
                Some(frame)
            }
            Some(Err(FrameError::UnknownKind { seq, .. })) => {
                self.note_sequence(seq);
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

    fn note_sequence(&mut self, seq: u16) {
        if let Some(expected) = self.expected_seq {
            let gap = seq.wrapping_sub(expected);
            if gap >= BACKWARDS {
                self.stats.sequence_restarts += 1;
            } else {
                self.stats.lost += u64::from(gap);
            }
        }
        self.expected_seq = Some(seq.wrapping_add(1));
    }
}

#[cfg(test)]
mod tests {
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
            assert_eq!(dec.stats().frames, [0, 0, 8]);
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

    #[test]
    fn open_chunk_at_end_counts_as_garbage() {
        let mut dec = Decoder::new();
        dec.feed(&[1, 2, 3], |_| {});
        dec.finish();
        assert_eq!(dec.stats().garbage_bytes, 3);
        assert_eq!(dec.stats().malformed, 1);
    }
}
