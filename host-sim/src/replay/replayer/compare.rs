//! The replay compared with the probe: each replayed solution with the
//! probe's solution of the same sample, each replayed station with the
//! probe's station of the same number, bit for bit as encoded frames
//! (`rows::encoded_payload`). Either side may come first: the other waits
//! for its partner. A navigation mode differing from the probe's, or a
//! station sent on a command by one side only, stops the comparison (the
//! stage's notes in `replay/mod.rs`).

use mwd_core::protocol::frame::station_flags;
use mwd_core::protocol::{NavSolution, Payload, StationSurvey};

use super::state::Partners;
use super::Replayer;
use crate::replay::rows::{encoded, encoded_payload, ReplayRow, StationRow, StationSummary};
use crate::replay::step_loss::StepLossReason;

impl Replayer {
    /// Compares row number `index` with the probe's solution.
    pub(super) fn compare(&mut self, index: usize, on_board: &NavSolution) {
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
    pub(super) fn note_newest(&mut self, index: usize, row: ReplayRow) {
        if self.rows_replayed() == index + 1 {
            self.last_row = Some(row);
        }
    }

    pub(super) fn compare_row(&mut self, row: &mut ReplayRow, on_board: &NavSolution) {
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

    pub(super) fn replayed_station(&mut self, station: StationSurvey, counter: u32) {
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

    pub(super) fn compare_station(&mut self, index: usize, on_board: &StationSurvey) {
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
    pub(super) fn forget_station_partners(&mut self) {
        self.station_summary.unchecked += self.early_station.len();
        self.awaiting_station = Partners::default();
        self.early_station = Partners::default();
    }
}
