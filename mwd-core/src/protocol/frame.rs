//! Frame kinds and their fixed little-endian layouts (the byte tables are in
//! `docs/protocol.md`). A frame body, before COBS, is:
//!
//! ```text
//! version u8 | kind u8 | seq u16 | payload (fixed length per kind) | crc32c u32
//! ```
//! The CRC covers everything before it.

/// Version byte of this layout; a decoder rejects other versions.
pub const PROTOCOL_VERSION: u8 = 1;
/// version + kind + sequence number.
pub const HEADER_LEN: usize = 4;
/// The CRC-32C trailer.
pub const CRC_LEN: usize = 4;

/// Kind byte of each frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u8)]
pub enum FrameKind {
    RawSample = 1,
    NavSolution = 2,
    Event = 3,
    /// Added after the first three: a decoder that predates it skips it
    /// as an unknown kind, its sequence number still counted
    /// (docs/protocol.md, "Compatibility").
    StationSurvey = 4,
}

impl FrameKind {
    pub const ALL: [FrameKind; 4] = [
        Self::RawSample,
        Self::NavSolution,
        Self::Event,
        Self::StationSurvey,
    ];
    /// Number of kinds (per-kind counters).
    pub const COUNT: usize = Self::ALL.len();

    pub fn from_byte(byte: u8) -> Option<Self> {
        Self::ALL.into_iter().find(|k| *k as u8 == byte)
    }

    /// Payload length in bytes (fixed per kind).
    pub const fn payload_len(self) -> usize {
        match self {
            Self::RawSample => RAW_PAYLOAD_LEN,
            Self::NavSolution => NAV_PAYLOAD_LEN,
            Self::Event => EVENT_PAYLOAD_LEN,
            Self::StationSurvey => STATION_PAYLOAD_LEN,
        }
    }

    /// Body length (header + payload + CRC) before COBS.
    pub const fn body_len(self) -> usize {
        HEADER_LEN + self.payload_len() + CRC_LEN
    }

    /// Index 0..COUNT for per-kind counters.
    pub const fn index(self) -> usize {
        self as usize - 1
    }
}

/// Bits of [`RawPart::flags`], set by the firmware from the driver's results.
pub mod raw_flags {
    /// Gyro rate and temperature were read without error in this sample.
    pub const GYRO_VALID: u16 = 1 << 0;
    /// Accelerations and temperature were read without error.
    pub const ACCEL_VALID: u16 = 1 << 1;
    /// The gyro's S_OK status bit was set.
    pub const GYRO_S_OK: u16 = 1 << 2;
    /// The gyro rate is beyond the specified +-300 deg/s (5400 counts) or
    /// at a 14-bit limit.
    pub const GYRO_SATURATED: u16 = 1 << 3;
    /// The accelerometer reported SAT.
    pub const ACCEL_SATURATED: u16 = 1 << 4;
    /// A parity error was seen on either slave of this part.
    pub const PARITY_ERROR: u16 = 1 << 5;
    /// The accelerometer reported ST (self-test / checksum failure).
    pub const SELF_TEST_FAILED: u16 = 1 << 6;
    /// The part reset (accelerometer PORST or gyro loop-failure restart).
    pub const RESET_SEEN: u16 = 1 << 7;
    /// A slave did not answer (dead chip select, bus error).
    pub const NO_RESPONSE: u16 = 1 << 8;
    /// The accelerometer reported FRME (it received a bad frame).
    pub const ACCEL_FRAME_ERROR: u16 = 1 << 9;
    /// A temperature of this part is outside its operating range
    /// (`sensor_units::OPERATING_TEMPERATURE_DEGC`), or at a count limit.
    pub const TEMPERATURE_OUT_OF_RANGE: u16 = 1 << 10;
}

/// One SCC1300's raw outputs: 14-bit counts as the part delivers them (the
/// accelerometer in the part's own axes; `sensor_units` converts to SI and to
/// the body frame).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct RawPart {
    pub gyro_rate: i16,
    pub gyro_temp: i16,
    pub accel: [i16; 3],
    pub accel_temp: i16,
    /// [`raw_flags`] bits.
    pub flags: u16,
}

/// Raw sample frame: both parts at one sample instant.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct RawSample {
    /// Sample instant, microseconds since boot.
    pub time_us: u64,
    /// Counts 20 Hz samples since boot (wraps after 6.8 years).
    pub sample_counter: u32,
    pub parts: [RawPart; 2],
}

/// Navigation filter modes ([`NavSolution::mode`]).
pub mod nav_mode {
    pub const INITIALISING: u8 = 0;
    pub const COARSE_ALIGNMENT: u8 = 1;
    pub const FINE_ALIGNMENT: u8 = 2;
    pub const NAVIGATING: u8 = 3;
}

/// Bits of [`NavSolution::flags`]; the rest are reserved (sent as 0).
pub mod nav_flags {
    /// A zero-velocity update was applied in this cycle.
    pub const ZUPT_APPLIED: u16 = 1 << 0;
    /// The tool axis is near vertical: the tool-axis rate from accelerometer
    /// roll is invalid (within `attitude::NEAR_VERTICAL`, 5 deg, of vertical).
    pub const TOOL_AXIS_RATE_INVALID: u16 = 1 << 1;
    /// Some sensor input of this cycle was flagged invalid.
    pub const SENSOR_DEGRADED: u16 = 1 << 2;
    /// The filter's covariance failed its health check (a variance not
    /// finite or not positive, or growth beyond its bound): the sigmas it
    /// would give are sent as NaN. Bit 3 was "covariance reset", never set.
    pub const COVARIANCE_INVALID: u16 = 1 << 3;
    /// The solution is not to be used: there is none yet (the coarse
    /// alignment: its fields are NaN placeholders), its covariance is
    /// invalid, or the small-angle error model no longer holds (a tilt
    /// sigma beyond the limit `docs/protocol.md` states).
    pub const SOLUTION_INVALID: u16 = 1 << 4;
    /// Propagated through missing or invalid samples and not aided since.
    pub const COASTING: u16 = 1 << 5;
    /// One part is out: the solution rests on the other part alone.
    pub const SINGLE_PART: u16 = 1 << 6;
    /// Navigating, the probe is still (`probe::still`): a station survey
    /// is being taken, with a zero-velocity update each cycle (bit 0), up
    /// to the longest station (then bit 7 alone).
    pub const STILL: u16 = 1 << 7;
    /// The heading was lost: navigating, the filter's azimuth sigma passed
    /// the first-order limit (`probe::navigator::AZIMUTH_SIGMA_LIMIT_RAD`,
    /// 10 deg) since the last tie-in or alignment. The azimuth sigma is
    /// sent as +inf until the next tie-in: unlike a heading the alignment
    /// never found, no station brings it back.
    pub const HEADING_LOST: u16 = 1 << 8;
    /// The probe runs without a calibration (the identity correction it
    /// boots with): its sigmas cover the residual errors of a calibrated
    /// part only, not the parts' turn-on biases, scale factors and
    /// misalignments, which may exceed them many times.
    pub const UNCALIBRATED: u16 = 1 << 9;
}

/// Bits of [`StationSurvey::flags`]; the rest are reserved (sent as 0).
pub mod station_flags {
    /// Always set: the survey uses no magnetometer (gyro and
    /// accelerometers only), so magnetic interference cannot bias it.
    pub const MAGNETIC_FREE: u16 = 1 << 0;
    /// The azimuth is not determined (the same rule as the navigation
    /// frames' azimuth sigma: no gyrocompassed heading, or one part); its
    /// sigma is +inf and its correlations NaN.
    pub const AZIMUTH_UNDETERMINED: u16 = 1 << 1;
    /// The still period reached the longest station
    /// (`probe::navigator::MAX_STATION_SAMPLES`): sent while the probe is
    /// still still; no more zero-velocity updates and no other station
    /// until it has moved.
    pub const MAX_DURATION: u16 = 1 << 2;
    /// The tool axis is within `attitude::NEAR_VERTICAL` (5 deg) of
    /// vertical: azimuth and toolface are poorly defined (large sigmas).
    pub const NEAR_VERTICAL: u16 = 1 << 3;
    /// Do not use: the covariance failed its health check (sigmas NaN) or
    /// a tilt sigma is beyond the small-angle limit (as navigation bit 4).
    pub const SOLUTION_INVALID: u16 = 1 << 4;
    /// Sent because the surface asked for it (uplink "take a station
    /// now") while the probe was still, before the still period ended.
    pub const REQUESTED: u16 = 1 << 5;
    /// A dwell of the toolface-indexing procedure (uplink 0x48): still for
    /// the procedure's dwell time at a toolface that changed from the
    /// previous dwell's (`probe::navigator::commands`).
    pub const INDEXING_DWELL: u16 = 1 << 6;
    /// Ended because the gyros saw the tool turn while the still detector
    /// saw no motion (a smooth slide or creep: a block's rate gyrocompass
    /// failed its consistency test, `probe::navigator::EARTH_RATE_GATE`).
    /// The survey is the last checkpoint before that block; as after the
    /// longest station, no further zero-velocity update and no further
    /// station until the detector sees motion.
    pub const MOTION_SEEN: u16 = 1 << 7;
    /// The heading was lost since the last tie-in (as navigation bit 8),
    /// at this station or before it: the azimuth is undetermined (bit 1)
    /// until a new tie-in.
    pub const HEADING_LOST: u16 = 1 << 8;
    /// Surveyed without a calibration (as navigation bit 9): the sigmas
    /// do not cover the parts' uncalibrated errors.
    pub const UNCALIBRATED: u16 = 1 << 9;
}

/// A station survey (kind 4): the attitude at the end of a still period
/// during navigation, after a zero-velocity update in each of its cycles,
/// as drilling angles with their uncertainty (`probe::station`).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct StationSurvey {
    /// Time of the last still sample (microseconds since boot).
    pub time_us: u64,
    /// Station number since boot, from 1.
    pub station: u16,
    /// [`station_flags`] bits.
    pub flags: u16,
    /// Sample counters of the first and last zero-velocity update of the
    /// station (the probe had been still for `probe::still`'s detection
    /// delay, 39 samples, before the first).
    pub start_sample: u32,
    pub end_sample: u32,
    /// Inclination, azimuth, gravity toolface (rad): inclination in
    /// [0, pi] from vertical down, azimuth and toolface in [0, 2 pi).
    pub angles: [f32; 3],
    /// Their 1-sigma (rad); +inf for an undetermined azimuth, NaN when the
    /// covariance is invalid.
    pub angles_std: [f32; 3],
    /// Correlation coefficients inclination-azimuth,
    /// inclination-toolface, azimuth-toolface.
    pub correlations: [f32; 3],
    /// The largest of the still detector's normalised statistics, averaged
    /// over the station: about 1 for a probe that is still within its
    /// noise, larger for a disturbed one.
    pub still_quality: f32,
}

/// Navigation solution frame. Angles in rad, velocity in m/s (NED), position
/// as geodetic latitude/longitude in rad (f64: f32 would quantise latitude
/// to ~0.4 m, too coarse for the 1 m requirement and for bit-exact replay)
/// and height in m (f32: 1 mm resolution at 10 km).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct NavSolution {
    pub time_us: u64,
    /// The raw sample this solution used last.
    pub sample_counter: u32,
    /// One of [`nav_mode`].
    pub mode: u8,
    /// [`nav_flags`] bits.
    pub flags: u16,
    /// Roll, pitch, azimuth (rad), in the navigation core's convention.
    pub attitude: [f32; 3],
    pub velocity_ned: [f32; 3],
    pub latitude: f64,
    pub longitude: f64,
    pub height: f32,
    /// One-sigma of roll, pitch, azimuth (rad).
    pub attitude_std: [f32; 3],
    /// One-sigma of the NED velocity (m/s).
    pub velocity_std: [f32; 3],
    /// One-sigma of the position error, north/east/down (m).
    pub position_std_ned: [f32; 3],
}

/// What an event frame reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EventKind {
    /// The probe booted; `code` = firmware version, `value` = reset cause.
    Boot,
    /// A sensor fault; `part`, `code` = driver error code, `value` = count.
    SensorFault,
    /// A part was reset and restarted; `part`, `code` = reason.
    SensorReset,
    /// Sampling resynchronised; `value` = samples skipped.
    Resync,
    /// The navigation fell behind and samples were dropped from its inbox;
    /// `value` = samples dropped since the previous such event.
    SamplesDropped,
    /// A part's temperature left (`code` 0 below, 1 above) or came back
    /// into (`code` 2) its operating range; `part`, `value` = the
    /// temperature count (i16, sign-extended).
    Temperature,
    /// A code this decoder does not know (kept for forward compatibility).
    Other(u8),
}

impl EventKind {
    pub fn to_byte(self) -> u8 {
        match self {
            Self::Boot => 1,
            Self::SensorFault => 2,
            Self::SensorReset => 3,
            Self::Resync => 4,
            Self::SamplesDropped => 5,
            Self::Temperature => 6,
            Self::Other(b) => b,
        }
    }

    pub fn from_byte(byte: u8) -> Self {
        match byte {
            1 => Self::Boot,
            2 => Self::SensorFault,
            3 => Self::SensorReset,
            4 => Self::Resync,
            5 => Self::SamplesDropped,
            6 => Self::Temperature,
            b => Self::Other(b),
        }
    }
}

/// `Event::part` when the event concerns no particular part.
pub const NO_PART: u8 = 0xFF;

/// Status/event frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Event {
    pub time_us: u64,
    pub kind: EventKind,
    /// 0 or 1, or [`NO_PART`].
    pub part: u8,
    pub code: u16,
    pub value: u32,
}

/// The payload of one frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Payload {
    Raw(RawSample),
    Nav(NavSolution),
    Event(Event),
    Station(StationSurvey),
}

impl Payload {
    pub fn kind(&self) -> FrameKind {
        match self {
            Self::Raw(_) => FrameKind::RawSample,
            Self::Nav(_) => FrameKind::NavSolution,
            Self::Event(_) => FrameKind::Event,
            Self::Station(_) => FrameKind::StationSurvey,
        }
    }
}

/// A decoded frame: its sequence number and payload.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    pub seq: u16,
    pub payload: Payload,
}

const RAW_PART_LEN: usize = 14;
/// time_us 8 + sample_counter 4 + two parts.
pub const RAW_PAYLOAD_LEN: usize = 12 + 2 * RAW_PART_LEN;
/// time 8 + counter 4 + mode 1 + flags 2 + 6 f32 + 2 f64 + 10 f32.
pub const NAV_PAYLOAD_LEN: usize = 15 + 24 + 16 + 40;
/// time 8 + kind 1 + part 1 + code 2 + value 4.
pub const EVENT_PAYLOAD_LEN: usize = 16;
/// time 8 + station 2 + flags 2 + two counters 8 + 10 f32.
pub const STATION_PAYLOAD_LEN: usize = 20 + 40;
/// The longest body of any kind.
pub const MAX_BODY_LEN: usize = HEADER_LEN + NAV_PAYLOAD_LEN + CRC_LEN;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kinds_and_lengths() {
        for kind in FrameKind::ALL {
            assert_eq!(FrameKind::from_byte(kind as u8), Some(kind));
            assert_eq!(kind.body_len(), HEADER_LEN + kind.payload_len() + CRC_LEN);
        }
        assert_eq!(FrameKind::from_byte(0), None);
        assert_eq!(MAX_BODY_LEN, FrameKind::NavSolution.body_len());
        for kind in FrameKind::ALL {
            assert!(kind.body_len() <= MAX_BODY_LEN, "{kind:?}");
            assert_eq!(FrameKind::ALL[kind.index()], kind);
        }
        assert_eq!(FrameKind::StationSurvey.body_len(), 68);
        for kind in [
            EventKind::Boot,
            EventKind::SensorFault,
            EventKind::SensorReset,
            EventKind::Resync,
            EventKind::SamplesDropped,
            EventKind::Temperature,
            EventKind::Other(200),
        ] {
            assert_eq!(EventKind::from_byte(kind.to_byte()), kind);
        }
    }
}
