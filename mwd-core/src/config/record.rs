//! The configuration's record in flash: fixed size, little-endian, the
//! uplink's own field layouts (`protocol::uplink::fields`), so a value is
//! the same bytes on the wire and in flash, and the same checks on reading.
//!
//! ```text
//! magic "MWDC" 4 | format u16 | version u32 | site 24 | tie-in flag u8 |
//! tie-in 48 | calibration part 0 112 | part 1 112 | still settings 18 |
//! crc32c u32
//! ```
//! 329 bytes. The CRC-32C covers everything before it: a record cut short
//! by a power failure during its write (the rest still erased, 0xFF) fails
//! it, except with probability 2^-32. The tie-in's 48 bytes are zero when
//! the flag is 0 (none).

use super::{tie_in_field, ProbeConfig};
use crate::probe::TieIn;
use crate::protocol::bytes::{OutOfRoom, Reader, Writer};
use crate::protocol::codec::{open_body, seal_body};
use crate::protocol::uplink::fields::{self, Field, ReadError};

pub const RECORD_MAGIC: [u8; 4] = *b"MWDC";
/// The layout's number; a new layout gets a new one (the loader then
/// falls back to the defaults and says why).
pub const RECORD_FORMAT: u16 = 1;
pub const RECORD_LEN: usize = 4
    + 2
    + 4
    + fields::SITE_LEN
    + 1
    + fields::TIE_IN_LEN
    + 2 * fields::PART_CALIBRATION_LEN
    + fields::STILL_SETTINGS_LEN
    + 4;

/// Why a slot holds no usable record.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RecordError {
    /// All 0xFF: never written (or erased and cut before its write).
    Erased,
    /// Not a configuration record (another use of the sector, or a write
    /// cut before the magic).
    BadMagic,
    /// The CRC fails: a write cut part way, or a flash error.
    BadCrc,
    /// Another layout's record, CRC good.
    UnsupportedFormat(u16),
    /// The tie-in flag is neither 0 nor 1.
    BadTieInFlag(u8),
    /// A value out of its range (CRC good: written by other firmware).
    Invalid(Field),
    /// Fewer than [`RECORD_LEN`] bytes.
    TooShort,
}

impl From<ReadError> for RecordError {
    fn from(e: ReadError) -> Self {
        match e {
            ReadError::OutOfRoom => Self::TooShort,
            ReadError::OutOfRange(field) => Self::Invalid(field),
        }
    }
}

impl From<OutOfRoom> for RecordError {
    fn from(_: OutOfRoom) -> Self {
        Self::TooShort
    }
}

/// The record of `config`.
pub fn encode_record(config: &ProbeConfig) -> [u8; RECORD_LEN] {
    let mut buf = [0u8; RECORD_LEN];
    // The buffer is the record's exact size: the writes cannot run out
    // of room (checked by the tests), so the error is only passed on.
    let _ = write_record(config, &mut buf);
    buf
}

fn write_record(config: &ProbeConfig, buf: &mut [u8; RECORD_LEN]) -> Result<usize, OutOfRoom> {
    let len = {
        let mut w = Writer::new(buf);
        w.bytes(&RECORD_MAGIC)?;
        w.u16(RECORD_FORMAT)?;
        w.u32(config.version)?;
        fields::write_site(&mut w, &config.site)?;
        match &config.tie_in {
            Some(t) => {
                w.u8(1)?;
                fields::write_tie_in(&mut w, &t.angles(), &t.sigma())?;
            }
            None => {
                w.u8(0)?;
                w.bytes(&[0; fields::TIE_IN_LEN])?;
            }
        }
        fields::write_probe_calibration(&mut w, &config.calibration)?;
        fields::write_still_settings(&mut w, &config.still)?;
        w.len()
    };
    seal_body(buf, len)
}

/// Reads a record: magic, CRC, format, then every field's range (the
/// uplink's, and the navigator's for the tie-in).
pub fn decode_record(bytes: &[u8]) -> Result<ProbeConfig, RecordError> {
    let bytes = bytes.get(..RECORD_LEN).ok_or(RecordError::TooShort)?;
    if bytes.iter().all(|b| *b == 0xFF) {
        return Err(RecordError::Erased);
    }
    if bytes.get(..4) != Some(&RECORD_MAGIC[..]) {
        return Err(RecordError::BadMagic);
    }
    let covered = open_body(bytes).map_err(|_| RecordError::BadCrc)?;
    let mut r = Reader::new(covered.get(4..).ok_or(RecordError::TooShort)?);
    let format = r.u16()?;
    if format != RECORD_FORMAT {
        return Err(RecordError::UnsupportedFormat(format));
    }
    let version = r.u32()?;
    let site = fields::read_site(&mut r)?;
    let flag = r.u8()?;
    let tie_in = match flag {
        0 => {
            // No tie-in: its zeros are skipped, not read as angles.
            for _ in 0..fields::TIE_IN_LEN / 8 {
                r.f64()?;
            }
            None
        }
        1 => {
            let (angles, sigma) = fields::read_tie_in(&mut r)?;
            let tie_in = TieIn::new(angles, sigma);
            Some(tie_in.map_err(|e| RecordError::Invalid(tie_in_field(e)))?)
        }
        other => return Err(RecordError::BadTieInFlag(other)),
    };
    Ok(ProbeConfig {
        version,
        site,
        tie_in,
        calibration: fields::read_probe_calibration(&mut r)?,
        still: fields::read_still_settings(&mut r)?,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::calibration::GyroCalibration;
    use crate::conventions::{DrillingAngles, DEG};
    use crate::protocol::uplink::Command;

    fn configured() -> ProbeConfig {
        let mut c = ProbeConfig::default();
        let angles = DrillingAngles {
            inclination: 88.0 * DEG,
            azimuth: 271.0 * DEG,
            toolface: 15.0 * DEG,
        };
        let sigma = DrillingAngles {
            inclination: 0.1 * DEG,
            azimuth: 1.5 * DEG,
            toolface: 0.3 * DEG,
        };
        c.apply(&Command::SetTieIn { angles, sigma }).unwrap();
        let mut accel = c.calibration.accel[1];
        accel.bias = [0.02, -0.01, 0.005];
        let gyro = GyroCalibration {
            bias: 2e-4,
            scale: 0.998,
        };
        c.apply(&Command::SetCalibration {
            part: 1,
            accel,
            gyro,
        })
        .unwrap();
        c
    }

    #[test]
    fn records_round_trip_with_and_without_a_tie_in() {
        assert_eq!(RECORD_LEN, 329);
        for config in [ProbeConfig::default(), configured()] {
            let record = encode_record(&config);
            assert_eq!(&record[..4], b"MWDC");
            assert_eq!(decode_record(&record), Ok(config));
        }
        assert_eq!(configured().version, 2);
    }

    #[test]
    fn a_write_cut_anywhere_is_never_read_as_a_config() {
        let record = encode_record(&configured());
        for cut in 0..RECORD_LEN {
            let mut flash = [0xFFu8; RECORD_LEN];
            flash[..cut].copy_from_slice(&record[..cut]);
            let got = decode_record(&flash);
            let expected = match cut {
                0 => RecordError::Erased,
                1..=3 => RecordError::BadMagic,
                _ => RecordError::BadCrc,
            };
            assert_eq!(got, Err(expected), "cut after {cut} bytes");
        }
        assert_eq!(decode_record(&record[..100]), Err(RecordError::TooShort));
    }

    #[test]
    fn another_format_or_a_bad_value_is_named_even_with_a_good_crc() {
        let reseal = |mut r: [u8; RECORD_LEN]| {
            seal_body(&mut r, RECORD_LEN - 4).unwrap();
            r
        };
        let mut r = encode_record(&configured());
        r[4] = 2;
        assert_eq!(
            decode_record(&reseal(r)),
            Err(RecordError::UnsupportedFormat(2))
        );
        let mut r = encode_record(&configured());
        r[34] = 7; // the tie-in flag after magic, format, version, site
        assert_eq!(decode_record(&reseal(r)), Err(RecordError::BadTieInFlag(7)));
        let mut r = encode_record(&configured());
        r[10..18].copy_from_slice(&f64::NAN.to_le_bytes());
        assert_eq!(
            decode_record(&reseal(r)),
            Err(RecordError::Invalid(Field::Latitude))
        );
    }
}
