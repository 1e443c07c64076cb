//! Where and why a replay went out of step with the probe: from that
//! sample on (to the next boot, or for the station surveys only) its
//! solutions are still given but not compared, and the report says why.

use crate::formats::display;

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
                let name = |mode| display::mode_name(mode).trim_end();
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
