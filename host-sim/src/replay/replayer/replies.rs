//! The replayer's side of the uplink commands: it takes the probe's
//! replies, schedules each acknowledged command that changes the
//! navigator after the sample of the last navigation frame before its
//! reply, and carries it out on its own navigator when it steps past that
//! sample (the rule, and what each command does, in `replay::commands`).

use mwd_core::probe::Navigator;
use mwd_core::protocol::uplink::{Command, CommandKind, Reply, ReplyStatus};

use super::{linked, Replayer};
use crate::replay::commands::{effect, is_setting, CommandOutcome, CommandRow, Effect};
use crate::replay::step_loss::StepLossReason;

impl Replayer {
    /// Tells the replay a command the host sent (its uplink log), for what
    /// the reply does not carry: toolface indexing's parameters. Commands
    /// of other kinds need nothing more.
    pub fn knows_sent_command(&mut self, seq: u16, command: &Command) {
        if let Command::IndexToolface(p) = command {
            self.sent_indexing.insert(seq, *p);
        }
    }

    /// Takes a reply to an uplink command: an acknowledged command that
    /// changes the navigator is carried out after the sample of the last
    /// navigation frame before it (`replay::commands`'s notes).
    pub fn push_reply(&mut self, seq: u16, reply: &Reply) {
        self.note_seq(seq);
        self.step.seen_any = true;
        let run = self.run;
        let late = run
            .stepped_through
            .is_some_and(|stepped| run.last_probe_nav.is_none_or(|after| after < stepped));
        let place_known =
            !run.lost_since_nav && (run.last_probe_nav.is_some() || !run.raw_seen) && !late;
        let mut row = CommandRow {
            run: self.summary.restarts,
            command_seq: reply.command_seq,
            command_kind: reply.command_kind,
            status: reply.status,
            after_sample: run.last_probe_nav,
            place_known,
            outcome: CommandOutcome::NoEffect,
        };
        let from_sample = run.last_probe_nav.map_or(0, |n| n.wrapping_add(1));
        if reply.status != ReplyStatus::Ack {
            row.outcome = CommandOutcome::Refused;
        } else if is_setting(reply.command_kind) {
            self.run.settings_changed = true;
        } else if CommandKind::from_byte(reply.command_kind).is_none() {
            row.outcome = CommandOutcome::UnknownKind;
            let command_seq = reply.command_seq;
            self.lose_from(from_sample, StepLossReason::UnknownCommand { command_seq });
        } else if let Some(effect) = effect(
            reply.command_kind,
            reply.config_version,
            self.sent_indexing.get(&reply.command_seq).copied(),
        ) {
            row.outcome = CommandOutcome::Pending;
            if !place_known {
                let command_seq = reply.command_seq;
                self.lose_from(
                    from_sample,
                    StepLossReason::CommandPlaceUnknown { command_seq },
                );
            }
            self.scheduled.push_back((self.command_rows.len(), effect));
        }
        self.command_rows.push(row);
    }

    /// The replies seen so far and what the replay did with each.
    pub fn commands(&self) -> &[CommandRow] {
        &self.command_rows
    }

    /// Carries out the scheduled commands due before sample `counter`.
    pub(super) fn apply_due_commands(&mut self, counter: u32) {
        while let Some(&(index, effect)) = self.scheduled.front() {
            let after = self.command_rows.get(index).and_then(|r| r.after_sample);
            if after.is_some_and(|a| a >= counter) {
                return;
            }
            self.scheduled.pop_front();
            let outcome = self.apply(index, effect, counter);
            if let Some(row) = self.command_rows.get_mut(index) {
                row.outcome = outcome;
            }
        }
    }

    fn apply(&mut self, index: usize, effect: Effect, counter: u32) -> CommandOutcome {
        let command_seq = self.command_rows.get(index).map_or(0, |r| r.command_seq);
        let done = match effect {
            Effect::StartSurveying => self.navigator.start_surveying(),
            Effect::TakeStation => self.navigator.take_station_now().map(|station| {
                self.replayed_station(station, counter);
            }),
            Effect::IndexToolface(Some(procedure)) => self.navigator.index_toolface(procedure),
            Effect::IndexToolface(None) => {
                self.lose_from(counter, StepLossReason::IndexingUnknown { command_seq });
                return CommandOutcome::Incomplete;
            }
            Effect::Realign { config_version } => {
                self.navigator = linked(Navigator::with_settings(
                    self.position,
                    self.calibration,
                    &self.still,
                ));
                self.tie_in_pending = self.tie_in;
                // The new navigator numbers its stations from 1 again.
                self.forget_station_partners();
                self.run.stations_in_step = true;
                let changed = self.run.settings_changed
                    || self.run.boot_version.is_some_and(|v| v != config_version);
                if changed {
                    self.lose_from(counter, StepLossReason::ConfigurationChanged);
                    return CommandOutcome::Incomplete;
                }
                Ok(())
            }
        };
        match done {
            Ok(()) => CommandOutcome::Replayed,
            Err(refusal) => {
                self.lose_from(
                    counter,
                    StepLossReason::ReplayRefusedCommand { command_seq },
                );
                CommandOutcome::ReplayRefused(refusal)
            }
        }
    }
}
