//! A recorded or simulated **sensor stream**: what each of the probe's two
//! parts senses, sample by sample, in its own axes (the physical input of
//! the hil-mock parts). `host-sim simulate --sensor-stream FILE` writes it
//! (the drilling simulator's samples with the sensor errors applied); the
//! QEMU probe (feature `qemu-drilling`) reads it through semihosting in
//! small chunks, and the parts answer the driver from it instead of the
//! still generator.
//!
//! # Format (version 1, all little-endian)
//!
//! | bytes | field |
//! |-------|-------|
//! | 8     | magic `MWDSTRM\0` |
//! | 2     | version, u16 = 1 |
//! | 2     | parts per sample, u16 = 2 |
//! | 4     | sample rate, u32 Hz (= 20, the probe's rate) |
//! | 4     | sample count N, u32 (> 0) |
//!
//! then N records of 2 x 5 f32: per part (0 then 1) the rate about the
//! part's gyro axis (rad/s), the specific force along the part's X, Y, Z
//! (m/s^2) and the temperature (degC). A record's values must be finite;
//! bytes after the N-th record are not read (the count sets the run).
//!
//! # Timing
//!
//! The stream is indexed by the probe's **sample counter**, not by time:
//! the board selects record `n` ([`StreamPlayer::advance_to`]) just before
//! it takes raw sample `n`, so raw sample `n` quantises record `n` whatever
//! the start-up took. Before the first selection the parts see record 0.
//!
//! No heap: the player reads through a fixed buffer of `N` bytes.

use core::fmt;

use crate::source::{PhysicalSample, SampleSource};

pub const STREAM_MAGIC: [u8; 8] = *b"MWDSTRM\0";
pub const STREAM_VERSION: u16 = 1;
pub const STREAM_PARTS: usize = 2;
pub const HEADER_LEN: usize = 20;
/// f32 values per part in a record.
pub const VALUES_PER_PART: usize = 5;
pub const RECORD_LEN: usize = STREAM_PARTS * VALUES_PER_PART * 4;
const _: () = assert!(RECORD_LEN >= HEADER_LEN);

/// One record: both parts' readings at one sample.
pub type StreamRecord = [PhysicalSample; STREAM_PARTS];

/// The stream's header.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StreamHeader {
    pub sample_rate_hz: u32,
    pub sample_count: u32,
}

impl StreamHeader {
    pub fn encode(&self) -> [u8; HEADER_LEN] {
        let mut out = [0u8; HEADER_LEN];
        out[..8].copy_from_slice(&STREAM_MAGIC);
        out[8..10].copy_from_slice(&STREAM_VERSION.to_le_bytes());
        out[10..12].copy_from_slice(&(STREAM_PARTS as u16).to_le_bytes());
        out[12..16].copy_from_slice(&self.sample_rate_hz.to_le_bytes());
        out[16..20].copy_from_slice(&self.sample_count.to_le_bytes());
        out
    }

    /// Checks and decodes a header.
    pub fn decode(bytes: &[u8; HEADER_LEN]) -> Result<Self, StreamError> {
        if bytes[..8] != STREAM_MAGIC {
            return Err(StreamError::BadMagic);
        }
        let version = u16::from_le_bytes([bytes[8], bytes[9]]);
        if version != STREAM_VERSION {
            return Err(StreamError::UnsupportedVersion(version));
        }
        let parts = u16::from_le_bytes([bytes[10], bytes[11]]);
        if usize::from(parts) != STREAM_PARTS {
            return Err(StreamError::BadPartCount(parts));
        }
        let sample_rate_hz = u32::from_le_bytes([bytes[12], bytes[13], bytes[14], bytes[15]]);
        if sample_rate_hz == 0 {
            return Err(StreamError::BadSampleRate(sample_rate_hz));
        }
        let sample_count = u32::from_le_bytes([bytes[16], bytes[17], bytes[18], bytes[19]]);
        if sample_count == 0 {
            return Err(StreamError::Empty);
        }
        Ok(Self {
            sample_rate_hz,
            sample_count,
        })
    }
}

/// Encodes one record.
pub fn encode_record(record: &StreamRecord) -> [u8; RECORD_LEN] {
    let mut out = [0u8; RECORD_LEN];
    let values = record.iter().flat_map(|p| {
        [
            p.rate_rad_s,
            p.accel_m_s2[0],
            p.accel_m_s2[1],
            p.accel_m_s2[2],
            p.temperature_degc,
        ]
    });
    for (chunk, v) in out.chunks_exact_mut(4).zip(values) {
        chunk.copy_from_slice(&v.to_le_bytes());
    }
    out
}

/// Decodes record number `index` (for the error message); every value
/// must be finite.
pub fn decode_record(bytes: &[u8; RECORD_LEN], index: u32) -> Result<StreamRecord, StreamError> {
    let mut values = [0f32; STREAM_PARTS * VALUES_PER_PART];
    for (v, chunk) in values.iter_mut().zip(bytes.chunks_exact(4)) {
        *v = f32::from_le_bytes([chunk[0], chunk[1], chunk[2], chunk[3]]);
        if !v.is_finite() {
            return Err(StreamError::NotFinite { index });
        }
    }
    let mut record = StreamRecord::default();
    for (part, v) in record.iter_mut().zip(values.chunks_exact(VALUES_PER_PART)) {
        *part = PhysicalSample {
            rate_rad_s: v[0],
            accel_m_s2: [v[1], v[2], v[3]],
            temperature_degc: v[4],
        };
    }
    Ok(record)
}

/// What went wrong with a stream.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StreamError {
    /// The host refused the read (or the open), with its error code.
    Io(i32),
    /// Shorter than the header.
    NoHeader,
    BadMagic,
    UnsupportedVersion(u16),
    BadPartCount(u16),
    BadSampleRate(u32),
    /// The header says zero samples.
    Empty,
    /// The data ended inside record `index` (the header promised more).
    Truncated {
        index: u32,
    },
    /// Record `index` holds a NaN or an infinity.
    NotFinite {
        index: u32,
    },
    /// Record `index` was asked for after a later one (the stream only
    /// goes forward) or beyond the stream's end.
    OutOfOrder {
        index: u32,
    },
}

impl fmt::Display for StreamError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Io(code) => write!(f, "the host could not open or read it (host errno {code})"),
            Self::NoHeader => write!(f, "shorter than its {HEADER_LEN}-byte header"),
            Self::BadMagic => write!(f, "not a sensor stream (bad magic)"),
            Self::UnsupportedVersion(v) => {
                write!(f, "stream version {v} (this reads {STREAM_VERSION})")
            }
            Self::BadPartCount(n) => {
                write!(f, "{n} parts per sample (the probe has {STREAM_PARTS})")
            }
            Self::BadSampleRate(r) => write!(f, "sample rate {r} Hz"),
            Self::Empty => write!(f, "the stream holds no samples"),
            Self::Truncated { index } => write!(f, "the data end inside record {index}"),
            Self::NotFinite { index } => write!(f, "record {index} holds a non-finite value"),
            Self::OutOfOrder { index } => {
                write!(f, "record {index} asked for out of order or beyond the end")
            }
        }
    }
}

/// Where the stream's bytes come from (a semihosting file on the target,
/// a slice in host tests).
pub trait StreamRead {
    /// Reads up to `buf.len()` bytes; returns how many (0 at the end).
    fn read(&mut self, buf: &mut [u8]) -> Result<usize, StreamError>;
}

impl StreamRead for &[u8] {
    fn read(&mut self, buf: &mut [u8]) -> Result<usize, StreamError> {
        let n = buf.len().min(self.len());
        buf[..n].copy_from_slice(&self[..n]);
        *self = &self[n..];
        Ok(n)
    }
}

/// Plays a stream forward record by record through a buffer of `N` bytes
/// (`N` at least one record; larger means fewer host reads).
pub struct StreamPlayer<R, const N: usize> {
    reader: R,
    buf: [u8; N],
    /// Unconsumed bytes are `buf[start..end]`.
    start: usize,
    end: usize,
    header: StreamHeader,
    index: u32,
    current: StreamRecord,
}

impl<R: StreamRead, const N: usize> StreamPlayer<R, N> {
    /// Reads and checks the header and the first record.
    pub fn open(reader: R) -> Result<Self, StreamError> {
        // A record is longer than the header: room for one is room for both.
        const { assert!(N >= RECORD_LEN) };
        let mut player = Self {
            reader,
            buf: [0; N],
            start: 0,
            end: 0,
            header: StreamHeader {
                sample_rate_hz: 0,
                sample_count: 0,
            },
            index: 0,
            current: StreamRecord::default(),
        };
        let mut header = [0u8; HEADER_LEN];
        if !player.take(&mut header)? {
            return Err(StreamError::NoHeader);
        }
        player.header = StreamHeader::decode(&header)?;
        player.current = player.next_record(0)?;
        Ok(player)
    }

    pub fn header(&self) -> StreamHeader {
        self.header
    }

    /// The current record's index.
    pub fn index(&self) -> u32 {
        self.index
    }

    /// Part `part`'s reading in the current record (a part beyond the
    /// record's two reads zeros).
    pub fn part(&self, part: usize) -> PhysicalSample {
        self.current.get(part).copied().unwrap_or_default()
    }

    /// Makes record `index` the current one, reading forward.
    pub fn advance_to(&mut self, index: u32) -> Result<(), StreamError> {
        if index < self.index || index >= self.header.sample_count {
            return Err(StreamError::OutOfOrder { index });
        }
        while self.index < index {
            self.current = self.next_record(self.index + 1)?;
            self.index += 1;
        }
        Ok(())
    }

    fn next_record(&mut self, index: u32) -> Result<StreamRecord, StreamError> {
        let mut bytes = [0u8; RECORD_LEN];
        if !self.take(&mut bytes)? {
            return Err(StreamError::Truncated { index });
        }
        decode_record(&bytes, index)
    }

    /// Fills `out` from the buffer, refilling it from the reader as
    /// needed; false if the data end first.
    fn take(&mut self, out: &mut [u8]) -> Result<bool, StreamError> {
        while self.end - self.start < out.len() {
            // Move the rest to the front and read after it.
            self.buf.copy_within(self.start..self.end, 0);
            self.end -= self.start;
            self.start = 0;
            let n = self.reader.read(&mut self.buf[self.end..])?;
            if n == 0 {
                return Ok(false);
            }
            self.end += n.min(N - self.end);
        }
        out.copy_from_slice(&self.buf[self.start..self.start + out.len()]);
        self.start += out.len();
        Ok(true)
    }
}

/// One part's readings taken from a stream shared by both parts: `feed`
/// returns the current record's reading of a part (e.g. from a
/// [`StreamPlayer`] in a static). The time is not used: the board selects
/// the record (see the module's "Timing").
#[derive(Debug, Clone, Copy)]
pub struct StreamSource<F> {
    pub feed: F,
    pub part: usize,
}

impl<F: FnMut(usize) -> PhysicalSample> SampleSource for StreamSource<F> {
    fn sample(&mut self, _time_ns: u64) -> PhysicalSample {
        (self.feed)(self.part)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record(k: u32) -> StreamRecord {
        let f = k as f32;
        [
            PhysicalSample {
                rate_rad_s: 0.001 * f,
                accel_m_s2: [f, -f, 9.8],
                temperature_degc: 25.0,
            },
            PhysicalSample {
                rate_rad_s: -0.002 * f,
                accel_m_s2: [0.5, f, -9.8],
                temperature_degc: 26.0,
            },
        ]
    }

    fn stream(count: u32, records: u32) -> [u8; HEADER_LEN + 7 * RECORD_LEN] {
        let mut out = [0u8; HEADER_LEN + 7 * RECORD_LEN];
        let header = StreamHeader {
            sample_rate_hz: 20,
            sample_count: count,
        };
        out[..HEADER_LEN].copy_from_slice(&header.encode());
        for k in 0..records.min(7) {
            let at = HEADER_LEN + k as usize * RECORD_LEN;
            out[at..at + RECORD_LEN].copy_from_slice(&encode_record(&record(k)));
        }
        out
    }

    #[test]
    fn plays_every_record_in_order_through_a_small_buffer() {
        let bytes = stream(7, 7);
        // A buffer of one and a half records: most records straddle reads.
        let mut player = StreamPlayer::<_, 60>::open(&bytes[..]).expect("a good stream");
        assert_eq!(player.header().sample_count, 7);
        assert_eq!(player.part(0), record(0)[0]);
        for k in [1, 2, 5, 6] {
            player.advance_to(k).expect("in order");
            assert_eq!([player.part(0), player.part(1)], record(k));
        }
        assert_eq!(
            player.advance_to(7),
            Err(StreamError::OutOfOrder { index: 7 })
        );
        assert_eq!(
            player.advance_to(5),
            Err(StreamError::OutOfOrder { index: 5 })
        );
        let mut source = StreamSource {
            feed: |part| player.part(part),
            part: 1,
        };
        assert_eq!(source.sample(0), record(6)[1]);
    }

    #[test]
    fn bad_streams_are_named() {
        let good = stream(7, 7);
        let open = |b: &[u8]| StreamPlayer::<_, 64>::open(b).err();
        assert_eq!(open(&good[..10]), Some(StreamError::NoHeader));
        let mut bad = good;
        bad[0] = b'X';
        assert_eq!(open(&bad), Some(StreamError::BadMagic));
        let mut bad = good;
        bad[8] = 9;
        assert_eq!(open(&bad), Some(StreamError::UnsupportedVersion(9)));
        let mut bad = good;
        bad[10] = 3;
        assert_eq!(open(&bad), Some(StreamError::BadPartCount(3)));
        assert_eq!(open(&stream(0, 7)), Some(StreamError::Empty));
        // The header promises more records than there are.
        let short = stream(7, 3);
        let mut player =
            StreamPlayer::<_, 64>::open(&short[..HEADER_LEN + 3 * RECORD_LEN]).expect("header");
        assert_eq!(player.advance_to(2), Ok(()));
        assert_eq!(
            player.advance_to(3),
            Err(StreamError::Truncated { index: 3 })
        );
        let mut nan = good;
        nan[HEADER_LEN + 4..HEADER_LEN + 8].copy_from_slice(&f32::NAN.to_le_bytes());
        assert_eq!(open(&nan), Some(StreamError::NotFinite { index: 0 }));
    }
}
