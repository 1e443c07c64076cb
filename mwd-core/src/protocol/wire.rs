//! Framing on the UART: each body is COBS-encoded (so it holds no 0x00) and
//! sent between two 0x00 delimiters: `00 | cobs(body) | 00`.
//!
//! Why a delimiter on both sides: a bit error that turns a frame's closing
//! 0x00 into something else would otherwise merge it with the next frame and
//! lose both; with the next frame's own opening 0x00 only the hit frame is
//! lost. It costs one byte per frame. Receivers treat any run of 0x00 as one
//! separator. COBS comes from the `cobs` crate (no_std, no heap).

use super::bytes::OutOfRoom;
use super::codec::encode_body;
use super::frame::{Payload, MAX_BODY_LEN};

/// Delimiter between frames.
pub const DELIMITER: u8 = 0x00;

/// Bytes on the wire for a body of `body_len` bytes: COBS adds one byte per
/// started 254-byte block, plus the two delimiters.
pub const fn wire_len(body_len: usize) -> usize {
    cobs::max_encoding_length(body_len) + 2
}

/// The longest frame on the wire; size transmit buffers with it.
pub const MAX_WIRE_LEN: usize = wire_len(MAX_BODY_LEN);

/// Encodes one frame for the wire into `out`; returns the bytes written.
pub fn encode_frame(seq: u16, payload: &Payload, out: &mut [u8]) -> Result<usize, OutOfRoom> {
    let mut body = [0u8; MAX_BODY_LEN];
    let body_len = encode_body(seq, payload, &mut body)?;
    delimit_body(body.get(..body_len).ok_or(OutOfRoom)?, out)
}

/// COBS-encodes a sealed body between two delimiters into `out`; returns
/// the bytes written. The one framing step of both directions.
pub fn delimit_body(body: &[u8], out: &mut [u8]) -> Result<usize, OutOfRoom> {
    let (first, rest) = out.split_first_mut().ok_or(OutOfRoom)?;
    *first = DELIMITER;
    let encoded = cobs::try_encode(body, rest).map_err(|_| OutOfRoom)?;
    let last = rest.get_mut(encoded).ok_or(OutOfRoom)?;
    *last = DELIMITER;
    Ok(encoded + 2)
}

/// The probe's side: numbers frames consecutively (one counter across all
/// kinds, so the host sees every loss) and encodes them.
#[derive(Debug, Clone, Default)]
pub struct FrameEncoder {
    next_seq: u16,
}

impl FrameEncoder {
    pub const fn new() -> Self {
        Self { next_seq: 0 }
    }

    /// Starts numbering at `seq` (tests, or resuming a capture).
    pub const fn starting_at(seq: u16) -> Self {
        Self { next_seq: seq }
    }

    /// The sequence number the next frame will carry.
    pub fn next_seq(&self) -> u16 {
        self.next_seq
    }

    /// Encodes `payload` with the next sequence number into `out` and
    /// returns the bytes written. On error (buffer too small) the sequence
    /// number is not used up.
    pub fn encode(&mut self, payload: &Payload, out: &mut [u8]) -> Result<usize, OutOfRoom> {
        let n = encode_frame(self.next_seq, payload, out)?;
        self.next_seq = self.next_seq.wrapping_add(1);
        Ok(n)
    }
}

#[cfg(test)]
mod tests {
    use super::super::codec::decode_body;
    use super::super::frame::{FrameKind, NavSolution, RawSample};
    use super::*;

    #[test]
    fn wire_frames_are_delimited_and_zero_free_inside() {
        let mut enc = FrameEncoder::starting_at(0xFFFF);
        let mut out = [0u8; MAX_WIRE_LEN];
        let payload = Payload::Raw(RawSample::default());
        let n = enc.encode(&payload, &mut out).unwrap();
        assert_eq!(n, wire_len(FrameKind::RawSample.body_len()));
        assert_eq!(enc.next_seq(), 0, "sequence wraps");
        assert_eq!(out[0], 0);
        assert_eq!(out[n - 1], 0);
        assert!(out[1..n - 1].iter().all(|b| *b != 0));
        let mut inner = [0u8; MAX_WIRE_LEN];
        inner[..n - 2].copy_from_slice(&out[1..n - 1]);
        let len = cobs::decode_in_place(&mut inner[..n - 2]).unwrap();
        let frame = decode_body(&inner[..len]).unwrap();
        assert_eq!(frame.seq, 0xFFFF);
        assert_eq!(frame.payload, payload);
    }

    #[test]
    fn too_small_a_buffer_is_an_error_and_keeps_the_sequence() {
        let mut enc = FrameEncoder::new();
        let mut out = [0u8; 20];
        let payload = Payload::Nav(NavSolution::default());
        assert_eq!(enc.encode(&payload, &mut out), Err(OutOfRoom));
        assert_eq!(enc.next_seq(), 0);
    }
}
