//! Encoding and decoding of frame bodies: the fixed little-endian layouts
//! of `frame.rs`, the header and the CRC-32C trailer.

use super::bytes::{OutOfRoom, Reader, Writer};
use super::crc::crc32c;
use super::frame::{
    Event, EventKind, Frame, FrameKind, NavSolution, Payload, RawPart, RawSample, StationSurvey,
    CRC_LEN, HEADER_LEN, PROTOCOL_VERSION,
};

/// Why a body was rejected.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FrameError {
    TooShort,
    BadCrc,
    UnsupportedVersion(u8),
    /// CRC and version fine, kind unknown: the sequence number is still good.
    UnknownKind {
        kind: u8,
        seq: u16,
    },
    /// Known kind, wrong length for it.
    BadLength,
}

impl core::fmt::Display for FrameError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::TooShort => f.write_str("the frame is shorter than a header and its CRC"),
            Self::BadCrc => f.write_str("the frame's CRC does not match its contents"),
            Self::UnsupportedVersion(version) => write!(
                f,
                "the frame is of protocol version {version}; this decoder reads version {PROTOCOL_VERSION}"
            ),
            Self::UnknownKind { kind, seq } => {
                write!(f, "frame {seq} is of an unknown kind ({kind})")
            }
            Self::BadLength => f.write_str("the frame's length does not fit its kind"),
        }
    }
}

impl core::error::Error for FrameError {}

impl From<OutOfRoom> for FrameError {
    fn from(_: OutOfRoom) -> Self {
        Self::BadLength
    }
}

fn write_payload(w: &mut Writer, payload: &Payload) -> Result<(), OutOfRoom> {
    match payload {
        Payload::Raw(r) => {
            w.u64(r.time_us)?;
            w.u32(r.sample_counter)?;
            for p in &r.parts {
                w.i16(p.gyro_rate)?;
                w.i16(p.gyro_temp)?;
                p.accel.iter().try_for_each(|a| w.i16(*a))?;
                w.i16(p.accel_temp)?;
                w.u16(p.flags)?;
            }
        }
        Payload::Nav(n) => {
            w.u64(n.time_us)?;
            w.u32(n.sample_counter)?;
            w.u8(n.mode)?;
            w.u16(n.flags)?;
            w.f32s(&n.attitude)?;
            w.f32s(&n.velocity_ned)?;
            w.f64(n.latitude)?;
            w.f64(n.longitude)?;
            w.f32(n.height)?;
            w.f32s(&n.attitude_std)?;
            w.f32s(&n.velocity_std)?;
            w.f32s(&n.position_std_ned)?;
        }
        Payload::Event(e) => {
            w.u64(e.time_us)?;
            w.u8(e.kind.to_byte())?;
            w.u8(e.part)?;
            w.u16(e.code)?;
            w.u32(e.value)?;
        }
        Payload::Station(s) => {
            w.u64(s.time_us)?;
            w.u16(s.station)?;
            w.u16(s.flags)?;
            w.u32(s.start_sample)?;
            w.u32(s.end_sample)?;
            w.f32s(&s.angles)?;
            w.f32s(&s.angles_std)?;
            w.f32s(&s.correlations)?;
            w.f32(s.still_quality)?;
        }
    }
    Ok(())
}

fn read_payload(kind: FrameKind, r: &mut Reader) -> Result<Payload, OutOfRoom> {
    Ok(match kind {
        FrameKind::RawSample => {
            let time_us = r.u64()?;
            let sample_counter = r.u32()?;
            let mut parts = [RawPart::default(); 2];
            for p in parts.iter_mut() {
                p.gyro_rate = r.i16()?;
                p.gyro_temp = r.i16()?;
                for a in p.accel.iter_mut() {
                    *a = r.i16()?;
                }
                p.accel_temp = r.i16()?;
                p.flags = r.u16()?;
            }
            Payload::Raw(RawSample {
                time_us,
                sample_counter,
                parts,
            })
        }
        FrameKind::NavSolution => Payload::Nav(NavSolution {
            time_us: r.u64()?,
            sample_counter: r.u32()?,
            mode: r.u8()?,
            flags: r.u16()?,
            attitude: r.f32s()?,
            velocity_ned: r.f32s()?,
            latitude: r.f64()?,
            longitude: r.f64()?,
            height: r.f32()?,
            attitude_std: r.f32s()?,
            velocity_std: r.f32s()?,
            position_std_ned: r.f32s()?,
        }),
        FrameKind::Event => Payload::Event(Event {
            time_us: r.u64()?,
            kind: EventKind::from_byte(r.u8()?),
            part: r.u8()?,
            code: r.u16()?,
            value: r.u32()?,
        }),
        FrameKind::StationSurvey => Payload::Station(StationSurvey {
            time_us: r.u64()?,
            station: r.u16()?,
            flags: r.u16()?,
            start_sample: r.u32()?,
            end_sample: r.u32()?,
            angles: r.f32s()?,
            angles_std: r.f32s()?,
            correlations: r.f32s()?,
            still_quality: r.f32()?,
        }),
    })
}

/// Writes the body (header, payload, CRC) of a frame into `buf`; returns its
/// length, [`FrameKind::body_len`].
pub fn encode_body(seq: u16, payload: &Payload, buf: &mut [u8]) -> Result<usize, OutOfRoom> {
    let len = {
        let mut w = Writer::new(buf);
        w.u8(PROTOCOL_VERSION)?;
        w.u8(payload.kind() as u8)?;
        w.u16(seq)?;
        write_payload(&mut w, payload)?;
        w.len()
    };
    seal_body(buf, len)
}

/// Appends the CRC-32C of `buf[..len]` after it; returns the body's length.
/// The one sealing step of every body, downlink and uplink.
pub fn seal_body(buf: &mut [u8], len: usize) -> Result<usize, OutOfRoom> {
    let crc = crc32c(buf.get(..len).ok_or(OutOfRoom)?);
    let end = len.checked_add(CRC_LEN).ok_or(OutOfRoom)?;
    let tail = buf.get_mut(len..end).ok_or(OutOfRoom)?;
    tail.copy_from_slice(&crc.to_le_bytes());
    Ok(end)
}

/// Checks a body's length and CRC; returns the bytes the CRC covers
/// (header and payload). The one opening step of every body.
pub fn open_body(body: &[u8]) -> Result<&[u8], FrameError> {
    let split = body
        .len()
        .checked_sub(CRC_LEN)
        .filter(|n| *n >= HEADER_LEN)
        .ok_or(FrameError::TooShort)?;
    let (covered, trailer) = body.split_at(split);
    let mut crc_bytes = [0u8; CRC_LEN];
    crc_bytes.copy_from_slice(trailer);
    if crc32c(covered) != u32::from_le_bytes(crc_bytes) {
        return Err(FrameError::BadCrc);
    }
    Ok(covered)
}

/// Checks and parses a frame body (COBS already removed).
pub fn decode_body(body: &[u8]) -> Result<Frame, FrameError> {
    let mut r = Reader::new(open_body(body)?);
    let version = r.u8()?;
    if version != PROTOCOL_VERSION {
        return Err(FrameError::UnsupportedVersion(version));
    }
    let kind_byte = r.u8()?;
    let seq = r.u16()?;
    let kind = FrameKind::from_byte(kind_byte).ok_or(FrameError::UnknownKind {
        kind: kind_byte,
        seq,
    })?;
    if r.remaining() != kind.payload_len() {
        return Err(FrameError::BadLength);
    }
    let payload = read_payload(kind, &mut r)?;
    Ok(Frame { seq, payload })
}

#[cfg(test)]
mod tests {
    use super::super::frame::{MAX_BODY_LEN, NAV_PAYLOAD_LEN, NO_PART, RAW_PAYLOAD_LEN};
    use super::*;

    fn event() -> Payload {
        Payload::Event(Event {
            time_us: 1_000_000,
            kind: EventKind::Boot,
            part: NO_PART,
            code: 1,
            value: 0,
        })
    }

    #[test]
    fn payload_lengths_match_the_writer() {
        for payload in [
            Payload::Raw(RawSample::default()),
            Payload::Nav(NavSolution::default()),
            event(),
            Payload::Station(StationSurvey::default()),
        ] {
            let mut buf = [0u8; MAX_BODY_LEN];
            let n = encode_body(7, &payload, &mut buf).unwrap();
            assert_eq!(n, payload.kind().body_len());
        }
        assert_eq!(RAW_PAYLOAD_LEN, 40);
        assert_eq!(NAV_PAYLOAD_LEN, 95);
    }

    #[test]
    fn round_trip_and_rejections() {
        let mut buf = [0u8; MAX_BODY_LEN];
        let n = encode_body(0xBEEF, &event(), &mut buf).unwrap();
        let frame = decode_body(&buf[..n]).unwrap();
        assert_eq!(frame.seq, 0xBEEF);
        assert_eq!(frame.payload, event());
        // Any single bit flip is caught by the CRC.
        for bit in 0..n * 8 {
            let mut copy = buf;
            copy[bit / 8] ^= 1 << (bit % 8);
            assert_eq!(decode_body(&copy[..n]), Err(FrameError::BadCrc));
        }
        assert_eq!(decode_body(&buf[..7]), Err(FrameError::TooShort));
        assert_eq!(decode_body(&buf[..n - 1]), Err(FrameError::BadCrc));
    }

    #[test]
    fn version_kind_and_length_are_checked_after_the_crc() {
        let with_crc = |bytes: &mut [u8]| {
            let n = bytes.len() - CRC_LEN;
            let crc = crc32c(&bytes[..n]).to_le_bytes();
            bytes[n..].copy_from_slice(&crc);
        };
        let mut buf = [0u8; MAX_BODY_LEN];
        let n = encode_body(3, &event(), &mut buf).unwrap();
        let mut v = buf;
        v[0] = 2;
        with_crc(&mut v[..n]);
        assert_eq!(decode_body(&v[..n]), Err(FrameError::UnsupportedVersion(2)));
        let mut k = buf;
        k[1] = 9; // 4 is the station survey since version 1's fourth kind
        with_crc(&mut k[..n]);
        assert_eq!(
            decode_body(&k[..n]),
            Err(FrameError::UnknownKind { kind: 9, seq: 3 })
        );
        let mut l = buf;
        l[1] = FrameKind::RawSample as u8;
        with_crc(&mut l[..n]);
        assert_eq!(decode_body(&l[..n]), Err(FrameError::BadLength));
    }

    #[test]
    fn errors_read_as_sentences_with_their_numbers() {
        extern crate std;
        use std::string::ToString;
        let errors = [
            FrameError::TooShort,
            FrameError::BadCrc,
            FrameError::UnsupportedVersion(2),
            FrameError::UnknownKind { kind: 9, seq: 3 },
            FrameError::BadLength,
        ];
        for e in errors {
            let text = e.to_string();
            assert!(text.split(' ').count() >= 5, "{e:?}: `{text}`");
        }
        assert!(errors[2].to_string().contains("version 2"));
        let unknown = errors[3].to_string();
        assert!(
            unknown.contains("frame 3") && unknown.contains("(9)"),
            "{unknown}"
        );
        assert!(OutOfRoom.to_string().contains("buffer"));
    }

    #[test]
    fn event_kinds_round_trip_through_bytes() {
        for b in 0..=255u8 {
            assert_eq!(EventKind::from_byte(b).to_byte(), b);
        }
    }
}
