//! The dashboard's server-side state: everything the page shows, in
//! bounded buffers, and the JSON updates the page receives. Each frame
//! taken in is one numbered update; a page that reconnects (server-sent
//! events' `Last-Event-ID`) gets the updates it missed if the buffers
//! still hold them, or a fresh snapshot if not.
//!
//! Memory: the last [`Limits::recent_samples`] samples and solutions at
//! full rate (10 min at 20 Hz), one point per [`Limits::bucket_samples`]
//! (10 s) for the long window up to [`Limits::long_points`] (10 h), and
//! bounded lists of stations, events and commands. What is older is
//! dropped, so a session of any length holds at most these.

use std::collections::VecDeque;
use std::time::{Duration, Instant};

use mwd_core::protocol::uplink::Reply;
use mwd_core::protocol::{DecoderStats, Frame, NavSolution, Payload};
use serde_json::{json, Value};

use super::ring::{BucketMean, Ring};
use super::stations::stations_json;
use super::view::{
    attitude_channels, event_text, latest_json, sensor_channels, ATTITUDE_CHANNELS, SENSOR_CHANNELS,
};
use crate::formats::depth_log::DepthLog;
use crate::survey::stations::{StationCollector, SurveySetup};

/// The bounds of the dashboard's buffers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Limits {
    /// Samples (and solutions) kept at full rate.
    pub recent_samples: usize,
    /// Samples per point of the long window.
    pub bucket_samples: usize,
    /// Points of the long window.
    pub long_points: usize,
    pub stations: usize,
    pub events: usize,
    pub commands: usize,
}

/// The span the frame rate is counted over.
const RATE_WINDOW: Duration = Duration::from_secs(5);

/// 10 min at full rate, 10 s points over 10 h.
pub const LIMITS: Limits = Limits {
    recent_samples: 12_000,
    bucket_samples: 200,
    long_points: 3_600,
    stations: 1_000,
    events: 50,
    commands: 50,
};

/// Where the data come from, and what goes with them.
#[derive(Debug, Clone)]
pub struct SourceInfo {
    /// "capture run.bin at 10x", "port /dev/ttyUSB0 at 115200 baud".
    pub description: String,
    /// Why the probe's commands cannot be sent (replaying a file), if so.
    pub controls_disabled: Option<String>,
    /// The calibration in use, for people.
    pub calibration: Vec<String>,
    /// The job file "configure" sends, if one was given.
    pub job: Option<String>,
    /// The depth log pairing stations with MD, if one was given.
    pub depth: Option<DepthLog>,
    /// The tie-on and the probe's error model the stations are positioned
    /// with (as `survey CAPTURE --job` positions them).
    pub survey: SurveySetup,
    /// The job's well plan, (north, east, TVD) m along its MD, that the
    /// stations are drawn against.
    pub well_plan: Option<Vec<[f64; 3]>>,
}

/// One command sent to the probe and what came of it.
#[derive(Debug, Clone)]
struct CommandEntry {
    number: u64,
    label: String,
    result: String,
}

/// The lengths of the buffers (for the memory-bound test).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BufferLengths {
    pub sensors: usize,
    pub attitude: usize,
    pub long_sensors: usize,
    pub long_attitude: usize,
    pub stations: usize,
    pub events: usize,
    pub commands: usize,
}

type Point<const N: usize> = (f64, [f32; N]);

pub struct DashboardState {
    limits: Limits,
    /// Tells this server's update numbers from an earlier run's.
    session: u64,
    update: u64,
    sensors: Ring<Point<SENSOR_CHANNELS>>,
    attitude: Ring<Point<ATTITUDE_CHANNELS>>,
    long_sensors: Ring<Point<SENSOR_CHANNELS>>,
    long_attitude: Ring<Point<ATTITUDE_CHANNELS>>,
    sensor_mean: BucketMean<SENSOR_CHANNELS>,
    solutions_seen: u64,
    /// Added to the probe's clock so that time keeps increasing across
    /// probe restarts (the curves need an increasing time axis).
    time_offset_s: f64,
    last_time_s: f64,
    latest: Option<NavSolution>,
    /// The stations held (at most `limits.stations`), each with its start.
    stations: StationCollector,
    stations_dropped: u64,
    stations_view: Value,
    stations_update: u64,
    events: Ring<String>,
    events_update: u64,
    commands: VecDeque<CommandEntry>,
    commands_sent: u64,
    commands_update: u64,
    config_version: Option<u32>,
    link: DecoderStats,
    /// (when, good frames so far) of the last seconds' link updates: the
    /// rate.
    link_history: VecDeque<(Instant, u64)>,
    status: String,
    /// The source has ended: no more frames will come.
    finished: bool,
    source: SourceInfo,
}

impl DashboardState {
    pub fn new(source: SourceInfo, session: u64, limits: Limits) -> Self {
        let stations = StationCollector::default();
        let stations_view = stations_json(
            &stations,
            0,
            source.depth.as_ref(),
            &source.survey,
            source.well_plan.as_deref(),
        );
        Self {
            limits,
            session,
            update: 0,
            sensors: Ring::new(limits.recent_samples),
            attitude: Ring::new(limits.recent_samples),
            long_sensors: Ring::new(limits.long_points),
            long_attitude: Ring::new(limits.long_points),
            sensor_mean: BucketMean::new(limits.bucket_samples),
            solutions_seen: 0,
            time_offset_s: 0.0,
            last_time_s: f64::NEG_INFINITY,
            latest: None,
            stations,
            stations_dropped: 0,
            stations_view,
            stations_update: 0,
            events: Ring::new(limits.events),
            events_update: 0,
            commands: VecDeque::new(),
            commands_sent: 0,
            commands_update: 0,
            config_version: None,
            link: DecoderStats::default(),
            link_history: VecDeque::new(),
            status: "waiting for data".into(),
            finished: false,
            source,
        }
    }

    fn next_update(&mut self) -> u64 {
        self.update += 1;
        self.update
    }

    /// The session time of a probe time stamp (s).
    fn session_time(&mut self, time_us: u64) -> f64 {
        let t = time_us as f64 * 1e-6;
        if t + self.time_offset_s < self.last_time_s {
            // The probe restarted: carry on after the last time shown.
            self.time_offset_s = self.last_time_s - t + 0.05;
        }
        self.last_time_s = t + self.time_offset_s;
        self.last_time_s
    }

    /// Takes one decoded frame.
    pub fn push_frame(&mut self, frame: &Frame) {
        let update = self.next_update();
        match &frame.payload {
            Payload::Raw(raw) => {
                let t = self.session_time(raw.time_us);
                let channels = sensor_channels(raw);
                self.sensors.push(update, (t, channels));
                if let Some(point) = self.sensor_mean.push(t, &channels) {
                    self.long_sensors.push(update, point);
                }
            }
            Payload::Nav(nav) => {
                let t = self.session_time(nav.time_us);
                let channels = attitude_channels(nav);
                self.attitude.push(update, (t, channels));
                // The long window keeps one solution per bucket, not a
                // mean: azimuth and toolface wrap at 360 deg, where a mean
                // would be meaningless.
                if self.solutions_seen % self.limits.bucket_samples as u64 == 0 {
                    self.long_attitude.push(update, (t, channels));
                }
                self.solutions_seen += 1;
                self.stations.push_solution(nav);
                self.latest = Some(*nav);
            }
            Payload::Event(event) => {
                self.events.push(update, event_text(event));
                self.events_update = update;
            }
            Payload::Station(station) => {
                if self.stations.stations().len() == self.limits.stations {
                    self.stations.drop_oldest();
                    self.stations_dropped += 1;
                }
                self.stations.push_station(station);
                self.stations_view = stations_json(
                    &self.stations,
                    self.stations_dropped,
                    self.source.depth.as_ref(),
                    &self.source.survey,
                    self.source.well_plan.as_deref(),
                );
                self.stations_update = update;
            }
        }
    }

    /// The link's statistics so far, received at `now`.
    pub fn set_link(&mut self, stats: DecoderStats, now: Instant) {
        self.link = stats;
        self.link_history.push_back((now, stats.good_frames()));
        while self
            .link_history
            .front()
            .is_some_and(|(t, _)| now.duration_since(*t) > RATE_WINDOW + Duration::from_secs(1))
        {
            self.link_history.pop_front();
        }
    }

    pub fn set_status(&mut self, status: impl Into<String>) {
        self.status = status.into();
        self.update += 1;
    }

    /// The source has ended (end of the capture, the port closed), why.
    pub fn finish(&mut self, status: impl Into<String>) {
        self.set_status(status);
        self.finished = true;
    }

    /// Notes a command sent; returns its number for [`Self::command_result`].
    pub fn command_sent(&mut self, label: &str) -> u64 {
        if self.commands.len() == self.limits.commands {
            self.commands.pop_front();
        }
        self.commands_sent += 1;
        self.commands.push_back(CommandEntry {
            number: self.commands_sent,
            label: label.into(),
            result: "sent, waiting for the reply".into(),
        });
        self.commands_update = self.next_update();
        self.commands_sent
    }

    /// What came of command `number` (ACK/NAK text, or no reply).
    pub fn command_result(&mut self, number: u64, result: String, reply: Option<&Reply>) {
        // Gone from the list already if more were sent since.
        if let Some(entry) = self.commands.iter_mut().find(|c| c.number == number) {
            entry.result = result;
        }
        if let Some(reply) = reply {
            self.config_version = Some(reply.config_version);
        }
        self.commands_update = self.next_update();
    }

    pub fn buffer_lengths(&self) -> BufferLengths {
        BufferLengths {
            sensors: self.sensors.len(),
            attitude: self.attitude.len(),
            long_sensors: self.long_sensors.len(),
            long_attitude: self.long_attitude.len(),
            stations: self.stations.stations().len(),
            events: self.events.len(),
            commands: self.commands.len(),
        }
    }

    pub fn limits(&self) -> Limits {
        self.limits
    }

    /// The event id of the update made now: session and update number.
    pub fn event_id(&self) -> String {
        format!("{}-{}", self.session, self.update)
    }

    /// The update number a page that sent `last_event_id` has seen, if it
    /// can be brought up to date from the buffers (else: a snapshot).
    fn resume_from(&self, last_event_id: Option<&str>) -> Option<u64> {
        let (session, update) = last_event_id?.split_once('-')?;
        let (session, update) = (session.parse::<u64>().ok()?, update.parse::<u64>().ok()?);
        let covered = self.sensors.covers(update)
            && self.attitude.covers(update)
            && self.long_sensors.covers(update)
            && self.long_attitude.covers(update);
        (session == self.session && update <= self.update && covered).then_some(update)
    }

    /// The update for a page that has seen `last_event_id` (`None`: a new
    /// page), as JSON text: everything new since, or everything
    /// (`"reset": true`).
    pub fn update_json(&self, last_event_id: Option<&str>) -> String {
        let resume = self.resume_from(last_event_id);
        let since = resume.unwrap_or(0);
        let changed = |at: u64| resume.is_none() || at > since;
        let events: Vec<&String> = self.events.since(0).collect();
        let commands: Vec<Value> = self
            .commands
            .iter()
            .map(|c| json!({"label": c.label, "result": c.result}))
            .collect();
        let l = &self.limits;
        let rest = json!({
            "reset": resume.is_none(),
            "limits": {"recent": l.recent_samples, "long": l.long_points,
                       "bucket_s": l.bucket_samples as f64 * mwd_core::timing::SAMPLE_INTERVAL_S},
            "latest": self.latest.as_ref().map(latest_json),
            "link": self.link_json(),
            "status": self.status,
            "finished": self.finished,
            "source": {
                "description": self.source.description,
                "controls_disabled": self.source.controls_disabled,
                "calibration": self.source.calibration,
                "job": self.source.job,
                "config_version": self.config_version,
            },
            "stations": changed(self.stations_update).then_some(&self.stations_view),
            "events": changed(self.events_update).then_some(events),
            "commands": changed(self.commands_update).then_some(commands),
        });
        format!(
            r#"{{"sensors":{},"attitude":{},"long_sensors":{},"long_attitude":{},"rest":{rest}}}"#,
            rows_text(self.sensors.since(since)),
            rows_text(self.attitude.since(since)),
            rows_text(self.long_sensors.since(since)),
            rows_text(self.long_attitude.since(since)),
        )
    }

    /// Good frames per second over the last [`RATE_WINDOW`] before `now`
    /// (0 once frames stop coming); `None` before two link updates.
    fn frame_rate(&self, now: Instant) -> Option<f64> {
        let (_, latest) = self.link_history.back()?;
        let start = now.checked_sub(RATE_WINDOW)?;
        let (t0, n0) = self
            .link_history
            .iter()
            .rev()
            .find(|(t, _)| *t <= start)
            .or_else(|| self.link_history.front())?;
        let span = now.duration_since(*t0).as_secs_f64();
        (span > 0.2).then(|| (latest - n0) as f64 / span)
    }

    fn link_json(&self) -> Value {
        let s = &self.link;
        let rate = self.frame_rate(Instant::now());
        json!({
            "frames": s.good_frames(),
            "raw": s.frames[0], "nav": s.frames[1], "events": s.frames[2], "stations": s.frames[3],
            "replies_and_unknown": s.unknown_kind,
            "rate_per_s": rate,
            "lost": s.lost,
            "crc_errors": s.crc_errors,
            "malformed": s.malformed,
            "restarts": s.sequence_restarts,
            "duplicated": s.duplicated,
            "reordered": s.reordered,
            "garbage_bytes": s.garbage_bytes,
            "bytes": s.bytes,
        })
    }
}

/// `[[t, channel...], ...]`: time to the millisecond, each channel as
/// the shortest text that reads back to its f32, NaN as null (JSON has no
/// NaN).
fn rows_text<'a, const N: usize>(points: impl Iterator<Item = &'a Point<N>>) -> String {
    use std::fmt::Write;
    let mut text = String::from("[");
    for (i, (t, channels)) in points.enumerate() {
        let sep = if i == 0 { "" } else { "," };
        let _ = write!(text, "{sep}[{t:.3}");
        for v in channels {
            let _ = if v.is_finite() {
                write!(text, ",{v}")
            } else {
                write!(text, ",null")
            };
        }
        text.push(']');
    }
    text.push(']');
    text
}
