//! Writing a capture: simulated samples as the probe's raw-sample frames,
//! and the navigation frames its own navigation code makes of them.

use crate::formats::files::OutputFile;
use std::io::{self, Write};
use std::path::Path;

use anyhow::Context;
use mwd_core::calibration::ProbeCalibration;
use mwd_core::config::default_still_settings;
use mwd_core::earth::Position;
use mwd_core::probe::{Navigator, TieIn};
use mwd_core::protocol::bytes::OutOfRoom;
use mwd_core::protocol::frame::{raw_flags, Payload, RawPart, RawSample, NO_PART};
use mwd_core::protocol::uplink::Reply;
use mwd_core::protocol::uplink::StillSettings;
use mwd_core::protocol::{Event, EventKind};
use mwd_core::protocol::{FrameEncoder, MAX_WIRE_LEN};
use mwd_core::sensor_units::{
    self, ACCEL_TEMPERATURE, GYRO_TEMPERATURE, PART_COUNT, PART_MOUNTINGS,
};
use mwd_core::timing::sample_time_us;
use nalgebra::Vector3;

use crate::formats::samples_csv::SimSample;

/// One simulated sample in SI units, body frame (x right, y forward, z up).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SiSample {
    /// Sample counter (20 Hz samples since start); the frame's time stamp
    /// follows from it as the probe's does.
    pub index: u32,
    /// What the two gyros measure: the body x rate (part 1) and the body z
    /// rate (part 2), rad/s, errors included.
    pub gyro_body_xz_rad_s: [f64; 2],
    /// Specific force each part's accelerometer measures, expressed in body
    /// axes, m/s^2 (errors included; one triad per part).
    pub accel_body_m_s2: [[f64; 3]; PART_COUNT],
    /// Temperature of both parts, degC.
    pub temperature_degc: f64,
}

/// The raw frame of sample `index` of measured body rates `gyro` (the x
/// and z gyros sense theirs) and specific force `accel`: both parts'
/// triads see the same force, both parts at 25 degC, as the simulator's
/// probe ([`raw_sample_from_si`]).
pub fn raw_sample_from_body(index: u32, gyro: &Vector3<f64>, accel: &Vector3<f64>) -> RawSample {
    let force = [accel.x, accel.y, accel.z];
    raw_sample_from_si(&SiSample {
        index,
        gyro_body_xz_rad_s: [gyro.x, gyro.z],
        accel_body_m_s2: [force, force],
        temperature_degc: 25.0,
    })
}

/// Turns a simulated sample into the raw-sample frame the probe would send:
/// body -> part axes through `PART_MOUNTINGS`, SI -> 14-bit counts
/// (rounded, saturated), flags "valid, S_OK", stamped as the probe stamps
/// sample n (`mwd_core::timing::sample_time_us`, n x 50 ms). A gyro count
/// beyond the specified range or at a 14-bit limit is flagged as the
/// probe's driver flags it (`firmware::app::raw_part`): saturated, and not
/// valid (the count is still sent).
pub fn raw_sample_from_si(sample: &SiSample) -> RawSample {
    let [x, z] = sample.gyro_body_xz_rad_s;
    // The tool-axis (y) rate is not sensed by either gyro.
    let body_rate = [x as f32, 0.0, z as f32];
    let temp = sample.temperature_degc as f32;
    let mut parts = [RawPart::default(); PART_COUNT];
    for ((part, mounting), accel) in parts
        .iter_mut()
        .zip(PART_MOUNTINGS.iter())
        .zip(sample.accel_body_m_s2.iter())
    {
        let rate = mounting.gyro_rate_from_body(body_rate);
        let sensor = mounting.body_to_sensor(accel.map(|a| a as f32));
        part.gyro_rate = sensor_units::rad_s_to_gyro_count(rate);
        part.gyro_temp = GYRO_TEMPERATURE.degc_to_count(temp);
        part.accel = sensor.map(sensor_units::m_s2_to_accel_count);
        part.accel_temp = ACCEL_TEMPERATURE.degc_to_count(temp);
        let gyro = if sensor_units::gyro_count_is_saturated(part.gyro_rate) {
            raw_flags::GYRO_SATURATED
        } else {
            raw_flags::GYRO_VALID
        };
        // An axis beyond the 6 g range: the part raises SAT and the driver
        // reports the sample saturated, not valid (firmware::scc1300::accel,
        // app::sensor_wire::raw_part). The counts are still sent.
        let accel_limit = (sensor_units::ACCEL_RANGE_G * sensor_units::ACCEL_LSB_PER_G) as i16;
        let accel = if part
            .accel
            .iter()
            .any(|c| c.unsigned_abs() > accel_limit as u16)
        {
            raw_flags::ACCEL_SATURATED
        } else {
            raw_flags::ACCEL_VALID
        };
        part.flags = gyro | accel | raw_flags::GYRO_S_OK;
    }
    RawSample {
        time_us: sample_time_us(sample.index),
        sample_counter: sample.index,
        parts,
    }
}

/// Writes frames to a capture exactly as the probe sends them (one sequence
/// counter across all kinds, starting at 0).
pub struct CaptureWriter<W: Write> {
    out: W,
    encoder: FrameEncoder,
    bytes: u64,
}

impl<W: Write> CaptureWriter<W> {
    pub fn new(out: W) -> Self {
        Self {
            out,
            encoder: FrameEncoder::new(),
            bytes: 0,
        }
    }

    /// Encodes and writes one frame.
    pub fn write(&mut self, payload: &Payload) -> io::Result<()> {
        self.write_encoded("frame", |encoder, buf| encoder.encode(payload, buf))
    }

    /// Encodes and writes a reply to an uplink command (kind 5), numbered
    /// in the same sequence as the frames, as the probe numbers it.
    pub fn write_reply(&mut self, reply: &Reply) -> io::Result<()> {
        self.write_encoded("reply", |encoder, buf| encoder.encode_reply(reply, buf))
    }

    /// Writes what `encode` puts in a wire-sized buffer (a `what`).
    fn write_encoded(
        &mut self,
        what: &str,
        encode: impl FnOnce(&mut FrameEncoder, &mut [u8]) -> Result<usize, OutOfRoom>,
    ) -> io::Result<()> {
        let mut buf = [0u8; MAX_WIRE_LEN];
        let n = encode(&mut self.encoder, &mut buf)
            .map_err(|_| io::Error::other(format!("{what} larger than MAX_WIRE_LEN")))?;
        self.out.write_all(&buf[..n])?;
        self.bytes += n as u64;
        Ok(())
    }

    /// Writes a simulated sample as a raw-sample frame.
    pub fn write_si_sample(&mut self, sample: &SiSample) -> io::Result<()> {
        self.write(&Payload::Raw(raw_sample_from_si(sample)))
    }

    /// Bytes written so far.
    pub fn bytes_written(&self) -> u64 {
        self.bytes
    }

    /// Flushes and returns the writer.
    pub fn finish(mut self) -> io::Result<W> {
        self.out.flush()?;
        Ok(self.out)
    }
}

/// Creates a `.bin` capture file, named only when finished
/// ([`OutputFile`]: `finish` the writer, then the file).
pub fn create_capture(path: &Path) -> anyhow::Result<CaptureWriter<OutputFile>> {
    Ok(CaptureWriter::new(OutputFile::create(path)?))
}

/// The `code` of a simulated capture's boot event (a real probe sends its
/// firmware version, from 1): 0 marks the capture as the simulator's.
const SIMULATED_FIRMWARE_VERSION: u16 = 0;

/// How a probe is configured: the site, the calibration, the still
/// detector's settings and the tie-in it takes after its first navigating
/// cycle. What a simulated probe runs with, and what a capture's replay
/// must be given to run as the probe did.
#[derive(Clone, Copy, Debug)]
pub struct ProbeSetup {
    pub site: Position,
    pub calibration: ProbeCalibration,
    pub still: StillSettings,
    pub tie_in: Option<TieIn>,
}

impl ProbeSetup {
    /// A probe at `site` as it boots: no calibration, the default still
    /// settings, no tie-in.
    pub fn at(site: Position) -> Self {
        Self {
            site,
            calibration: ProbeCalibration::default(),
            still: default_still_settings(),
            tie_in: None,
        }
    }

    /// The probe ran without a calibration of its parts (the identity
    /// correction, as it boots): its station sigmas do not cover the
    /// parts' turn-on biases, scale factors and misalignments.
    pub fn is_uncalibrated(&self) -> bool {
        self.calibration == ProbeCalibration::default()
    }
}

/// Writes what a probe at `site` sends for simulated `samples`: its boot
/// event, then per sample the raw frame and the navigation frame its own
/// navigation code (the same `Navigator` the firmware runs) makes of that
/// raw frame. A configured `tie_in` is taken as the probe's main loop
/// takes it, after the first navigating cycle
/// (`firmware/src/app/main_loop.rs`).
pub fn write_simulated_probe<W: Write>(
    capture: &mut CaptureWriter<W>,
    samples: impl IntoIterator<Item = SimSample>,
    probe: &ProbeSetup,
) -> anyhow::Result<()> {
    let mut tie_in = probe.tie_in;
    capture.write(&Payload::Event(Event {
        time_us: 0,
        kind: EventKind::Boot,
        part: NO_PART,
        code: SIMULATED_FIRMWARE_VERSION,
        value: 0,
    }))?;
    let mut navigator = Navigator::with_settings(probe.site, probe.calibration, &probe.still);
    for (index, s) in samples.into_iter().enumerate() {
        // Both parts' triads see the same body-frame specific force; the
        // encoder turns each into its part's axes and counts.
        let index = u32::try_from(index).context("more than 2^32 samples")?;
        let raw = raw_sample_from_body(index, &s.gyro, &s.accel);
        capture.write(&Payload::Raw(raw))?;
        capture.write(&Payload::Nav(navigator.step(&raw)))?;
        // As the probe: a finished station after its cycle's navigation.
        if let Some(station) = navigator.take_station() {
            capture.write(&Payload::Station(station))?;
        }
        if let Some(t) = tie_in.filter(|_| navigator.is_navigating()) {
            navigator.start_from_tie_in(&t);
            tie_in = None;
        }
    }
    Ok(())
}
