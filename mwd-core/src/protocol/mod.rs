//! The probe's wire protocol (UART, 115200 baud 8N1), shared by the probe
//! and the host. `docs/protocol.md` gives the byte layout for decoders in
//! other languages, a worked example and the bandwidth budget.
//!
//! - [`frame`]: frame kinds and their fields; [`codec`]: their fixed
//!   little-endian layouts, version byte, sequence number, CRC-32C ([`crc`]).
//! - [`wire`]: COBS framing between 0x00 delimiters and the probe's
//!   [`FrameEncoder`].
//! - [`uplink`]: the host's commands to the probe and the probe's replies.
//! - [`decoder`]: the host's (or anyone's) streaming [`Decoder`], which
//!   resynchronises after garbage and counts lost and corrupt frames.
//!
//! No heap, no unsafe, no panics on received bytes.

pub mod bytes;
pub mod codec;
pub mod crc;
pub mod decoder;
pub mod example;
pub mod frame;
pub mod uplink;
pub mod wire;

pub use codec::{decode_body, encode_body, FrameError};
pub use decoder::{Decoder, DecoderStats};
pub use frame::{
    Event, EventKind, Frame, FrameKind, NavSolution, Payload, RawPart, RawSample, StationSurvey,
    PROTOCOL_VERSION,
};
pub use wire::{encode_frame, wire_len, FrameEncoder, MAX_WIRE_LEN};

/// UART payload rate at 115200 baud 8N1: 10 bit times per byte.
pub const UART_BYTES_PER_S: u32 = 115_200 / 10;
/// Raw and navigation frames per second each.
pub const FRAME_RATE_HZ: u32 = 20;

/// Wire bytes per second of one raw and one navigation frame at 20 Hz.
pub const fn cyclic_bytes_per_s() -> u32 {
    let per_cycle =
        wire_len(FrameKind::RawSample.body_len()) + wire_len(FrameKind::NavSolution.body_len());
    per_cycle as u32 * FRAME_RATE_HZ
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cyclic_frames_use_at_most_half_the_uart() {
        // 51 + 106 bytes per cycle, 3140 B/s of 11520 B/s = 27.3 %.
        assert_eq!(wire_len(FrameKind::RawSample.body_len()), 51);
        assert_eq!(wire_len(FrameKind::NavSolution.body_len()), 106);
        assert_eq!(cyclic_bytes_per_s(), 3140);
        assert!(2 * cyclic_bytes_per_s() <= UART_BYTES_PER_S);
    }
}
