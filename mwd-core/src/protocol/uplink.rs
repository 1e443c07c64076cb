//! The uplink: commands from the host to the probe, in the downlink's
//! framing (`0x00 | COBS(body) | 0x00`, body `version | kind | seq |
//! payload | CRC-32C`, [`super::codec`]), and the probe's answer to each,
//! an ACK or a NAK on the downlink ([`reply`]). Byte tables and worked
//! examples: `docs/protocol.md`, "Uplink".
//!
//! Command kinds are 0x40..=0x4A, apart from the downlink's kinds (1..=5),
//! so that an echo of a command on a shared or looped-back line is never
//! taken for a probe frame: a downlink decoder skips it as an unknown kind.
//! Every field is range-checked on decoding ([`fields`]); an error names
//! what was wrong and, once the CRC has held, the command's sequence
//! number and kind, for its NAK.

pub mod fields;
pub mod reply;

pub use fields::{Field, IndexingProcedure, StillSettings};
pub use reply::{NakReason, Reply, ReplyStatus, REPLY_KIND};

use super::bytes::{OutOfRoom, Reader, Writer};
use super::codec::{open_body, seal_body, FrameError};
use super::frame::{CRC_LEN, HEADER_LEN, PROTOCOL_VERSION};
use super::wire::{delimit_body, wire_len};
use crate::calibration::{GyroCalibration, TriadCalibration};
use crate::conventions::DrillingAngles;
use crate::earth::Position;
use fields::ReadError;

/// Kind byte of each command.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u8)]
pub enum CommandKind {
    SetSite = 0x40,
    SetTieIn = 0x41,
    ClearTieIn = 0x42,
    SetCalibration = 0x43,
    SetStillSettings = 0x44,
    Realign = 0x45,
    StartSurveying = 0x46,
    TakeStation = 0x47,
    IndexToolface = 0x48,
    ReportConfig = 0x49,
    Reboot = 0x4A,
}

impl CommandKind {
    pub const ALL: [CommandKind; 11] = [
        Self::SetSite,
        Self::SetTieIn,
        Self::ClearTieIn,
        Self::SetCalibration,
        Self::SetStillSettings,
        Self::Realign,
        Self::StartSurveying,
        Self::TakeStation,
        Self::IndexToolface,
        Self::ReportConfig,
        Self::Reboot,
    ];

    pub fn from_byte(byte: u8) -> Option<Self> {
        Self::ALL.into_iter().find(|k| *k as u8 == byte)
    }

    /// Payload length (fixed per kind).
    pub const fn payload_len(self) -> usize {
        match self {
            Self::SetSite => fields::SITE_LEN,
            Self::SetTieIn => fields::TIE_IN_LEN,
            Self::SetCalibration => 1 + fields::PART_CALIBRATION_LEN,
            Self::SetStillSettings => fields::STILL_SETTINGS_LEN,
            Self::IndexToolface => fields::INDEXING_LEN,
            Self::ClearTieIn
            | Self::Realign
            | Self::StartSurveying
            | Self::TakeStation
            | Self::ReportConfig
            | Self::Reboot => 0,
        }
    }

    pub const fn body_len(self) -> usize {
        HEADER_LEN + self.payload_len() + CRC_LEN
    }
}

/// The longest command body: a part's calibration, 121 bytes.
pub const MAX_COMMAND_BODY_LEN: usize = CommandKind::SetCalibration.body_len();
/// The longest command on the wire; size receive buffers with it.
pub const MAX_COMMAND_WIRE_LEN: usize = wire_len(MAX_COMMAND_BODY_LEN);

/// What the host asks of the probe.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Command {
    /// The site the probe aligns at (geodetic, rad and m).
    SetSite(Position),
    /// Start from a tie-in instead of the static alignment: the parent
    /// well's survey angles and their 1-sigma (rad).
    SetTieIn {
        angles: DrillingAngles,
        sigma: DrillingAngles,
    },
    /// Back to the static alignment.
    ClearTieIn,
    /// One part's six-position calibration (`calibration::ProbeCalibration`):
    /// part 0 the x-gyro part, 1 the z-gyro part.
    SetCalibration {
        part: u8,
        accel: TriadCalibration,
        gyro: GyroCalibration,
    },
    SetStillSettings(StillSettings),
    /// Align again (the probe must be still).
    Realign,
    /// Leave the alignment for navigation with station surveys (drilling).
    StartSurveying,
    /// Take a station survey now (the probe must be still).
    TakeStation,
    /// Begin the guided toolface-indexing procedure.
    IndexToolface(IndexingProcedure),
    /// Answer with the configuration's version (and, later, its contents).
    ReportConfig,
    Reboot,
}

impl Command {
    pub fn kind(&self) -> CommandKind {
        match self {
            Self::SetSite(_) => CommandKind::SetSite,
            Self::SetTieIn { .. } => CommandKind::SetTieIn,
            Self::ClearTieIn => CommandKind::ClearTieIn,
            Self::SetCalibration { .. } => CommandKind::SetCalibration,
            Self::SetStillSettings(_) => CommandKind::SetStillSettings,
            Self::Realign => CommandKind::Realign,
            Self::StartSurveying => CommandKind::StartSurveying,
            Self::TakeStation => CommandKind::TakeStation,
            Self::IndexToolface(_) => CommandKind::IndexToolface,
            Self::ReportConfig => CommandKind::ReportConfig,
            Self::Reboot => CommandKind::Reboot,
        }
    }
}

/// A decoded command and the sequence number its reply quotes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Received {
    pub seq: u16,
    pub command: Command,
}

/// Why a command body was refused. From `UnsupportedVersion` on the CRC
/// held, so the sequence number and kind byte are the host's and a NAK
/// can quote them ([`UplinkError::addressed`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum UplinkError {
    /// Shorter than a header and its CRC.
    TooShort,
    BadCrc,
    UnsupportedVersion {
        version: u8,
        seq: u16,
        kind: u8,
    },
    UnknownCommand {
        seq: u16,
        kind: u8,
    },
    /// A known command with the wrong payload length for it.
    BadLength {
        seq: u16,
        kind: u8,
    },
    OutOfRange {
        seq: u16,
        kind: u8,
        field: Field,
    },
}

impl UplinkError {
    /// The sequence number and kind byte of a command whose CRC held.
    pub fn addressed(&self) -> Option<(u16, u8)> {
        match *self {
            Self::TooShort | Self::BadCrc => None,
            Self::UnsupportedVersion { seq, kind, .. }
            | Self::UnknownCommand { seq, kind }
            | Self::BadLength { seq, kind }
            | Self::OutOfRange { seq, kind, .. } => Some((seq, kind)),
        }
    }
}

impl core::fmt::Display for UplinkError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::TooShort => f.write_str("the command is shorter than a header and its CRC"),
            Self::BadCrc => f.write_str("the command's CRC does not match its contents"),
            Self::UnsupportedVersion { version, seq, .. } => write!(
                f,
                "command {seq} is of protocol version {version}; the probe reads version {PROTOCOL_VERSION}"
            ),
            Self::UnknownCommand { seq, kind } => {
                write!(f, "command {seq} is of an unknown kind ({kind:#04x})")
            }
            Self::BadLength { seq, kind } => {
                write!(f, "command {seq} (kind {kind:#04x}) has the wrong length for its kind")
            }
            Self::OutOfRange { seq, field, .. } => {
                write!(f, "command {seq}: the {} is out of its range", field.name())
            }
        }
    }
}

impl core::error::Error for UplinkError {}

fn write_command(w: &mut Writer, command: &Command) -> Result<(), OutOfRoom> {
    match command {
        Command::SetSite(site) => fields::write_site(w, site),
        Command::SetTieIn { angles, sigma } => fields::write_tie_in(w, angles, sigma),
        Command::SetCalibration { part, accel, gyro } => {
            w.u8(*part)?;
            fields::write_part_calibration(w, accel, gyro)
        }
        Command::SetStillSettings(s) => fields::write_still_settings(w, s),
        Command::IndexToolface(p) => fields::write_indexing(w, p),
        Command::ClearTieIn
        | Command::Realign
        | Command::StartSurveying
        | Command::TakeStation
        | Command::ReportConfig
        | Command::Reboot => Ok(()),
    }
}

fn read_command(kind: CommandKind, r: &mut Reader) -> Result<Command, ReadError> {
    Ok(match kind {
        CommandKind::SetSite => Command::SetSite(fields::read_site(r)?),
        CommandKind::SetTieIn => {
            let (angles, sigma) = fields::read_tie_in(r)?;
            Command::SetTieIn { angles, sigma }
        }
        CommandKind::ClearTieIn => Command::ClearTieIn,
        CommandKind::SetCalibration => {
            let part = r.u8()?;
            if part > 1 {
                return Err(ReadError::OutOfRange(Field::Part));
            }
            let (accel, gyro) = fields::read_part_calibration(r)?;
            Command::SetCalibration { part, accel, gyro }
        }
        CommandKind::SetStillSettings => Command::SetStillSettings(fields::read_still_settings(r)?),
        CommandKind::Realign => Command::Realign,
        CommandKind::StartSurveying => Command::StartSurveying,
        CommandKind::TakeStation => Command::TakeStation,
        CommandKind::IndexToolface => Command::IndexToolface(fields::read_indexing(r)?),
        CommandKind::ReportConfig => Command::ReportConfig,
        CommandKind::Reboot => Command::Reboot,
    })
}

/// Writes a command's body (header, payload, CRC) into `buf`; returns its
/// length, [`CommandKind::body_len`].
pub fn encode_command_body(
    seq: u16,
    command: &Command,
    buf: &mut [u8],
) -> Result<usize, OutOfRoom> {
    let len = {
        let mut w = Writer::new(buf);
        w.u8(PROTOCOL_VERSION)?;
        w.u8(command.kind() as u8)?;
        w.u16(seq)?;
        write_command(&mut w, command)?;
        w.len()
    };
    seal_body(buf, len)
}

/// Encodes a command for the wire (delimiters and COBS) into `out`;
/// returns the bytes written. The host's side.
pub fn encode_command(seq: u16, command: &Command, out: &mut [u8]) -> Result<usize, OutOfRoom> {
    let mut body = [0u8; MAX_COMMAND_BODY_LEN];
    let len = encode_command_body(seq, command, &mut body)?;
    delimit_body(body.get(..len).ok_or(OutOfRoom)?, out)
}

/// Checks and parses a command body (COBS already removed): length, CRC,
/// version, kind, payload length, then every field's range.
pub fn decode_command(body: &[u8]) -> Result<Received, UplinkError> {
    let covered = open_body(body).map_err(|e| match e {
        FrameError::BadCrc => UplinkError::BadCrc,
        _ => UplinkError::TooShort,
    })?;
    let mut r = Reader::new(covered);
    let header = (r.u8(), r.u8(), r.u16());
    let (Ok(version), Ok(kind_byte), Ok(seq)) = header else {
        return Err(UplinkError::TooShort);
    };
    if version != PROTOCOL_VERSION {
        return Err(UplinkError::UnsupportedVersion {
            version,
            seq,
            kind: kind_byte,
        });
    }
    let kind = CommandKind::from_byte(kind_byte).ok_or(UplinkError::UnknownCommand {
        seq,
        kind: kind_byte,
    })?;
    let bad_length = UplinkError::BadLength {
        seq,
        kind: kind_byte,
    };
    if r.remaining() != kind.payload_len() {
        return Err(bad_length);
    }
    match read_command(kind, &mut r) {
        Ok(command) => Ok(Received { seq, command }),
        Err(ReadError::OutOfRoom) => Err(bad_length),
        Err(ReadError::OutOfRange(field)) => Err(UplinkError::OutOfRange {
            seq,
            kind: kind_byte,
            field,
        }),
    }
}

#[cfg(test)]
mod tests;
