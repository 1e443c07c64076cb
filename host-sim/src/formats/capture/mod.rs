//! Captures of the probe's UART stream (`.bin`: exactly the bytes the probe
//! sends, see `docs/protocol.md`): writing simulated samples as raw-sample
//! frames (and the navigation frames a probe makes of them), reading and decoding a capture with its loss statistics, and
//! exporting the frames as CSV.

use std::fmt;
use std::fs::File;
use std::io::{self, BufWriter, Read, Write};
use std::path::Path;

use anyhow::Context;
use mwd_core::earth::Position;
use mwd_core::probe::{Navigator, TieIn};
use mwd_core::protocol::bytes::OutOfRoom;
use mwd_core::protocol::frame::{raw_flags, Payload, RawPart, RawSample, NO_PART};
use mwd_core::protocol::uplink::Reply;
use mwd_core::protocol::{Decoder, DecoderStats, Frame, FrameEncoder, MAX_WIRE_LEN};
use mwd_core::protocol::{Event, EventKind};
use mwd_core::sensor_units::{
    self, ACCEL_TEMPERATURE, GYRO_TEMPERATURE, PART_COUNT, PART_MOUNTINGS,
};
use mwd_core::timing::sample_time_us;

use crate::formats::display::AzimuthStatus;
use crate::formats::samples_csv::SimSample;

mod stream;
pub use stream::{feed, CaptureSummary, FrameStream, Item, ProbeCaptureFile};

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

/// Creates a `.bin` capture file.
pub fn create_capture(path: &Path) -> io::Result<CaptureWriter<BufWriter<File>>> {
    Ok(CaptureWriter::new(BufWriter::new(File::create(path)?)))
}

/// The `code` of a simulated capture's boot event (a real probe sends its
/// firmware version, from 1): 0 marks the capture as the simulator's.
const SIMULATED_FIRMWARE_VERSION: u16 = 0;

/// Writes what a probe at `site` sends for simulated `samples`: its boot
/// event, then per sample the raw frame and the navigation frame its own
/// navigation code (the same `Navigator` the firmware runs) makes of that
/// raw frame. A configured `tie_in` is taken as the probe's main loop
/// takes it, after the first navigating cycle
/// (`firmware/src/bin/probe_qemu/main.rs`).
pub fn write_simulated_probe<W: Write>(
    capture: &mut CaptureWriter<W>,
    samples: impl IntoIterator<Item = SimSample>,
    site: Position,
    mut tie_in: Option<TieIn>,
) -> anyhow::Result<()> {
    capture.write(&Payload::Event(Event {
        time_us: 0,
        kind: EventKind::Boot,
        part: NO_PART,
        code: SIMULATED_FIRMWARE_VERSION,
        value: 0,
    }))?;
    let mut navigator = Navigator::new(site);
    for (index, s) in samples.into_iter().enumerate() {
        // Both parts' triads see the same body-frame specific force; the
        // encoder turns each into its part's axes and counts.
        let accel = [s.accel.x, s.accel.y, s.accel.z];
        let raw = raw_sample_from_si(&SiSample {
            index: u32::try_from(index).context("more than 2^32 samples")?,
            gyro_body_xz_rad_s: [s.gyro.x, s.gyro.z],
            accel_body_m_s2: [accel, accel],
            temperature_degc: 25.0,
        });
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

/// A decoded capture: the good frames in order and what was lost.
#[derive(Debug, Clone, Default)]
pub struct Capture {
    pub frames: Vec<Frame>,
    pub stats: DecoderStats,
    /// The replies to uplink commands (downlink kind 5, outside
    /// [`Payload`]: `mwd_core::protocol::uplink::reply`), each with its
    /// place among `frames`.
    pub replies: Vec<CapturedReply>,
}

/// A reply to an uplink command as the capture holds it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CapturedReply {
    /// How many of the capture's frames came before it.
    pub after_frames: usize,
    /// Its downlink sequence number (the one counter of all kinds).
    pub seq: u16,
    pub reply: Reply,
}

/// One good frame of the downlink: a telemetry frame or a reply.
#[derive(Debug, Clone, Copy)]
pub enum Received<'a> {
    Frame(&'a Frame),
    Reply { seq: u16, reply: &'a Reply },
}

impl Capture {
    /// Every good frame in the order it came, replies included.
    pub fn in_order(&self) -> impl Iterator<Item = Received<'_>> {
        let (mut next_reply, mut next_frame) = (0, 0);
        std::iter::from_fn(move || match self.replies.get(next_reply) {
            Some(r) if r.after_frames <= next_frame || next_frame >= self.frames.len() => {
                next_reply += 1;
                Some(Received::Reply {
                    seq: r.seq,
                    reply: &r.reply,
                })
            }
            _ => {
                let frame = self.frames.get(next_frame)?;
                next_frame += 1;
                Some(Received::Frame(frame))
            }
        })
    }

    /// Feeds `bytes` to `decoder`, keeping its frames and replies;
    /// `on_new` sees each as it comes.
    pub fn feed(&mut self, decoder: &mut Decoder, bytes: &[u8], mut on_new: impl FnMut(Received)) {
        stream::feed(decoder, bytes, |item| {
            self.push(item);
            on_new(item.received());
        });
    }

    /// Keeps one good item, in order.
    fn push(&mut self, item: Item) {
        match item {
            Item::Frame(frame) => self.frames.push(frame),
            Item::Reply { seq, reply } => self.replies.push(CapturedReply {
                after_frames: self.frames.len(),
                seq,
                reply,
            }),
        }
    }
}

/// A capture's bytes with frame `index` (counting every frame in the
/// order sent, the boot event first) left out: a loss on the line, for
/// tests and studies of the host's loss handling.
pub fn without_frame(bytes: &[u8], index: usize) -> Vec<u8> {
    let mut out = Vec::new();
    for (i, chunk) in bytes
        .split(|b| *b == 0)
        .filter(|c| !c.is_empty())
        .enumerate()
    {
        if i != index {
            out.push(0);
            out.extend_from_slice(chunk);
            out.push(0);
        }
    }
    out
}

/// Decodes a whole capture held in memory.
pub fn decode_bytes(bytes: &[u8]) -> Capture {
    let mut decoder = Decoder::new();
    let mut capture = Capture::default();
    capture.feed(&mut decoder, bytes, |_| {});
    decoder.finish();
    capture.stats = *decoder.stats();
    capture
}

/// Reads and decodes a whole capture from any reader into memory (a
/// command that reads a capture of any size goes through
/// [`ProbeCaptureFile`] instead, keeping only what it reports).
pub fn decode_reader(reader: impl Read) -> io::Result<Capture> {
    let mut stream = FrameStream::new(reader);
    let mut capture = Capture::default();
    while let Some(item) = stream.next_item()? {
        capture.push(item);
    }
    capture.stats = *stream.stats();
    Ok(capture)
}

/// Reads and decodes a `.bin` capture file into memory.
pub fn read_capture(path: &Path) -> io::Result<Capture> {
    decode_reader(io::BufReader::new(File::open(path)?))
}

impl fmt::Display for Capture {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        CaptureSummary::of(self).fmt(f)
    }
}

/// Columns of the CSV export: every frame is one row; the columns of the
/// other kinds stay empty. Raw counts come with their SI values (part axes).
pub const CSV_HEADER: &str = "seq,kind,time_us,sample_counter,\
p1_gyro_count,p1_gyro_temp_count,p1_ax_count,p1_ay_count,p1_az_count,p1_accel_temp_count,p1_flags,\
p2_gyro_count,p2_gyro_temp_count,p2_ax_count,p2_ay_count,p2_az_count,p2_accel_temp_count,p2_flags,\
p1_rate_rad_s,p1_ax_m_s2,p1_ay_m_s2,p1_az_m_s2,p1_gyro_temp_degc,\
p2_rate_rad_s,p2_ax_m_s2,p2_ay_m_s2,p2_az_m_s2,p2_gyro_temp_degc,\
nav_mode,nav_flags,roll_rad,pitch_rad,azimuth_rad,azimuth_status,vn_m_s,ve_m_s,vd_m_s,lat_rad,lon_rad,height_m,\
sd_roll_rad,sd_pitch_rad,sd_azimuth_rad,sd_vn_m_s,sd_ve_m_s,sd_vd_m_s,sd_pn_m,sd_pe_m,sd_pd_m,\
event,event_part,event_code,event_value,\
st_number,st_flags,st_start_sample,st_end_sample,st_inclination_rad,st_azimuth_rad,st_azimuth_status,\
st_toolface_rad,st_sd_inclination_rad,st_sd_azimuth_rad,st_sd_toolface_rad,\
st_corr_inc_azi,st_corr_inc_tf,st_corr_azi_tf,st_still_quality";

const RAW_COLS: usize = 24;
const NAV_COLS: usize = 21;
const EVENT_COLS: usize = 4;
const STATION_COLS: usize = 15;

fn empties(n: usize) -> String {
    ",".repeat(n)
}

fn join<T: fmt::Display>(values: impl IntoIterator<Item = T>) -> String {
    values
        .into_iter()
        .map(|v| format!(",{v}"))
        .collect::<String>()
}

/// Writes all frames as CSV (see [`CSV_HEADER`]).
pub fn write_csv(frames: &[Frame], mut out: impl Write) -> io::Result<()> {
    writeln!(out, "{CSV_HEADER}")?;
    for frame in frames {
        write_csv_row(frame, &mut out)?;
    }
    out.flush()
}

/// Writes one frame as a row of the CSV export (after [`CSV_HEADER`]).
pub fn write_csv_row(frame: &Frame, mut out: impl Write) -> io::Result<()> {
    let (kind, body) = match &frame.payload {
        Payload::Raw(r) => ("raw", raw_csv(r)),
        Payload::Nav(n) => {
            let mut cells = format!(",{},{}", n.time_us, n.sample_counter);
            cells += &empties(RAW_COLS);
            cells += &join([n.mode as u32, n.flags as u32]);
            cells += &join(&n.attitude[..2]);
            cells += &azimuth_cells(n);
            cells += &join(n.velocity_ned);
            cells += &join([n.latitude, n.longitude]);
            cells += &join(
                std::iter::once(&n.height)
                    .chain(&n.attitude_std)
                    .chain(&n.velocity_std)
                    .chain(&n.position_std_ned),
            );
            cells += &empties(EVENT_COLS + STATION_COLS);
            ("nav", cells)
        }
        Payload::Event(e) => {
            let mut cells = format!(",{},", e.time_us);
            cells += &empties(RAW_COLS + NAV_COLS);
            cells += &join([
                e.kind.to_byte() as u32,
                e.part as u32,
                e.code as u32,
                e.value,
            ]);
            cells += &empties(STATION_COLS);
            ("event", cells)
        }
        Payload::Station(st) => {
            // The end sample goes in the sample_counter column.
            let mut cells = format!(",{},{}", st.time_us, st.end_sample);
            cells += &empties(RAW_COLS + NAV_COLS + EVENT_COLS);
            cells += &join([
                u32::from(st.station),
                u32::from(st.flags),
                st.start_sample,
                st.end_sample,
            ]);
            cells += &join([st.angles[0]]);
            cells += &station_azimuth_cells(st);
            cells += &join(
                [st.angles[2]]
                    .iter()
                    .chain(&st.angles_std)
                    .chain(&st.correlations)
                    .chain([&st.still_quality]),
            );
            ("station", cells)
        }
    };
    writeln!(out, "{},{kind}{body}", frame.seq)
}

/// The azimuth and its status ([`AzimuthStatus`]): in [0, 2 pi) rad when
/// determined, empty when not.
fn azimuth_cells(n: &mwd_core::protocol::NavSolution) -> String {
    match AzimuthStatus::of_nav(n) {
        AzimuthStatus::Determined => {
            let wrapped = crate::formats::display::deg_0_360(f64::from(n.attitude[2])).to_radians();
            format!(",{},determined", wrapped as f32)
        }
        status => format!(",,{}", status.word()),
    }
}

/// The same for a station survey.
fn station_azimuth_cells(st: &mwd_core::protocol::StationSurvey) -> String {
    match AzimuthStatus::of_station(st) {
        AzimuthStatus::Determined => format!(",{},determined", st.angles[1]),
        status => format!(",,{}", status.word()),
    }
}

fn raw_csv(r: &RawSample) -> String {
    let mut cells = format!(",{},{}", r.time_us, r.sample_counter);
    for p in &r.parts {
        cells += &join(
            [p.gyro_rate, p.gyro_temp]
                .iter()
                .chain(&p.accel)
                .chain(&[p.accel_temp]),
        );
        cells += &format!(",{}", p.flags);
    }
    for p in &r.parts {
        let acc = p.accel.map(sensor_units::accel_count_to_m_s2);
        cells += &join(
            std::iter::once(sensor_units::gyro_count_to_rad_s(p.gyro_rate))
                .chain(acc)
                .chain([GYRO_TEMPERATURE.count_to_degc(p.gyro_temp)]),
        );
    }
    cells + &empties(NAV_COLS + EVENT_COLS + STATION_COLS)
}

#[cfg(test)]
mod tests {
    use super::*;
    use mwd_core::protocol::example;
    use mwd_core::sensor_units::{accel_count_to_m_s2, gyro_count_to_rad_s, STANDARD_GRAVITY};

    fn sample(i: u32) -> SiSample {
        let g = STANDARD_GRAVITY;
        SiSample {
            index: i,
            gyro_body_xz_rad_s: [1e-3 * f64::from(i), -0.2],
            accel_body_m_s2: [[0.1, 0.2, g], [0.3, -0.2, g + 0.01]],
            temperature_degc: 30.0,
        }
    }

    #[test]
    fn si_sample_becomes_counts_through_the_mounting() {
        let s = sample(7);
        let raw = raw_sample_from_si(&s);
        assert_eq!(raw.time_us, 350_000);
        assert_eq!(raw.sample_counter, 7);
        let lsb_rate = f64::from(gyro_count_to_rad_s(1));
        let lsb_acc = f64::from(accel_count_to_m_s2(1));
        let [p1, p2] = raw.parts;
        // Part 1 senses body x; part 2 body z.
        assert!((f64::from(gyro_count_to_rad_s(p1.gyro_rate)) - 7e-3).abs() <= lsb_rate / 2.0);
        assert!((f64::from(gyro_count_to_rad_s(p2.gyro_rate)) + 0.2).abs() <= lsb_rate / 2.0);
        // Part 2: X = body z, Y = body y, Z = -body x.
        let expect2 = [s.accel_body_m_s2[1][2], -0.2, -0.3];
        for (c, e) in p2.accel.iter().zip(expect2) {
            assert!((f64::from(accel_count_to_m_s2(*c)) - e).abs() <= lsb_acc / 2.0);
        }
        assert_eq!(p1.accel[2], 650);
        assert_eq!(p1.flags & raw_flags::GYRO_SATURATED, 0);
        assert!((f64::from(GYRO_TEMPERATURE.count_to_degc(p1.gyro_temp)) - 30.0).abs() < 0.02);
    }

    #[test]
    fn a_saturated_gyro_is_flagged_as_the_driver_flags_it_and_samples_are_stamped_n_x_50_ms() {
        let mut s = sample(3);
        // 400 deg/s about body x: beyond the specified +-300 deg/s.
        s.gyro_body_xz_rad_s = [400f64.to_radians(), -0.2];
        let raw = raw_sample_from_si(&s);
        let [p1, p2] = raw.parts;
        // The driver reports Error::Saturated: no GYRO_VALID, the
        // saturation bit, S_OK as read (firmware::app::raw_part).
        assert_eq!(
            p1.flags,
            raw_flags::GYRO_SATURATED | raw_flags::GYRO_S_OK | raw_flags::ACCEL_VALID
        );
        assert_eq!(
            p2.flags,
            raw_flags::GYRO_VALID | raw_flags::GYRO_S_OK | raw_flags::ACCEL_VALID
        );
        assert_eq!(raw.time_us, 150_000);
        // 7 g along body y: both parts' accelerometers flag SAT (6 g range).
        let mut s = sample(3);
        s.accel_body_m_s2 = [[0.0, 7.0 * 9.80665, 0.0]; 2];
        for p in raw_sample_from_si(&s).parts {
            assert_eq!(
                p.flags,
                raw_flags::GYRO_VALID | raw_flags::GYRO_S_OK | raw_flags::ACCEL_SATURATED
            );
        }
        // The simulator's own capture: sample 0 at 0 us, as the probe.
        let samples = crate::sim::SensorSimulator::new(
            crate::sim::Trajectory::paper_static(mwd_core::conventions::Euler::new(0.0, 0.0, 0.0)),
            crate::sim::SensorModel::ideal(),
            mwd_core::timing::SAMPLE_INTERVAL_S,
        )
        .take(3);
        let mut w = CaptureWriter::new(Vec::new());
        write_simulated_probe(&mut w, samples, Position::paper_site(), None).unwrap();
        let cap = decode_bytes(&w.finish().unwrap());
        let stamps: Vec<u64> = cap
            .frames
            .iter()
            .filter_map(|f| match f.payload {
                Payload::Raw(r) => Some(r.time_us),
                _ => None,
            })
            .collect();
        assert_eq!(stamps, [0, 50_000, 100_000]);
    }

    #[test]
    fn written_captures_decode_back() {
        let mut w = CaptureWriter::new(Vec::new());
        w.write(&example::boot_event()).unwrap();
        for i in 0..100 {
            w.write_si_sample(&sample(i)).unwrap();
        }
        w.write(&example::nav_solution()).unwrap();
        let n = w.bytes_written();
        let bytes = w.finish().unwrap();
        assert_eq!(bytes.len() as u64, n);
        assert_eq!(n, 27 + 100 * 51 + 106);
        let cap = decode_reader(&bytes[..]).unwrap();
        assert_eq!(cap.stats.frames, [100, 1, 1, 0]);
        assert_eq!(cap.stats.lost, 0);
        assert_eq!(
            cap.frames[5].payload,
            Payload::Raw(raw_sample_from_si(&sample(4)))
        );
        let text = cap.to_string();
        assert!(
            text.contains("raw sample 100, navigation 1, event 1"),
            "{text}"
        );
        assert!(text.contains("0 frames lost"), "{text}");
    }

    #[test]
    fn the_frame_csv_shows_an_azimuth_only_when_determined_in_0_to_2_pi() {
        use mwd_core::protocol::NavSolution;
        let nav = |azimuth: f32, sigma: f32| Frame {
            seq: 0,
            payload: Payload::Nav(NavSolution {
                attitude: [0.1, 0.2, azimuth],
                attitude_std: [0.01, 0.01, sigma],
                ..NavSolution::default()
            }),
        };
        let mut lost = nav(-1.0, f32::INFINITY);
        if let Payload::Nav(n) = &mut lost.payload {
            n.flags = mwd_core::protocol::frame::nav_flags::HEADING_LOST;
        }
        let station = |flags: u16| Frame {
            seq: 0,
            payload: Payload::Station(mwd_core::protocol::StationSurvey {
                flags,
                angles: [1.5, 2.0, 0.3],
                angles_std: [0.001, 0.01, 0.002],
                ..mwd_core::protocol::StationSurvey::default()
            }),
        };
        use mwd_core::protocol::frame::station_flags;
        let frames = [
            nav(-1.0, f32::INFINITY),
            nav(-1.0, 0.01),
            nav(f32::NAN, f32::NAN),
            lost,
            station(0),
            station(station_flags::AZIMUTH_UNDETERMINED),
            station(station_flags::AZIMUTH_UNDETERMINED | station_flags::HEADING_LOST),
        ];
        let mut out = Vec::new();
        write_csv(&frames, &mut out).unwrap();
        let text = String::from_utf8(out).unwrap();
        let rows: Vec<Vec<&str>> = text.lines().map(|l| l.split(',').collect()).collect();
        let col = |name: &str| rows[0].iter().position(|c| *c == name).unwrap();
        let (az, status) = (col("azimuth_rad"), col("azimuth_status"));
        assert_eq!((rows[1][az], rows[1][status]), ("", "undetermined"));
        let wrapped: f64 = rows[2][az].parse().unwrap();
        assert!(
            (wrapped - (std::f64::consts::TAU - 1.0)).abs() < 1e-6,
            "{wrapped}"
        );
        assert_eq!(rows[2][status], "determined");
        assert_eq!((rows[3][az], rows[3][status]), ("", "n/a"));
        assert_eq!((rows[4][az], rows[4][status]), ("", "lost"));
        assert_eq!(rows[1][col("roll_rad")], "0.1");
        let (st_az, st_status) = (col("st_azimuth_rad"), col("st_azimuth_status"));
        assert_eq!((rows[5][st_az], rows[5][st_status]), ("2", "determined"));
        assert_eq!((rows[6][st_az], rows[6][st_status]), ("", "undetermined"));
        assert_eq!((rows[7][st_az], rows[7][st_status]), ("", "lost"));
    }

    #[test]
    fn csv_has_one_row_per_frame_and_fixed_columns() {
        let frames = decode_bytes(&{
            let mut w = CaptureWriter::new(Vec::new());
            w.write(&example::raw_sample()).unwrap();
            w.write(&example::nav_solution()).unwrap();
            w.write(&example::boot_event()).unwrap();
            w.write(&example::station_survey()).unwrap();
            w.finish().unwrap()
        })
        .frames;
        let mut out = Vec::new();
        write_csv(&frames, &mut out).unwrap();
        let text = String::from_utf8(out).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), 5);
        let columns = CSV_HEADER.split(',').count();
        for line in &lines {
            assert_eq!(line.split(',').count(), columns, "{line}");
        }
        assert!(lines[1].starts_with("0,raw,61700000,1234,18,-1625,0,-3,650,"));
        assert!(lines[2].starts_with("1,nav,61700000,1234,"));
        assert!(lines[3].starts_with("2,event,0,,"));
        assert!(lines[3].contains(",1,255,1,0,"));
        assert!(
            lines[4].starts_with("3,station,1379950000,27599,"),
            "{}",
            lines[4]
        );
        assert!(
            lines[4].ends_with(",3,1,24000,27599,0.7853982,2.0943952,determined,5.2359877,0.0008727,0.020944,0.0012217,0.12,-0.35,0.05,1.02"),
            "{}",
            lines[4]
        );
    }
}
