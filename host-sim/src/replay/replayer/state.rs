//! What the replayer keeps track of between frames, besides its rows:
//! the samples waiting for the probe's solution, the current run as the
//! commands see it, the stations waiting for their partner, and whether
//! the replay is still in step with the probe's navigation (the stage's
//! notes in `replay/mod.rs`).

use std::collections::{HashMap, VecDeque};

use crate::replay::rows::ReplayRow;

/// A replayed sample waiting for the probe's solution.
#[derive(Debug, Clone, Copy)]
pub(super) enum Awaiting {
    /// Its row, by row number.
    Row(usize),
    /// Its row (row number `number`) was forgotten before the probe's
    /// solution came (a capture whose navigation frames come late or not
    /// at all): the comparison still counts.
    Forgotten { number: usize, row: ReplayRow },
}

/// What the commands need to know of the current run.
#[derive(Debug, Clone, Copy)]
pub(super) struct RunState {
    /// The sample of the probe's last navigation frame.
    pub(super) last_probe_nav: Option<u32>,
    /// A frame was lost since that navigation frame (or since the boot).
    pub(super) lost_since_nav: bool,
    /// A frame was lost in this run.
    pub(super) lost_in_run: bool,
    pub(super) raw_seen: bool,
    /// The last sample the replay's navigator stepped.
    pub(super) stepped_through: Option<u32>,
    /// Settings were acknowledged in this run (a re-align then uses values
    /// the replay does not have).
    pub(super) settings_changed: bool,
    /// The configuration version of this run's boot event.
    pub(super) boot_version: Option<u32>,
    /// Samples from this one on are not compared (a command's loss).
    pub(super) unchecked_from: Option<u32>,
    /// Station surveys are compared (not while indexing without its
    /// parameters).
    pub(super) stations_in_step: bool,
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
pub(super) struct Partners<T>(HashMap<u16, VecDeque<T>>);

impl<T> Default for Partners<T> {
    fn default() -> Self {
        Self(HashMap::new())
    }
}

impl<T> Partners<T> {
    pub(super) fn add(&mut self, station: u16, item: T) {
        self.0.entry(station).or_default().push_back(item);
    }

    pub(super) fn take(&mut self, station: u16) -> Option<T> {
        self.0.get_mut(&station)?.pop_front()
    }

    pub(super) fn len(&self) -> u64 {
        self.0.values().map(|q| q.len() as u64).sum()
    }
}

/// Whether the replay has seen what the probe's navigation saw.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct StepTracker {
    pub(super) seen_any: bool,
    pub(super) expected_seq: Option<u16>,
    /// A sequence gap since the last raw frame.
    pub(super) gap_since_raw: bool,
    /// The probe reported dropping samples since the last raw frame.
    pub(super) dropped_since_raw: bool,
    pub(super) last_counter: Option<u32>,
    /// This run began with its boot event in the capture.
    pub(super) from_boot: bool,
    pub(super) in_step: bool,
}
