//! The probe's answer to each command: downlink kind 5, an ACK or a NAK
//! with its reason, the command's sequence number and kind, and the
//! configuration's version after the command.
//!
//! Kind 5 joins the downlink by the compatibility rules of
//! `docs/protocol.md`: the version byte stays 1, its body (25 bytes, 26
//! encoded) is within the longest, and a decoder that predates it skips it
//! as an unknown kind and still counts its sequence number. It is kept out
//! of [`super::super::Payload`] so that the telemetry kinds' consumers are
//! unchanged; [`decode_reply_body`] reads it (the host finds the bodies the
//! telemetry decoder skipped with `Decoder::unknown_body`).

use super::super::bytes::{OutOfRoom, Reader, Writer};
use super::super::codec::{open_body, seal_body, FrameError};
use super::super::frame::{CRC_LEN, HEADER_LEN, PROTOCOL_VERSION};
use super::super::wire::{delimit_body, FrameEncoder};
use super::UplinkError;

/// The downlink kind byte of a reply.
pub const REPLY_KIND: u8 = 5;
/// time 8 + command seq 2 + command kind 1 + status 1 + detail 1 +
/// configuration version 4.
pub const REPLY_PAYLOAD_LEN: usize = 17;
pub const REPLY_BODY_LEN: usize = HEADER_LEN + REPLY_PAYLOAD_LEN + CRC_LEN;

/// Why a command was refused: the status byte of a NAK.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NakReason {
    /// Another protocol version.
    UnsupportedVersion,
    /// A kind byte the probe does not know.
    UnknownCommand,
    /// The wrong payload length for its kind.
    BadLength,
    /// A field out of its range; the detail byte is its `Field` code.
    OutOfRange,
    /// Not now: the probe is in a state that refuses it (a configuration
    /// change while surveying, a station while moving).
    Busy,
    /// The configuration could not be written to flash; the probe keeps
    /// the previous one.
    StorageFailed,
    /// Not yet: the navigation has not reached the state the command needs
    /// (still aligning, or not long enough to end the alignment).
    NotReady,
    /// A station was asked for while the probe is not still (moving, or
    /// still for less than the still detector's delay).
    NotStill,
    /// A code this decoder does not know (a newer probe's).
    Other(u8),
}

impl NakReason {
    pub fn to_byte(self) -> u8 {
        match self {
            Self::UnsupportedVersion => 1,
            Self::UnknownCommand => 2,
            Self::BadLength => 3,
            Self::OutOfRange => 4,
            Self::Busy => 5,
            Self::StorageFailed => 6,
            Self::NotReady => 7,
            Self::NotStill => 8,
            Self::Other(b) => b,
        }
    }

    /// `None` for 0, the ACK.
    pub fn from_byte(byte: u8) -> Option<Self> {
        Some(match byte {
            0 => return None,
            1 => Self::UnsupportedVersion,
            2 => Self::UnknownCommand,
            3 => Self::BadLength,
            4 => Self::OutOfRange,
            5 => Self::Busy,
            6 => Self::StorageFailed,
            7 => Self::NotReady,
            8 => Self::NotStill,
            b => Self::Other(b),
        })
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ReplyStatus {
    Ack,
    Nak(NakReason),
}

/// A reply (downlink kind 5).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Reply {
    /// The probe's clock when it answered (microseconds since boot).
    pub time_us: u64,
    /// The command's sequence number and kind byte.
    pub command_seq: u16,
    pub command_kind: u8,
    pub status: ReplyStatus,
    /// A NAK's detail: the `Field` code when out of range, else 0.
    pub detail: u8,
    /// The configuration record's version after the command (0: the
    /// defaults, never stored).
    pub config_version: u32,
}

impl Reply {
    pub fn ack(time_us: u64, command_seq: u16, command_kind: u8, config_version: u32) -> Self {
        Self {
            time_us,
            command_seq,
            command_kind,
            status: ReplyStatus::Ack,
            detail: 0,
            config_version,
        }
    }

    /// The NAK for a refused command, when its CRC held (otherwise its
    /// sequence number is not known and nothing is answered).
    pub fn for_error(error: &UplinkError, time_us: u64, config_version: u32) -> Option<Self> {
        let (command_seq, command_kind) = error.addressed()?;
        let (reason, detail) = match error {
            UplinkError::UnsupportedVersion { .. } => (NakReason::UnsupportedVersion, 0),
            UplinkError::UnknownCommand { .. } => (NakReason::UnknownCommand, 0),
            UplinkError::BadLength { .. } => (NakReason::BadLength, 0),
            UplinkError::OutOfRange { field, .. } => (NakReason::OutOfRange, *field as u8),
            UplinkError::TooShort | UplinkError::BadCrc => return None,
        };
        Some(Self {
            time_us,
            command_seq,
            command_kind,
            status: ReplyStatus::Nak(reason),
            detail,
            config_version,
        })
    }

    fn status_byte(&self) -> u8 {
        match self.status {
            ReplyStatus::Ack => 0,
            ReplyStatus::Nak(reason) => reason.to_byte(),
        }
    }
}

/// Writes a reply's body with downlink sequence number `seq` into `buf`.
pub fn encode_reply_body(seq: u16, reply: &Reply, buf: &mut [u8]) -> Result<usize, OutOfRoom> {
    let len = {
        let mut w = Writer::new(buf);
        w.u8(PROTOCOL_VERSION)?;
        w.u8(REPLY_KIND)?;
        w.u16(seq)?;
        w.u64(reply.time_us)?;
        w.u16(reply.command_seq)?;
        w.u8(reply.command_kind)?;
        w.u8(reply.status_byte())?;
        w.u8(reply.detail)?;
        w.u32(reply.config_version)?;
        w.len()
    };
    seal_body(buf, len)
}

/// Encodes a reply for the wire; the probe numbers it in its one downlink
/// sequence (`FrameEncoder::next_seq`).
pub fn encode_reply(seq: u16, reply: &Reply, out: &mut [u8]) -> Result<usize, OutOfRoom> {
    let mut body = [0u8; REPLY_BODY_LEN];
    let len = encode_reply_body(seq, reply, &mut body)?;
    delimit_body(body.get(..len).ok_or(OutOfRoom)?, out)
}

impl FrameEncoder {
    /// Encodes a reply with the next downlink sequence number (the one
    /// counter across all kinds, so the host counts every loss) and uses
    /// it up; on error (buffer too small) the number is not used up.
    pub fn encode_reply(&mut self, reply: &Reply, out: &mut [u8]) -> Result<usize, OutOfRoom> {
        let seq = self.next_seq();
        let n = encode_reply(seq, reply, out)?;
        *self = FrameEncoder::starting_at(seq.wrapping_add(1));
        Ok(n)
    }
}

/// Checks and parses a reply body: its downlink sequence number and the
/// reply. Other kinds are `UnknownKind`.
pub fn decode_reply_body(body: &[u8]) -> Result<(u16, Reply), FrameError> {
    let mut r = Reader::new(open_body(body)?);
    let version = r.u8()?;
    if version != PROTOCOL_VERSION {
        return Err(FrameError::UnsupportedVersion(version));
    }
    let kind = r.u8()?;
    let seq = r.u16()?;
    if kind != REPLY_KIND {
        return Err(FrameError::UnknownKind { kind, seq });
    }
    if r.remaining() != REPLY_PAYLOAD_LEN {
        return Err(FrameError::BadLength);
    }
    let time_us = r.u64()?;
    let command_seq = r.u16()?;
    let command_kind = r.u8()?;
    let status = match NakReason::from_byte(r.u8()?) {
        None => ReplyStatus::Ack,
        Some(reason) => ReplyStatus::Nak(reason),
    };
    Ok((
        seq,
        Reply {
            time_us,
            command_seq,
            command_kind,
            status,
            detail: r.u8()?,
            config_version: r.u32()?,
        },
    ))
}
