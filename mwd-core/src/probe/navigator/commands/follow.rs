//! How the navigator follows the surface's survey commands (the notes of
//! `commands`): each cycle after the station tracking, and on each
//! command.

use super::{Indexing, Refusal, INDEX_MIN_TURN_RAD, MIN_FINE_ALIGNMENT_SAMPLES};
use crate::conventions::wrap_pi;
use crate::kalman::FilterScalar;
use crate::probe::navigator::state::{Navigator, Phase};
use crate::protocol::frame::station_flags;
use crate::protocol::uplink::IndexingProcedure;
use crate::protocol::StationSurvey;

impl<T: FilterScalar> Navigator<T> {
    /// [`Navigator::start_surveying`].
    pub(in crate::probe::navigator) fn start_surveying_now(&mut self) -> Result<(), Refusal> {
        match self.phase {
            Phase::Coarse(_) => Err(Refusal::NotReady),
            Phase::Fine { samples } if samples < MIN_FINE_ALIGNMENT_SAMPLES => {
                Err(Refusal::NotReady)
            }
            Phase::Fine { .. } => {
                self.enter_navigation();
                Ok(())
            }
            Phase::Navigating => Ok(()),
        }
    }

    /// Uplink "take a station now": the current still period's station,
    /// flagged `REQUESTED`, for the caller to send now (see the module's
    /// notes); the same frame again when this still period already sent
    /// one.
    pub fn take_station_now(&mut self) -> Result<StationSurvey, Refusal> {
        if !self.is_navigating() {
            return Err(Refusal::NotReady);
        }
        let mut survey = match (self.commands.sent, &self.station) {
            (Some(sent), _) => sent,
            (None, Some(station)) => station.to_send(),
            (None, None) => return Err(Refusal::NotStill),
        };
        survey.flags |= station_flags::REQUESTED;
        self.commands.sent = Some(survey);
        Ok(survey)
    }

    /// Uplink "toolface indexing": starts the procedure (see the module's
    /// notes); the same procedure already running goes on unchanged (a
    /// resend), another replaces it.
    pub fn index_toolface(&mut self, procedure: IndexingProcedure) -> Result<(), Refusal> {
        if !self.is_navigating() {
            return Err(Refusal::NotReady);
        }
        if self.commands.indexing.map(|i| i.procedure) != Some(procedure) {
            self.commands.indexing = Some(Indexing {
                procedure,
                reported: 0,
                last_toolface: None,
                // A still period already sent cannot be a dwell.
                judged: self.commands.sent.is_some(),
            });
        }
        Ok(())
    }

    /// The toolface-indexing procedure in progress, if any.
    pub fn indexing(&self) -> Option<&Indexing> {
        self.commands.indexing.as_ref()
    }

    /// After each navigation cycle's station tracking: keeps the one-frame
    /// rule and reports indexing dwells.
    pub(in crate::probe::navigator) fn follow_commands(&mut self, still: bool) {
        const ENDED_WHILE_STILL: u16 = station_flags::MAX_DURATION | station_flags::MOTION_SEEN;
        // A frame the station tracking finished (never one of ours, which
        // carry these bits).
        let ours = station_flags::REQUESTED | station_flags::INDEXING_DWELL;
        if let Some(finished) = self.finished_station.filter(|f| f.flags & ours == 0) {
            match self.commands.sent {
                // Already sent by request or as a dwell.
                Some(sent) if sent.station == finished.station => self.finished_station = None,
                // Sent at the longest station, or when the gyros saw the
                // tool turn: a request repeats it (a still period's end
                // still waiting to be taken is not this one's).
                _ if still && finished.flags & ENDED_WHILE_STILL != 0 => {
                    self.commands.sent = Some(finished)
                }
                _ => {}
            }
        }
        if !still {
            self.commands.sent = None;
            if let Some(indexing) = self.commands.indexing.as_mut() {
                indexing.judged = false;
            }
            return;
        }
        let (Some(indexing), Some(station)) = (self.commands.indexing.as_mut(), &self.station)
        else {
            return;
        };
        if indexing.judged || station.epochs < indexing.dwell_epochs() {
            return;
        }
        if self.commands.sent.is_some() {
            // Sent on request before the dwell time: not a dwell.
            indexing.judged = true;
            return;
        }
        indexing.judged = true;
        let mut survey = station.to_send();
        let toolface = survey.angles[2];
        let turned = indexing.last_toolface.is_none_or(|last| {
            wrap_pi(f64::from(toolface) - f64::from(last)).abs() >= INDEX_MIN_TURN_RAD
        });
        if !turned {
            return;
        }
        survey.flags |= station_flags::INDEXING_DWELL;
        indexing.reported += 1;
        indexing.last_toolface = Some(toolface);
        if indexing.reported >= indexing.procedure.positions {
            self.commands.indexing = None;
        }
        self.commands.sent = Some(survey);
        self.finished_station = Some(survey);
    }
}
