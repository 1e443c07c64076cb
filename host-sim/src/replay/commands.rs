//! The uplink commands in a replay: which acknowledged commands change the
//! navigator, and at which sample the probe carried them out.
//!
//! The rule the firmware follows (`firmware::app::SharedProbe::main_loop_pass`,
//! then `UplinkService::serve`, in the main loop of both boards): each pass
//! first navigates every waiting sample, queueing each one's navigation
//! frame, and only then serves the uplink, queueing each reply. The
//! downlink is one FIFO with one sequence counter, so a command took
//! effect after the sample of the last navigation frame sent before its
//! reply, and before the next one's. The reply itself needs no sample
//! counter; what the replay needs is that no frame was lost between that
//! navigation frame and the reply (otherwise the lost frame may have been
//! a later sample's navigation frame, and the place is not known).
//!
//! Settings (site, tie-in, calibration, still settings) are only stored:
//! the navigator is built from them at the next re-align or boot
//! (`navigator_for` in the firmware's mains), so they change nothing until
//! then; their values are not in the downlink, only the configuration
//! version each reply carries.
//!
//! This file holds the commands as the replay reads them: what each
//! acknowledged command does ([`effect`]), a reply and what the replay made
//! of it ([`CommandRow`]), and the host's uplink log. The replayer takes
//! the replies and carries the commands out in `replayer/replies.rs`.

use std::fmt;

use mwd_core::probe::navigator::commands::Refusal;
use mwd_core::protocol::uplink::{
    decode_command, Command, CommandKind, IndexingProcedure, ReplyStatus,
};

/// What an acknowledged command does to the navigator, as the replay
/// repeats it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Effect {
    StartSurveying,
    TakeStation,
    /// The procedure's parameters are not in the reply: `None` when the
    /// replay was not told them.
    IndexToolface(Option<IndexingProcedure>),
    /// A new navigator from the configuration of this version.
    Realign {
        config_version: u32,
    },
}

/// What the replay made of one reply.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CommandOutcome {
    /// Refused by the probe (a NAK): nothing changed.
    Refused,
    /// Acknowledged, but nothing for the navigation now (a setting, which
    /// waits for a re-align or boot; report configuration; reboot, whose
    /// boot event restarts the replay).
    NoEffect,
    /// Acknowledged, waiting for the replay to reach its sample.
    Pending,
    /// Carried out on the replay's navigator at the probe's sample.
    Replayed,
    /// The replay's navigator refused what the probe's acknowledged: the
    /// two differ.
    ReplayRefused(Refusal),
    /// Carried out without what it needs (indexing: its parameters; a
    /// re-align: the configuration's new settings), so what follows it is
    /// not compared.
    Incomplete,
    /// A command kind this replay does not know (a newer probe's).
    UnknownKind,
}

/// One reply of the capture and what the replay did with it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CommandRow {
    /// The run (0 before the first restart).
    pub run: u64,
    pub command_seq: u16,
    pub command_kind: u8,
    pub status: ReplyStatus,
    /// The last sample the probe navigated before the command (`None`:
    /// none of this run).
    pub after_sample: Option<u32>,
    /// Whether that sample is certain (no frame lost since its navigation
    /// frame, and the replay had not gone past it).
    pub place_known: bool,
    pub outcome: CommandOutcome,
}

/// A command's name for the report.
pub fn kind_name(kind: u8) -> String {
    match CommandKind::from_byte(kind) {
        Some(CommandKind::SetSite) => "set site".into(),
        Some(CommandKind::SetTieIn) => "set tie-in".into(),
        Some(CommandKind::ClearTieIn) => "clear tie-in".into(),
        Some(CommandKind::SetCalibration) => "set calibration".into(),
        Some(CommandKind::SetStillSettings) => "set still settings".into(),
        Some(CommandKind::Realign) => "re-align".into(),
        Some(CommandKind::StartSurveying) => "start surveying".into(),
        Some(CommandKind::TakeStation) => "take a station".into(),
        Some(CommandKind::IndexToolface) => "toolface indexing".into(),
        Some(CommandKind::ReportConfig) => "report configuration".into(),
        Some(CommandKind::Reboot) => "reboot".into(),
        None => format!("unknown kind 0x{kind:02x}"),
    }
}

/// Whether an acknowledged command of this kind only changes the stored
/// configuration (and so its version).
pub fn is_setting(kind: u8) -> bool {
    matches!(
        CommandKind::from_byte(kind),
        Some(
            CommandKind::SetSite
                | CommandKind::SetTieIn
                | CommandKind::ClearTieIn
                | CommandKind::SetCalibration
                | CommandKind::SetStillSettings
        )
    )
}

/// The navigator change of an acknowledged command of `kind`; `None` for
/// one that changes nothing now. `indexing`: the procedure, when known.
pub fn effect(
    kind: u8,
    config_version: u32,
    indexing: Option<IndexingProcedure>,
) -> Option<Effect> {
    match CommandKind::from_byte(kind)? {
        CommandKind::StartSurveying => Some(Effect::StartSurveying),
        CommandKind::TakeStation => Some(Effect::TakeStation),
        CommandKind::IndexToolface => Some(Effect::IndexToolface(indexing)),
        CommandKind::Realign => Some(Effect::Realign { config_version }),
        _ => None,
    }
}

impl fmt::Display for CommandRow {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let status = match self.status {
            ReplyStatus::Ack => "ACK".to_string(),
            ReplyStatus::Nak(reason) => format!("NAK {}", reason.to_byte()),
        };
        let place = match (self.after_sample, self.place_known) {
            (Some(n), true) => format!("after sample {n}"),
            (None, true) => "before the run's first sample".to_string(),
            (Some(n), false) => format!("after sample {n} or later (frames lost)"),
            (None, false) => "at an unknown sample (frames lost)".to_string(),
        };
        let what = match self.outcome {
            CommandOutcome::Refused => "nothing changed".to_string(),
            CommandOutcome::NoEffect => "nothing for the navigation now".to_string(),
            CommandOutcome::Pending => format!("not reached ({place})"),
            CommandOutcome::Replayed => format!("replayed {place}"),
            CommandOutcome::ReplayRefused(r) => {
                format!("REFUSED by the replay ({r:?}) {place}: the replay differs")
            }
            CommandOutcome::Incomplete => {
                format!("replayed {place} without its settings or parameters: not compared after")
            }
            CommandOutcome::UnknownKind => "unknown to this replay: not compared after".to_string(),
        };
        write!(
            f,
            "run {}: command {} {} {status}: {what}",
            self.run,
            self.command_seq,
            kind_name(self.command_kind)
        )
    }
}

/// The commands of an uplink log (the bytes the host sent the probe, as
/// `docs/protocol.md` "Uplink" frames them), by sequence number: what the
/// replies do not carry. Chunks that are not a good command are skipped
/// (the probe refused them too, or never saw them).
pub fn decode_uplink_log(bytes: &[u8]) -> Vec<(u16, Command)> {
    bytes
        .split(|b| *b == 0)
        .filter(|chunk| !chunk.is_empty())
        .filter_map(|chunk| {
            let mut body = chunk.to_vec();
            let n = cobs::decode_in_place(&mut body).ok()?;
            let received = decode_command(body.get(..n)?).ok()?;
            Some((received.seq, received.command))
        })
        .collect()
}
