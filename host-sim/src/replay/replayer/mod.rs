//! The [`Replayer`]: a capture replayed one frame at a time (a file's or a
//! live stream's), through a navigator built as the probe builds its own.
//! This file holds what it keeps and how it steps through the frames: a
//! boot starts a new run, a raw frame waits for its place among the
//! commands' replies and is then stepped, and a loss (frames lost, a
//! capture starting mid-run, samples the probe dropped) puts the replay
//! out of step (the stage's notes in `replay/mod.rs`).
//!
//! The rest of the replayer, by what it does: the comparison with the
//! probe's own solutions and stations (`compare.rs`), the replies to
//! uplink commands and the commands they carry out (`replies.rs`), the
//! rows settled, written out and forgotten (`settle.rs`), and what it keeps
//! track of between frames (`state.rs`).

mod compare;
mod replies;
mod settle;
mod state;

use std::collections::{HashMap, VecDeque};

use mwd_core::calibration::ProbeCalibration;
use mwd_core::config::default_still_settings;
use mwd_core::earth::Position;
use mwd_core::probe::{Navigator, TieIn};
use mwd_core::protocol::decoder::starts_a_run;
use mwd_core::protocol::frame::nav_flags;
use mwd_core::protocol::uplink::{IndexingProcedure, StillSettings};
use mwd_core::protocol::{EventKind, Frame, NavSolution, Payload, RawSample, StationSurvey};

use crate::formats::capture::Received;
use crate::replay::commands::{CommandRow, Effect};
use crate::replay::rows::{ReplayRow, ReplaySummary, StationRow, StationSummary};
use crate::replay::step_loss::{StepLoss, StepLossReason};
use state::{Awaiting, Partners, RunState, StepTracker};

/// Rows of a live replay still waiting for the probe's solution after this
/// many later samples are written without it: more than the probe's
/// navigation inbox can hold back (32 samples). Also how many raw frames
/// wait for their navigation frame before they are replayed without it.
pub const SETTLE_AFTER_SAMPLES: usize = 64;

/// The replay one frame at a time, for a live stream: a raw frame is
/// replayed as soon as the probe's navigation frame of its sample (or a
/// later one) has come, which places it among the commands' replies (see
/// the `replay` module's notes). The probe sends a sample's navigation
/// frame after its raw frame, but the comparison does not rely on that
/// order: a solution waits for its partner on either side.
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

/// `navigator` keeping its station links ([`StationRow::link`]).
fn linked(mut navigator: Navigator) -> Navigator {
    navigator.track_station_links(true);
    navigator
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
    /// `firmware/src/app/main_loop.rs`), after each boot and
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

    /// The replay so far.
    pub fn summary(&self) -> &ReplaySummary {
        &self.summary
    }

    /// Where the replay went out of step with the probe, in order.
    pub fn step_losses(&self) -> &[StepLoss] {
        &self.step_losses
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
