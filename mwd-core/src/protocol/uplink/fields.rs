//! The values the uplink carries, their byte layouts and their ranges: the
//! site, the tie-in, a part's calibration, the still-detection and filter
//! settings, the toolface-indexing procedure. The configuration record
//! (`crate::config`) stores the same layouts, so a value means the same
//! bytes on the wire and in flash.
//!
//! Each reader checks every field as it reads it and names the first one
//! out of its range ([`Field`]); a NaN is out of every range. These are the
//! wire's ranges: what the probe could hold at all. The tie-in's tighter
//! limits (near vertical, sigmas the filter's model holds) are the
//! navigator's, checked where the configuration takes it
//! (`probe::tie_in::TieIn::new`), under the same field codes.

use crate::calibration::{GyroCalibration, ProbeCalibration, TriadCalibration};
use crate::conventions::DrillingAngles;
use crate::earth::Position;
use crate::protocol::bytes::{OutOfRoom, Reader, Writer};
use core::f64::consts::{FRAC_PI_2, PI, TAU};

/// A field of a command or of the configuration record; its code is the
/// NAK's detail byte (`docs/protocol.md`, "Uplink").
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u8)]
pub enum Field {
    Latitude = 1,
    Longitude = 2,
    Height = 3,
    Inclination = 4,
    Azimuth = 5,
    Toolface = 6,
    InclinationSigma = 7,
    AzimuthSigma = 8,
    ToolfaceSigma = 9,
    Part = 10,
    AccelBias = 11,
    AccelCorrection = 12,
    GyroBias = 13,
    GyroScale = 14,
    ZEnter = 15,
    ZStay = 16,
    EnterEpochs = 17,
    MaxStationSamples = 18,
    ZuptVelocitySigma = 19,
    IndexPositions = 20,
    IndexDwell = 21,
}

impl Field {
    pub const ALL: [Field; 21] = [
        Field::Latitude,
        Field::Longitude,
        Field::Height,
        Field::Inclination,
        Field::Azimuth,
        Field::Toolface,
        Field::InclinationSigma,
        Field::AzimuthSigma,
        Field::ToolfaceSigma,
        Field::Part,
        Field::AccelBias,
        Field::AccelCorrection,
        Field::GyroBias,
        Field::GyroScale,
        Field::ZEnter,
        Field::ZStay,
        Field::EnterEpochs,
        Field::MaxStationSamples,
        Field::ZuptVelocitySigma,
        Field::IndexPositions,
        Field::IndexDwell,
    ];

    /// The field of a NAK's detail code.
    pub fn from_byte(code: u8) -> Option<Self> {
        Self::ALL.into_iter().find(|f| *f as u8 == code)
    }

    /// The field's name as `docs/protocol.md` writes it.
    pub fn name(self) -> &'static str {
        match self {
            Self::Latitude => "latitude",
            Self::Longitude => "longitude",
            Self::Height => "height",
            Self::Inclination => "inclination",
            Self::Azimuth => "azimuth",
            Self::Toolface => "toolface",
            Self::InclinationSigma => "inclination sigma",
            Self::AzimuthSigma => "azimuth sigma",
            Self::ToolfaceSigma => "toolface sigma",
            Self::Part => "part",
            Self::AccelBias => "accelerometer bias",
            Self::AccelCorrection => "accelerometer correction matrix",
            Self::GyroBias => "gyro bias",
            Self::GyroScale => "gyro scale factor",
            Self::ZEnter => "still entering quantile",
            Self::ZStay => "still staying quantile",
            Self::EnterEpochs => "still entering epochs",
            Self::MaxStationSamples => "longest station",
            Self::ZuptVelocitySigma => "station ZUPT velocity sigma",
            Self::IndexPositions => "indexing positions",
            Self::IndexDwell => "indexing dwell",
        }
    }
}

/// A field failed: the slice ended early, or a value is out of its range.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ReadError {
    OutOfRoom,
    OutOfRange(Field),
}

impl From<OutOfRoom> for ReadError {
    fn from(_: OutOfRoom) -> Self {
        Self::OutOfRoom
    }
}

/// `value` when it lies in [lo, hi] (NaN never does).
fn within(value: f64, lo: f64, hi: f64, field: Field) -> Result<f64, ReadError> {
    if value >= lo && value <= hi {
        Ok(value)
    } else {
        Err(ReadError::OutOfRange(field))
    }
}

/// Lowest and highest site heights (m, ellipsoidal): the Dead Sea shore is
/// at about -430 m and the highest land below 8.9 km; a number outside
/// this band is a wrong unit or a typing error, not a rig.
pub const SITE_HEIGHT_M: (f64, f64) = (-1_000.0, 9_000.0);

/// Site: latitude 24 bytes, `lat f64 rad | lon f64 rad | height f64 m`.
pub const SITE_LEN: usize = 24;

pub fn write_site(w: &mut Writer, site: &Position) -> Result<(), OutOfRoom> {
    w.f64(site.lat)?;
    w.f64(site.lon)?;
    w.f64(site.height)
}

/// Latitude in [-pi/2, pi/2], longitude in [-pi, pi], height in
/// [`SITE_HEIGHT_M`].
pub fn read_site(r: &mut Reader) -> Result<Position, ReadError> {
    Ok(Position {
        lat: within(r.f64()?, -FRAC_PI_2, FRAC_PI_2, Field::Latitude)?,
        lon: within(r.f64()?, -PI, PI, Field::Longitude)?,
        height: within(r.f64()?, SITE_HEIGHT_M.0, SITE_HEIGHT_M.1, Field::Height)?,
    })
}

/// Tie-in: inclination, azimuth, toolface, then their 1-sigma, f64 rad.
pub const TIE_IN_LEN: usize = 48;

pub fn write_tie_in(
    w: &mut Writer,
    angles: &DrillingAngles,
    sigma: &DrillingAngles,
) -> Result<(), OutOfRoom> {
    for a in [angles, sigma] {
        w.f64(a.inclination)?;
        w.f64(a.azimuth)?;
        w.f64(a.toolface)?;
    }
    Ok(())
}

/// Angles in the drilling ranges (inclination [0, pi], azimuth and toolface
/// [0, 2 pi)), sigmas in (0, pi]; the navigator's tighter limits are
/// checked where the configuration takes the tie-in.
pub fn read_tie_in(r: &mut Reader) -> Result<(DrillingAngles, DrillingAngles), ReadError> {
    let below_tau = |v: f64, field| {
        within(v, 0.0, TAU, field).and_then(|v| {
            if v < TAU {
                Ok(v)
            } else {
                Err(ReadError::OutOfRange(field))
            }
        })
    };
    let angles = DrillingAngles {
        inclination: within(r.f64()?, 0.0, PI, Field::Inclination)?,
        azimuth: below_tau(r.f64()?, Field::Azimuth)?,
        toolface: below_tau(r.f64()?, Field::Toolface)?,
    };
    let sigma = |v: f64, field| {
        within(v, 0.0, PI, field).and_then(|v| {
            if v > 0.0 {
                Ok(v)
            } else {
                Err(ReadError::OutOfRange(field))
            }
        })
    };
    let sigma = DrillingAngles {
        inclination: sigma(r.f64()?, Field::InclinationSigma)?,
        azimuth: sigma(r.f64()?, Field::AzimuthSigma)?,
        toolface: sigma(r.f64()?, Field::ToolfaceSigma)?,
    };
    Ok((angles, sigma))
}

// The calibration's ranges, which the host's calibration-file limits
// (`host_sim::analysis::calibration_file::limits`) are built from, so that
// every file the host accepts, the probe accepts: physical bounds far beyond a working
// SCC1300's errors, beyond which a number is a unit mistake or a failed
// fit, never a calibration.

/// Largest accelerometer bias accepted (m/s^2): 1 g (the part's offset is
/// tens of mg).
pub const MAX_ACCEL_BIAS_M_S2: f64 = crate::sensor_units::STANDARD_GRAVITY;
/// Diagonal of the accelerometer correction `M = K^-1`: the inverse of a
/// scale factor, 0.5 to 2.
pub const ACCEL_CORRECTION_DIAGONAL: (f64, f64) = (0.5, 2.0);
/// Off-diagonal of `M`: cross-coupling up to 0.2 (11 deg of misalignment).
pub const MAX_ACCEL_CORRECTION_OFF_DIAGONAL: f64 = 0.2;
/// Largest gyro bias accepted (rad/s): 10 deg/s (more is deg/s written as
/// rad/s, or a broken gyro).
pub const MAX_GYRO_BIAS_RAD_S: f64 = 10.0 * crate::conventions::DEG;
/// The gyro scale factor: 0.5 to 2 (the part's error is a few %).
pub const GYRO_SCALE: (f64, f64) = (0.5, 2.0);

/// A part's calibration: accelerometer bias f64 x3 (m/s^2), correction
/// f64 x9 (row-major), gyro bias f64 (rad/s), gyro scale f64.
pub const PART_CALIBRATION_LEN: usize = 14 * 8;

pub fn write_part_calibration(
    w: &mut Writer,
    accel: &TriadCalibration,
    gyro: &GyroCalibration,
) -> Result<(), OutOfRoom> {
    accel.bias.iter().try_for_each(|b| w.f64(*b))?;
    for row in &accel.correction {
        row.iter().try_for_each(|m| w.f64(*m))?;
    }
    w.f64(gyro.bias)?;
    w.f64(gyro.scale)
}

pub fn read_part_calibration(
    r: &mut Reader,
) -> Result<(TriadCalibration, GyroCalibration), ReadError> {
    let mut accel = TriadCalibration::IDENTITY;
    for b in accel.bias.iter_mut() {
        *b = within(
            r.f64()?,
            -MAX_ACCEL_BIAS_M_S2,
            MAX_ACCEL_BIAS_M_S2,
            Field::AccelBias,
        )?;
    }
    for (i, row) in accel.correction.iter_mut().enumerate() {
        for (j, m) in row.iter_mut().enumerate() {
            let (lo, hi) = if i == j {
                ACCEL_CORRECTION_DIAGONAL
            } else {
                (
                    -MAX_ACCEL_CORRECTION_OFF_DIAGONAL,
                    MAX_ACCEL_CORRECTION_OFF_DIAGONAL,
                )
            };
            *m = within(r.f64()?, lo, hi, Field::AccelCorrection)?;
        }
    }
    let gyro = GyroCalibration {
        bias: within(
            r.f64()?,
            -MAX_GYRO_BIAS_RAD_S,
            MAX_GYRO_BIAS_RAD_S,
            Field::GyroBias,
        )?,
        scale: within(r.f64()?, GYRO_SCALE.0, GYRO_SCALE.1, Field::GyroScale)?,
    };
    Ok((accel, gyro))
}

/// Both parts' calibrations, part 0 first (the configuration record).
pub fn write_probe_calibration(w: &mut Writer, c: &ProbeCalibration) -> Result<(), OutOfRoom> {
    for (accel, gyro) in c.accel.iter().zip(&c.gyro) {
        write_part_calibration(w, accel, gyro)?;
    }
    Ok(())
}

pub fn read_probe_calibration(r: &mut Reader) -> Result<ProbeCalibration, ReadError> {
    let mut c = ProbeCalibration::default();
    for (accel, gyro) in c.accel.iter_mut().zip(c.gyro.iter_mut()) {
        (*accel, *gyro) = read_part_calibration(r)?;
    }
    Ok(c)
}

/// The still detector's and the station's settings (`probe::still`,
/// `probe::navigator`): the standard normal quantiles of the entering and
/// staying tests' false-alarm probabilities, the passing epochs to enter,
/// the longest station, and the 1-sigma of each station zero-velocity
/// update. The probe's defaults are the modules' constants
/// (`config::ProbeConfig::default`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StillSettings {
    pub z_enter: f32,
    pub z_stay: f32,
    pub enter_epochs: u16,
    pub max_station_samples: u32,
    pub zupt_velocity_sigma: f32,
}

/// `z_enter`: 2 (one-sided 2.3e-2, a false "still" every few seconds) to
/// 6 (1e-9, a still probe's noise already fails it now and then).
pub const Z_ENTER: (f32, f32) = (2.0, 6.0);
/// `z_stay`: at least `z_enter` (staying must be easier than entering,
/// the hysteresis) and at most 8 (6e-16).
pub const MAX_Z_STAY: f32 = 8.0;
/// `enter_epochs`: 1 to 200 (10 s).
pub const ENTER_EPOCHS: (u16, u16) = (1, 200);
/// `max_station_samples`: 200 (10 s) to 72000 (1 h).
pub const MAX_STATION_SAMPLES: (u32, u32) = (200, 72_000);
/// `zupt_velocity_sigma` (m/s): 1 mm/s to 1 m/s.
pub const ZUPT_VELOCITY_SIGMA: (f32, f32) = (1e-3, 1.0);

/// Still settings: `z_enter f32 | z_stay f32 | enter_epochs u16 |
/// max_station_samples u32 | zupt_velocity_sigma f32`.
pub const STILL_SETTINGS_LEN: usize = 18;

pub fn write_still_settings(w: &mut Writer, s: &StillSettings) -> Result<(), OutOfRoom> {
    w.f32(s.z_enter)?;
    w.f32(s.z_stay)?;
    w.u16(s.enter_epochs)?;
    w.u32(s.max_station_samples)?;
    w.f32(s.zupt_velocity_sigma)
}

pub fn read_still_settings(r: &mut Reader) -> Result<StillSettings, ReadError> {
    let wide = |v: f32, (lo, hi): (f32, f32), field| {
        within(f64::from(v), f64::from(lo), f64::from(hi), field).map(|_| v)
    };
    let z_enter = wide(r.f32()?, Z_ENTER, Field::ZEnter)?;
    let z_stay = wide(r.f32()?, (z_enter, MAX_Z_STAY), Field::ZStay)?;
    let epochs = r.u16()?;
    if !(ENTER_EPOCHS.0..=ENTER_EPOCHS.1).contains(&epochs) {
        return Err(ReadError::OutOfRange(Field::EnterEpochs));
    }
    let longest = r.u32()?;
    if !(MAX_STATION_SAMPLES.0..=MAX_STATION_SAMPLES.1).contains(&longest) {
        return Err(ReadError::OutOfRange(Field::MaxStationSamples));
    }
    Ok(StillSettings {
        z_enter,
        z_stay,
        enter_epochs: epochs,
        max_station_samples: longest,
        zupt_velocity_sigma: wide(r.f32()?, ZUPT_VELOCITY_SIGMA, Field::ZuptVelocitySigma)?,
    })
}

/// The guided toolface-indexing procedure: the operator turns the probe
/// through `positions` toolface positions, holding each for at least
/// `dwell_s` seconds; the probe reports each dwell it detects.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct IndexingProcedure {
    pub positions: u8,
    pub dwell_s: u16,
}

/// 2 to 36 positions (every 10 deg at most).
pub const INDEX_POSITIONS: (u8, u8) = (2, 36);
/// 3 s (longer than the still detector's 1.95 s delay) to 600 s.
pub const INDEX_DWELL_S: (u16, u16) = (3, 600);
/// `positions u8 | dwell_s u16`.
pub const INDEXING_LEN: usize = 3;

pub fn write_indexing(w: &mut Writer, p: &IndexingProcedure) -> Result<(), OutOfRoom> {
    w.u8(p.positions)?;
    w.u16(p.dwell_s)
}

pub fn read_indexing(r: &mut Reader) -> Result<IndexingProcedure, ReadError> {
    let positions = r.u8()?;
    if !(INDEX_POSITIONS.0..=INDEX_POSITIONS.1).contains(&positions) {
        return Err(ReadError::OutOfRange(Field::IndexPositions));
    }
    let dwell_s = r.u16()?;
    if !(INDEX_DWELL_S.0..=INDEX_DWELL_S.1).contains(&dwell_s) {
        return Err(ReadError::OutOfRange(Field::IndexDwell));
    }
    Ok(IndexingProcedure { positions, dwell_s })
}
