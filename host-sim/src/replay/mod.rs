//! Replay of a probe capture on the host: the raw-sample frames go through
//! the probe's own navigation code (`mwd_core::probe::Navigator`, the same
//! source the firmware runs), and where the capture also holds the probe's
//! navigation frames, each replayed solution is compared with the probe's
//! bit for bit (as encoded frames, so NaN placeholders compare equal).
//!
//! The comparison only means something while the replay's navigator has
//! seen exactly the samples the probe's did. A boot event starts a new run
//! (a new navigator, as the probe rebooted); a raw frame lost in a sequence
//! gap (the sample counter skips where frames were lost), a capture that
//! starts after the probe's first sample, or samples the probe's own
//! navigation dropped (a samples-dropped event) put the replay out of step:
//! from there to the next boot its solutions are still given, but not
//! compared, and the summary says from which sample.
//!
//! Station surveys (kind 4) are replayed the same way: the replay's
//! navigator finishes its stations at the same samples, and each is
//! compared bit for bit with the probe's station of the same number
//! ([`Replayer::stations`]). The replay's navigator keeps the station
//! links (`Navigator::track_station_links`, which do not feed back: the
//! solutions and stations are the same with them), so a station replayed
//! bit for bit also gives the link the probe's filter held but does not
//! send (the survey's chain, `survey_error::link_chain`).
//!
//! The probe's replies to uplink commands (kind 5) tell the replay which
//! commands changed the navigation and where ([`commands`]): an
//! acknowledged start surveying, take a station, toolface indexing or
//! re-align is carried out on the replay's navigator between the same two
//! samples as on the probe. To know that place, a raw frame is replayed
//! only once the probe's navigation frame of its sample (or a later one)
//! has come, or [`SETTLE_AFTER_SAMPLES`] later raw frames did (a capture
//! without navigation frames). What the replay cannot repeat (a command
//! whose place was lost with frames, a re-align with settings the downlink
//! does not carry) stops the comparison there; a reply lost altogether
//! shows as the probe's navigation mode differing from the replay's, which
//! stops it too and says so.

pub mod commands;
pub mod file_replay;
pub mod live;
pub mod report;

use std::collections::{HashMap, VecDeque};
use std::io::{self, Write};

use mwd_core::calibration::ProbeCalibration;
use mwd_core::config::default_still_settings;
use mwd_core::conventions::{DrillingAngles, Euler};
use mwd_core::earth::Position;
use mwd_core::probe::{Navigator, StationLink, TieIn};
use mwd_core::protocol::decoder::starts_a_run;
use mwd_core::protocol::frame::{nav_flags, station_flags, MAX_BODY_LEN};
use mwd_core::protocol::uplink::IndexingProcedure;
use mwd_core::protocol::uplink::StillSettings;
use mwd_core::protocol::{
    encode_body, EventKind, Frame, NavSolution, Payload, RawSample, StationSurvey,
};

use crate::formats::capture::{Capture, Received};
use crate::formats::display;
use commands::{CommandRow, Effect};

/// One replayed solution and how it compares with the probe's own.
#[derive(Debug, Clone, Copy)]
pub struct ReplayRow {
    pub solution: NavSolution,
    /// Whether the probe's solution for the same sample was identical;
    /// `None` while it has not arrived (or never did), and always for a
    /// row replayed out of step.
    pub matches_probe: Option<bool>,
    /// The replay had seen the same samples as the probe's navigation.
    pub in_step: bool,
}

/// One replayed station survey and how it compares with the probe's.
#[derive(Debug, Clone, Copy)]
pub struct StationRow {
    pub station: StationSurvey,
    /// Whether the probe's station of the same number was identical;
    /// `None` while it has not arrived (or never did), and always for a
    /// station replayed out of step.
    pub matches_probe: Option<bool>,
    pub in_step: bool,
    /// The replay's link of this station to its previous one.
    pub link: Option<StationLink>,
}

/// What the replay did with station surveys.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct StationSummary {
    /// Stations the replay finished.
    pub replayed: u64,
    /// Station frames in the capture.
    pub probe: u64,
    pub matched: u64,
    pub mismatched: u64,
    /// Probe stations not compared: out of step, or the replay finished
    /// no station of that number.
    pub unchecked: u64,
}

/// What a replay did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ReplaySummary {
    pub raw_frames: u64,
    pub probe_solutions: u64,
    /// Replayed solutions identical to the probe's / different from it.
    pub matched: u64,
    pub mismatched: u64,
    /// Probe solutions not compared: the replay was out of step.
    pub unchecked: u64,
    /// Raw frames with a part's data not valid (skipped or faulty samples).
    pub degraded: u64,
    /// Boot events after the first frame: the probe restarted, and so did
    /// the replay's navigation.
    pub restarts: u64,
}

/// Why and where the replay went out of step with the probe.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StepLoss {
    /// The run (0 before the first restart).
    pub run: u64,
    /// The first sample not compared.
    pub from_sample: u32,
    pub reason: StepLossReason,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StepLossReason {
    /// Raw frames were lost (a sequence gap, and the sample counter skips).
    RawFramesLost,
    /// The capture starts after the probe's first sample.
    StartsMidRun,
    /// The probe's navigation dropped samples (a samples-dropped event).
    ProbeDroppedSamples,
    /// Frames were lost between a command's reply and the navigation frame
    /// before it: the sample at which the command took effect is not known.
    CommandPlaceUnknown { command_seq: u16 },
    /// The probe re-aligned or restarted with a configuration the replay
    /// does not have (settings acknowledged since the run began, or a
    /// configuration version other than the capture's first).
    ConfigurationChanged,
    /// The replay's navigator refused a command the probe acknowledged.
    ReplayRefusedCommand { command_seq: u16 },
    /// An acknowledged command of a kind this replay does not know.
    UnknownCommand { command_seq: u16 },
    /// The probe's navigation mode differs from the replay's: a command
    /// the replay did not carry out, its reply lost when `frames_lost`.
    ModeDiffers {
        probe_mode: u8,
        replay_mode: u8,
        frames_lost: bool,
    },
    /// Toolface indexing without its parameters: the station surveys (not
    /// the navigation) are not compared until the run re-aligns or ends.
    IndexingUnknown { command_seq: u16 },
    /// A station sent on request or as an indexing dwell by the probe or
    /// the replay only, with frames lost: a lost reply. Station surveys
    /// only, as for `IndexingUnknown`.
    StationCommandLost { station: u16 },
}

impl StepLossReason {
    /// Whether this loss means the replay and the probe differ (rather than
    /// the capture missing something).
    pub fn is_a_difference(&self) -> bool {
        matches!(
            self,
            Self::ReplayRefusedCommand { .. }
                | Self::ModeDiffers {
                    frames_lost: false,
                    ..
                }
        )
    }
}

impl std::fmt::Display for StepLoss {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let why = match self.reason {
            StepLossReason::RawFramesLost => "raw frames lost before it".to_string(),
            StepLossReason::StartsMidRun => {
                "the capture starts after the probe's first sample".to_string()
            }
            StepLossReason::ProbeDroppedSamples => {
                "the probe's navigation dropped samples".to_string()
            }
            StepLossReason::CommandPlaceUnknown { command_seq } => format!(
                "frames lost before the reply to command {command_seq}: the sample at which \
                 it took effect is not known"
            ),
            StepLossReason::ConfigurationChanged => "the probe re-aligned or restarted with \
                 settings the downlink does not carry (replay it with those settings)"
                .to_string(),
            StepLossReason::ReplayRefusedCommand { command_seq } => format!(
                "the replay's navigator refused command {command_seq}, which the probe \
                 acknowledged: they DIFFER"
            ),
            StepLossReason::UnknownCommand { command_seq } => {
                format!("command {command_seq} is of a kind this replay does not know")
            }
            StepLossReason::ModeDiffers {
                probe_mode,
                replay_mode,
                frames_lost,
            } => {
                let cause = if frames_lost {
                    "frames were lost: most likely the reply to a start surveying or re-align"
                } else {
                    "no frame was lost: the replay DIFFERS from the probe"
                };
                let name = |mode| crate::replay::live::mode_name(mode).trim_end();
                format!(
                    "the probe's navigation mode is {} ({probe_mode}), the replay's {} \
                     ({replay_mode}); {cause}",
                    name(probe_mode),
                    name(replay_mode)
                )
            }
            StepLossReason::StationCommandLost { station } => format!(
                "station surveys only: station {station} was sent on a command by one side \
                 only, and frames were lost: most likely a reply to take a station or \
                 toolface indexing"
            ),
            StepLossReason::IndexingUnknown { command_seq } => format!(
                "station surveys only: toolface indexing (command {command_seq}) without its \
                 parameters (give the uplink log)"
            ),
        };
        write!(
            f,
            "run {}: not compared from sample {} on ({why})",
            self.run, self.from_sample
        )
    }
}

/// `navigator` keeping its station links ([`StationRow::link`]).
fn linked(mut navigator: Navigator) -> Navigator {
    navigator.track_station_links(true);
    navigator
}

/// Replays every raw frame of `frames` through the navigation, starting at
/// `position` (the probe's configured site), with uncalibrated sensors.
pub fn replay(frames: &[Frame], position: Position) -> (Vec<ReplayRow>, ReplaySummary) {
    replay_with(frames, position, ProbeCalibration::default())
}

/// The same with the probe's sensor calibration (what
/// `Navigator::with_calibration` is given).
pub fn replay_with(
    frames: &[Frame],
    position: Position,
    calibration: ProbeCalibration,
) -> (Vec<ReplayRow>, ReplaySummary) {
    let mut replayer = Replayer::with_calibration(position, calibration);
    for frame in frames {
        replayer.push(frame);
    }
    replayer.finish()
}

/// Replays a decoded capture, its replies to uplink commands included.
pub fn replay_capture(
    capture: &Capture,
    position: Position,
    calibration: ProbeCalibration,
) -> (Vec<ReplayRow>, ReplaySummary) {
    let mut replayer = Replayer::with_calibration(position, calibration);
    for received in capture.in_order() {
        replayer.push_received(received);
    }
    replayer.finish()
}

/// The station links of a capture's station frames (`stations`, in the
/// capture's order), from `replayer`, which has taken the whole capture
/// with the probe's site, calibration, still settings and tie-in
/// (`Replayer::with_settings`, `with_tie_in`): one per station when every
/// station frame was replayed bit for bit, in the same order (the replay's
/// filter then held the probe's, and its links are the ones the probe's
/// would have kept); otherwise why not, for the survey to say (it then
/// chains the azimuth alone).
pub fn replayed_station_links(
    replayer: &mut Replayer,
    stations: &[StationSurvey],
) -> Result<Vec<Option<StationLink>>, String> {
    let (rows, summary) = replayer.stations();
    let same = rows.len() == stations.len()
        && rows.iter().zip(stations).all(|(row, probe)| {
            row.matches_probe == Some(true)
                && encoded_payload(&Payload::Station(row.station))
                    == encoded_payload(&Payload::Station(*probe))
        });
    if !same {
        return Err(format!(
            "{} of the capture's {} station frames replayed bit for bit ({} replayed, {} \
             different, {} not compared)",
            summary.matched,
            stations.len(),
            summary.replayed,
            summary.mismatched,
            summary.unchecked
        ));
    }
    Ok(rows.iter().map(|r| r.link).collect())
}

/// Rows of a live replay still waiting for the probe's solution after this
/// many later samples are written without it: more than the probe's
/// navigation inbox can hold back (32 samples). Also how many raw frames
/// wait for their navigation frame before they are replayed without it.
pub const SETTLE_AFTER_SAMPLES: usize = 64;

/// How many items a replay of a file takes between writing out (and
/// forgetting) its settled rows ([`Replayer::write_settled`]): no one
/// waits for a file's rows, so they go in batches.
pub const FILE_BATCH_ITEMS: usize = 4096;

/// The replay one frame at a time, for a live stream: a raw frame is
/// replayed as soon as the probe's navigation frame of its sample (or a
/// later one) has come, which places it among the commands' replies (see
/// the module's notes). The probe sends a sample's navigation frame after
/// its raw frame, but the comparison does not rely on that order: a
/// solution waits for its partner on either side.
pub struct Replayer {
    position: Position,
    calibration: ProbeCalibration,
    /// The probe's still settings (`Navigator::with_settings`).
    still: StillSettings,
    /// The probe's configured tie-in ([`Replayer::with_tie_in`]), and the
    /// one this navigator has still to start from.
    tie_in: Option<TieIn>,
    tie_in_pending: Option<TieIn>,
    navigator: Navigator,
    /// The replayed rows not forgotten yet ([`Replayer::forget_settled`]):
    /// `rows[0]` is row number `rows_forgotten` of the replay.
    rows: Vec<ReplayRow>,
    rows_forgotten: usize,
    /// The newest replayed row (kept when it is forgotten).
    last_row: Option<ReplayRow>,
    /// Replayed samples the probe's solution has not arrived for yet, by
    /// sample counter (of the current run).
    awaiting_probe: HashMap<u32, Awaiting>,
    /// The probe's solutions whose raw frame has not arrived yet.
    early_probe: HashMap<u32, NavSolution>,
    summary: ReplaySummary,
    step: StepTracker,
    step_losses: Vec<StepLoss>,
    /// Rows already handed out by [`Replayer::settled_rows`] (a row
    /// number of the replay).
    settled: usize,
    station_rows: Vec<StationRow>,
    /// Replayed stations waiting for the probe's, by station number, in
    /// order (a still period's frame may be sent twice: a dwell, then on
    /// request).
    awaiting_station: Partners<usize>,
    /// The probe's stations the replay has not finished yet.
    early_station: Partners<StationSurvey>,
    station_summary: StationSummary,
    /// Raw frames waiting for the place of any command before them, with
    /// whether the replay was in step when each came.
    held: VecDeque<(RawSample, bool)>,
    /// Acknowledged commands not carried out yet: (index into
    /// `command_rows`, what to do).
    scheduled: VecDeque<(usize, Effect)>,
    command_rows: Vec<CommandRow>,
    /// The toolface-indexing procedures the host sent, by command sequence
    /// number ([`Replayer::knows_sent_command`]).
    sent_indexing: HashMap<u16, IndexingProcedure>,
    run: RunState,
    /// The configuration version of the capture's first boot event that
    /// reported one: the configuration the replay is taken to have.
    first_config_version: Option<u32>,
}

/// A replayed sample waiting for the probe's solution.
#[derive(Debug, Clone, Copy)]
enum Awaiting {
    /// Its row, by row number.
    Row(usize),
    /// Its row (row number `number`) was forgotten before the probe's
    /// solution came (a capture whose navigation frames come late or not
    /// at all): the comparison still counts.
    Forgotten { number: usize, row: ReplayRow },
}

/// What the commands need to know of the current run.
#[derive(Debug, Clone, Copy)]
struct RunState {
    /// The sample of the probe's last navigation frame.
    last_probe_nav: Option<u32>,
    /// A frame was lost since that navigation frame (or since the boot).
    lost_since_nav: bool,
    /// A frame was lost in this run.
    lost_in_run: bool,
    raw_seen: bool,
    /// The last sample the replay's navigator stepped.
    stepped_through: Option<u32>,
    /// Settings were acknowledged in this run (a re-align then uses values
    /// the replay does not have).
    settings_changed: bool,
    /// The configuration version of this run's boot event.
    boot_version: Option<u32>,
    /// Samples from this one on are not compared (a command's loss).
    unchecked_from: Option<u32>,
    /// Station surveys are compared (not while indexing without its
    /// parameters).
    stations_in_step: bool,
}

impl Default for RunState {
    fn default() -> Self {
        Self {
            last_probe_nav: None,
            lost_since_nav: false,
            lost_in_run: false,
            raw_seen: false,
            stepped_through: None,
            settings_changed: false,
            boot_version: None,
            unchecked_from: None,
            stations_in_step: true,
        }
    }
}

/// Station frames (or replayed stations) waiting for their partner, by
/// station number, oldest first.
struct Partners<T>(HashMap<u16, VecDeque<T>>);

impl<T> Default for Partners<T> {
    fn default() -> Self {
        Self(HashMap::new())
    }
}

impl<T> Partners<T> {
    fn add(&mut self, station: u16, item: T) {
        self.0.entry(station).or_default().push_back(item);
    }

    fn take(&mut self, station: u16) -> Option<T> {
        self.0.get_mut(&station)?.pop_front()
    }

    fn len(&self) -> u64 {
        self.0.values().map(|q| q.len() as u64).sum()
    }
}

/// Whether the replay has seen what the probe's navigation saw.
#[derive(Debug, Clone, Copy, Default)]
struct StepTracker {
    seen_any: bool,
    expected_seq: Option<u16>,
    /// A sequence gap since the last raw frame.
    gap_since_raw: bool,
    /// The probe reported dropping samples since the last raw frame.
    dropped_since_raw: bool,
    last_counter: Option<u32>,
    /// This run began with its boot event in the capture.
    from_boot: bool,
    in_step: bool,
}

impl Replayer {
    pub fn new(position: Position) -> Self {
        Self::with_calibration(position, ProbeCalibration::default())
    }

    pub fn with_calibration(position: Position, calibration: ProbeCalibration) -> Self {
        Self::with_settings(position, calibration, default_still_settings())
    }

    /// The same with the probe's still settings (a job's, as `probe
    /// configure` sent them).
    pub fn with_settings(
        position: Position,
        calibration: ProbeCalibration,
        still: StillSettings,
    ) -> Self {
        Self {
            position,
            calibration,
            still,
            tie_in: None,
            tie_in_pending: None,
            navigator: linked(Navigator::with_settings(position, calibration, &still)),
            rows: Vec::new(),
            rows_forgotten: 0,
            last_row: None,
            awaiting_probe: HashMap::new(),
            early_probe: HashMap::new(),
            summary: ReplaySummary::default(),
            step: StepTracker {
                in_step: true,
                ..StepTracker::default()
            },
            step_losses: Vec::new(),
            settled: 0,
            station_rows: Vec::new(),
            awaiting_station: Partners::default(),
            early_station: Partners::default(),
            station_summary: StationSummary::default(),
            held: VecDeque::new(),
            scheduled: VecDeque::new(),
            command_rows: Vec::new(),
            sent_indexing: HashMap::new(),
            run: RunState::default(),
            first_config_version: None,
        }
    }

    /// The probe's configured tie-in (a job's, as `probe configure` sent
    /// it): the replay's navigator starts from it where the probe's does,
    /// after the first cycle that navigates (its main loop,
    /// `firmware/src/bin/probe_qemu/main.rs`), after each boot and
    /// re-align. A probe that stepped several samples in that pass took it
    /// later: its solutions then differ from there, and say so.
    pub fn with_tie_in(mut self, tie_in: Option<TieIn>) -> Self {
        self.tie_in = tie_in;
        self.tie_in_pending = tie_in;
        self
    }

    /// Takes one good frame of the downlink, telemetry or reply.
    pub fn push_received(&mut self, received: Received) -> Option<NavSolution> {
        match received {
            Received::Frame(frame) => self.push(frame),
            Received::Reply { seq, reply } => {
                self.push_reply(seq, reply);
                None
            }
        }
    }

    /// Notes a frame's sequence number: a gap is a loss.
    fn note_seq(&mut self, seq: u16) {
        if let Some(expected) = self.step.expected_seq {
            if seq != expected {
                self.step.gap_since_raw = true;
                self.run.lost_since_nav = true;
                self.run.lost_in_run = true;
            }
        }
        self.step.expected_seq = Some(seq.wrapping_add(1));
    }

    /// Stops the comparison of this run's samples from `from_sample` on.
    fn lose_from(&mut self, from_sample: u32, reason: StepLossReason) {
        let stations_only = matches!(
            reason,
            StepLossReason::IndexingUnknown { .. } | StepLossReason::StationCommandLost { .. }
        );
        if stations_only {
            self.run.stations_in_step = false;
        } else {
            if self.run.unchecked_from.is_some_and(|f| f <= from_sample) {
                return;
            }
            self.run.unchecked_from = Some(from_sample);
        }
        self.step_losses.push(StepLoss {
            run: self.summary.restarts,
            from_sample,
            reason,
        });
    }

    /// Takes one decoded frame; returns the newest solution it let the
    /// replay step (a raw frame waits for its sample's navigation frame).
    pub fn push(&mut self, frame: &Frame) -> Option<NavSolution> {
        self.note_seq(frame.seq);
        let seen_before = std::mem::replace(&mut self.step.seen_any, true);
        match frame.payload {
            _ if starts_a_run(frame.seq, &frame.payload) => {
                // The last run's held samples, as its navigator would have.
                self.end_of_stream();
                if seen_before {
                    self.summary.restarts += 1;
                }
                self.restart_navigation();
                if let Payload::Event(boot) = frame.payload {
                    self.note_boot_configuration(boot.value);
                }
                None
            }
            Payload::Event(e) if e.kind == EventKind::SamplesDropped => {
                self.step.dropped_since_raw = true;
                None
            }
            Payload::Nav(on_board) => {
                self.summary.probe_solutions += 1;
                self.run.last_probe_nav = Some(on_board.sample_counter);
                self.run.lost_since_nav = false;
                match self.awaiting_probe.remove(&on_board.sample_counter) {
                    Some(Awaiting::Row(index)) => self.compare(index, &on_board),
                    Some(Awaiting::Forgotten { number, mut row }) => {
                        self.compare_row(&mut row, &on_board);
                        self.note_newest(number, row);
                    }
                    None => {
                        self.early_probe.insert(on_board.sample_counter, on_board);
                    }
                }
                self.step_held(false)
            }
            Payload::Raw(raw) => {
                self.summary.raw_frames += 1;
                self.run.raw_seen = true;
                self.check_step(raw.sample_counter);
                self.held.push_back((raw, self.step.in_step));
                self.step_held(false)
            }
            Payload::Station(on_board) => {
                self.station_summary.probe += 1;
                match self.awaiting_station.take(on_board.station) {
                    Some(index) => self.compare_station(index, &on_board),
                    None => self.early_station.add(on_board.station, on_board),
                }
                None
            }
            Payload::Event(_) => None,
        }
    }

    /// Replays the held raw frames whose place among the commands is known
    /// (all of them at the end of the stream): those up to the sample of
    /// the probe's latest navigation frame, and any beyond
    /// [`SETTLE_AFTER_SAMPLES`] held.
    fn step_held(&mut self, all: bool) -> Option<NavSolution> {
        let mut newest = None;
        while let Some(&(raw, in_step)) = self.held.front() {
            let placed = self
                .run
                .last_probe_nav
                .is_some_and(|n| raw.sample_counter <= n);
            if !(all || placed || self.held.len() > SETTLE_AFTER_SAMPLES) {
                break;
            }
            self.held.pop_front();
            newest = Some(self.step_raw(raw, in_step));
        }
        newest
    }

    /// Replays every held raw frame: the stream ended (or a new run began).
    pub fn end_of_stream(&mut self) {
        self.step_held(true);
    }

    fn step_raw(&mut self, raw: RawSample, arrived_in_step: bool) -> NavSolution {
        let counter = raw.sample_counter;
        self.apply_due_commands(counter);
        let solution = self.navigator.step(&raw);
        self.run.stepped_through = Some(counter);
        if solution.flags & nav_flags::SENSOR_DEGRADED != 0 {
            self.summary.degraded += 1;
        }
        let index = self.rows_replayed();
        self.rows.push(ReplayRow {
            solution,
            matches_probe: None,
            in_step: arrived_in_step && self.compared(counter),
        });
        match self.early_probe.remove(&counter) {
            Some(on_board) => self.compare(index, &on_board),
            None => {
                self.awaiting_probe.insert(counter, Awaiting::Row(index));
            }
        }
        self.last_row = self.rows.last().copied();
        if let Some(station) = self.navigator.take_station() {
            self.replayed_station(station, counter);
        }
        if let Some(tie_in) = self
            .tie_in_pending
            .filter(|_| self.navigator.is_navigating())
        {
            self.navigator.start_from_tie_in(&tie_in);
            self.tie_in_pending = None;
        }
        solution
    }

    /// Whether no command's loss stops the comparison at sample `counter`.
    fn compared(&self, counter: u32) -> bool {
        self.run.unchecked_from.is_none_or(|from| counter < from)
    }

    /// A boot event's configuration version (bits 16-31 of its value,
    /// docs/protocol.md "Event codes"; 0: not reported): a run with
    /// another configuration than the capture's first is not compared.
    fn note_boot_configuration(&mut self, boot_value: u32) {
        if boot_value == 0 {
            return;
        }
        let version = boot_value >> 16;
        self.run.boot_version = Some(version);
        match self.first_config_version {
            None => self.first_config_version = Some(version),
            Some(first) if first != version => {
                self.lose_from(0, StepLossReason::ConfigurationChanged)
            }
            Some(_) => {}
        }
    }

    fn replayed_station(&mut self, station: StationSurvey, counter: u32) {
        self.station_summary.replayed += 1;
        let index = self.station_rows.len();
        // In step as the newest replayed sample was.
        let arrived_in_step = self.last_row.is_none_or(|r| r.in_step);
        let link = self
            .navigator
            .station_link()
            .filter(|l| l.station == station.station)
            .copied();
        self.station_rows.push(StationRow {
            station,
            matches_probe: None,
            in_step: arrived_in_step && self.compared(counter) && self.run.stations_in_step,
            link,
        });
        match self.early_station.take(station.station) {
            Some(on_board) => self.compare_station(index, &on_board),
            None => self.awaiting_station.add(station.station, index),
        }
    }

    fn compare_station(&mut self, index: usize, on_board: &StationSurvey) {
        let Some(row) = self.station_rows.get_mut(index) else {
            return;
        };
        if !row.in_step {
            self.station_summary.unchecked += 1;
            return;
        }
        let same = encoded_payload(&Payload::Station(*on_board))
            == encoded_payload(&Payload::Station(row.station));
        let by_command = station_flags::REQUESTED | station_flags::INDEXING_DWELL;
        if !same && (on_board.flags ^ row.station.flags) & by_command != 0 && self.run.lost_in_run {
            // Sent on a command on one side only, frames lost: most likely
            // a lost reply, not a difference.
            row.in_step = false;
            self.station_summary.unchecked += 1;
            let station = on_board.station;
            let from = self.run.stepped_through.unwrap_or(0);
            self.lose_from(from, StepLossReason::StationCommandLost { station });
            return;
        }
        row.matches_probe = Some(same);
        if same {
            self.station_summary.matched += 1;
        } else {
            self.station_summary.mismatched += 1;
        }
    }

    /// The replayed stations (in order) and their comparison, at the end of
    /// the stream: the held raw frames are replayed first. A probe station
    /// whose partner has not been replayed counts as unchecked.
    pub fn stations(&mut self) -> (&[StationRow], StationSummary) {
        self.end_of_stream();
        let mut summary = self.station_summary;
        summary.unchecked += self.early_station.len();
        (&self.station_rows, summary)
    }

    /// Station numbers start again at 1 (a boot, a re-align): older
    /// partners can never match.
    fn forget_station_partners(&mut self) {
        self.station_summary.unchecked += self.early_station.len();
        self.awaiting_station = Partners::default();
        self.early_station = Partners::default();
    }

    /// A boot event: the probe started again, so does the replay.
    fn restart_navigation(&mut self) {
        self.navigator = linked(Navigator::with_settings(
            self.position,
            self.calibration,
            &self.still,
        ));
        self.tie_in_pending = self.tie_in;
        // Sample counters start again at 0: older partners can never match;
        // a probe solution whose raw frame was lost was not compared.
        self.summary.unchecked += self.early_probe.len() as u64;
        self.awaiting_probe.clear();
        self.early_probe.clear();
        self.forget_station_partners();
        // Commands the last run never reached are dropped with it.
        self.scheduled.clear();
        self.run = RunState::default();
        self.step = StepTracker {
            seen_any: true,
            expected_seq: self.step.expected_seq,
            from_boot: true,
            in_step: true,
            ..StepTracker::default()
        };
    }

    /// Whether the raw frame of sample `counter` keeps the replay in step.
    fn check_step(&mut self, counter: u32) {
        let step = &mut self.step;
        let reason = match step.last_counter {
            // The navigator starts where the probe's did: at its boot event
            // with nothing lost since, or (no boot event) at sample 0.
            None if step.from_boot && step.gap_since_raw && counter != 0 => {
                Some(StepLossReason::RawFramesLost)
            }
            None if !step.from_boot && counter != 0 => Some(StepLossReason::StartsMidRun),
            None => None,
            // A skip with no frame lost is the probe's own (a resync): its
            // navigation saw the same samples.
            Some(last) if step.gap_since_raw && counter != last.wrapping_add(1) => {
                Some(StepLossReason::RawFramesLost)
            }
            Some(_) if step.dropped_since_raw => Some(StepLossReason::ProbeDroppedSamples),
            Some(_) => None,
        };
        step.last_counter = Some(counter);
        step.gap_since_raw = false;
        step.dropped_since_raw = false;
        if let (true, Some(reason)) = (step.in_step, reason) {
            step.in_step = false;
            self.step_losses.push(StepLoss {
                run: self.summary.restarts,
                from_sample: counter,
                reason,
            });
        }
    }

    /// Compares row number `index` with the probe's solution.
    fn compare(&mut self, index: usize, on_board: &NavSolution) {
        let Some(at) = index.checked_sub(self.rows_forgotten) else {
            return;
        };
        let Some(mut row) = self.rows.get(at).copied() else {
            return;
        };
        self.compare_row(&mut row, on_board);
        self.rows[at] = row;
        self.note_newest(index, row);
    }

    /// Row number `index` changed: the newest row is kept apart too.
    fn note_newest(&mut self, index: usize, row: ReplayRow) {
        if self.rows_replayed() == index + 1 {
            self.last_row = Some(row);
        }
    }

    fn compare_row(&mut self, row: &mut ReplayRow, on_board: &NavSolution) {
        let compared = self.compared(on_board.sample_counter);
        let lost_in_run = self.run.lost_in_run;
        row.in_step &= compared;
        if !row.in_step {
            self.summary.unchecked += 1;
            return;
        }
        let same = encoded(on_board) == encoded(&row.solution);
        let replay_mode = row.solution.mode;
        if on_board.mode != replay_mode {
            // A navigation phase the replay is not in: a command it did not
            // carry out. After a loss, most likely a lost reply: not
            // compared; with nothing lost, a difference.
            if lost_in_run {
                row.in_step = false;
                self.summary.unchecked += 1;
            } else {
                row.matches_probe = Some(false);
                self.summary.mismatched += 1;
            }
            let reason = StepLossReason::ModeDiffers {
                probe_mode: on_board.mode,
                replay_mode,
                frames_lost: lost_in_run,
            };
            let from = on_board
                .sample_counter
                .wrapping_add(u32::from(!lost_in_run));
            self.lose_from(from, reason);
            return;
        }
        row.matches_probe = Some(same);
        if same {
            self.summary.matched += 1;
        } else {
            self.summary.mismatched += 1;
        }
    }

    /// The replay so far.
    pub fn summary(&self) -> &ReplaySummary {
        &self.summary
    }

    /// Where the replay went out of step with the probe, in order.
    pub fn step_losses(&self) -> &[StepLoss] {
        &self.step_losses
    }

    /// Rows not handed out before whose comparison is settled (compared,
    /// out of step, or left without the probe's solution for
    /// [`SETTLE_AFTER_SAMPLES`] samples), in order: what a live replay can
    /// write now. `all` settles every row (the stream ended).
    pub fn settled_rows(&mut self, all: bool) -> &[ReplayRow] {
        let from = self.settled - self.rows_forgotten;
        // Held raw frames count as later samples.
        let newest = self.rows.len() + self.held.len();
        let settled = self.rows[from..]
            .iter()
            .enumerate()
            .take_while(|(i, row)| {
                all || row.matches_probe.is_some()
                    || !row.in_step
                    || newest - (from + i) > SETTLE_AFTER_SAMPLES
            })
            .count();
        self.settled += settled;
        &self.rows[from..from + settled]
    }

    /// Forgets the rows [`settled_rows`](Self::settled_rows) handed out, so
    /// that a replay of any length (a live session, a day and a half of
    /// drilling) keeps only the rows still settling. A forgotten row whose
    /// probe solution has not come keeps its place in the comparison.
    pub fn forget_settled(&mut self) {
        let n = self.settled - self.rows_forgotten;
        for (k, row) in self.rows.drain(..n).enumerate() {
            let number = self.rows_forgotten + k;
            let counter = row.solution.sample_counter;
            if let Some(a) = self.awaiting_probe.get_mut(&counter) {
                if matches!(*a, Awaiting::Row(i) if i == number) {
                    *a = Awaiting::Forgotten { number, row };
                }
            }
        }
        self.rows_forgotten += n;
    }

    /// Writes the settled rows (all of them when `all`: the stream ended)
    /// to `csv` as CSV rows, flushed, and forgets them: a replay streaming
    /// its rows out keeps only the ones still settling.
    pub fn write_settled(
        &mut self,
        csv: Option<&mut (dyn Write + '_)>,
        all: bool,
    ) -> io::Result<()> {
        let rows = self.settled_rows(all);
        if let Some(out) = csv {
            if !rows.is_empty() {
                write_csv_rows(rows, &mut *out)?;
                out.flush()?;
            }
        }
        self.forget_settled();
        Ok(())
    }

    /// How many rows the replay has made (one per raw frame replayed),
    /// forgotten ones included.
    pub fn rows_replayed(&self) -> usize {
        self.rows_forgotten + self.rows.len()
    }

    /// The newest replayed row, forgotten or not.
    pub fn last_row(&self) -> Option<&ReplayRow> {
        self.last_row.as_ref()
    }

    /// The replayed rows not forgotten (one per raw frame, in arrival
    /// order: all of them unless [`forget_settled`](Self::forget_settled)
    /// was called) and the summary (probe solutions whose raw frame never
    /// came count as unchecked).
    pub fn finish(mut self) -> (Vec<ReplayRow>, ReplaySummary) {
        self.end_of_stream();
        self.summary.unchecked += self.early_probe.len() as u64;
        (self.rows, self.summary)
    }
}

fn encoded(nav: &NavSolution) -> Vec<u8> {
    encoded_payload(&Payload::Nav(*nav))
}

/// The frame body (sequence number 0): the comparison bit for bit, NaN
/// placeholders equal.
fn encoded_payload(payload: &Payload) -> Vec<u8> {
    let mut body = [0u8; MAX_BODY_LEN];
    let len = encode_body(0, payload, &mut body).unwrap_or(0);
    body[..len].to_vec()
}

/// CSV columns of [`write_csv`]: SI inside, degrees at this edge. Azimuth
/// and toolface in [0, 360); the azimuth is empty unless determined
/// (`azimuth_status`: determined, undetermined, lost, n/a: `display::AzimuthStatus`); NaN is a placeholder
/// (no estimate yet). `matches_probe`: yes, no, unchecked (the replay was
/// out of step), empty (no probe solution).
pub const CSV_HEADER: &str = "sample,time_s,mode,flags,roll_deg,pitch_deg,\
inclination_deg,azimuth_deg,azimuth_status,toolface_deg,\
vn_m_s,ve_m_s,vd_m_s,lat_deg,lon_deg,height_m,roll_std_deg,pitch_std_deg,azimuth_std_deg,\
matches_probe";

/// Writes the replayed solutions as CSV, one row per raw frame.
pub fn write_csv(rows: &[ReplayRow], mut out: impl Write) -> io::Result<()> {
    writeln!(out, "{CSV_HEADER}")?;
    write_csv_rows(rows, &mut out)?;
    out.flush()
}

/// Writes rows without the header (a live replay writes them as they
/// settle).
pub fn write_csv_rows(rows: &[ReplayRow], mut out: impl Write) -> io::Result<()> {
    for row in rows {
        let s = &row.solution;
        let deg = |a: f32| f64::from(a).to_degrees();
        let [roll, pitch, heading] = s.attitude.map(f64::from);
        let [roll_std, pitch_std, heading_std] = s.attitude_std.map(deg);
        let drilling = DrillingAngles::from_euler(&Euler::new(roll, pitch, heading));
        let (azimuth, status) = azimuth_cells(s);
        let [vn, ve, vd] = s.velocity_ned;
        let matches = match (row.in_step, row.matches_probe) {
            (false, _) => "unchecked",
            (true, Some(true)) => "yes",
            (true, Some(false)) => "no",
            (true, None) => "",
        };
        writeln!(
            out,
            "{},{:.6},{},{},{:.6},{:.6},{:.6},{azimuth},{status},{:.6},{vn},{ve},{vd},{:.9},{:.9},{},\
             {roll_std:.6},{pitch_std:.6},{heading_std:.6},{matches}",
            s.sample_counter,
            s.time_us as f64 * 1e-6,
            s.mode,
            s.flags,
            roll.to_degrees(),
            pitch.to_degrees(),
            drilling.inclination.to_degrees(),
            angle_0_360(roll),
            s.latitude.to_degrees(),
            s.longitude.to_degrees(),
            s.height,
        )?;
    }
    Ok(())
}

/// Toolface (or any angle) in [0, 360) deg, NaN kept as the placeholder.
fn angle_0_360(angle_rad: f64) -> f64 {
    if angle_rad.is_finite() {
        display::deg_0_360(angle_rad)
    } else {
        f64::NAN
    }
}

/// The azimuth cell (empty unless determined, deg) and its status
/// ([`display::AzimuthStatus`]).
pub fn azimuth_cells(s: &NavSolution) -> (String, &'static str) {
    match display::AzimuthStatus::of_nav(s) {
        display::AzimuthStatus::Determined => (
            format!("{:.6}", display::deg_0_360(f64::from(s.attitude[2]))),
            "determined",
        ),
        status => (String::new(), status.word()),
    }
}

#[cfg(test)]
mod tests;
