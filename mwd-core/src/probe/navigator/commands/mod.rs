//! The surface's survey commands (uplink 0x46-0x48, docs/protocol.md,
//! "Uplink"): start surveying, take a station now, the toolface-indexing
//! procedure. A child module of `navigator`: what the commands are and
//! keep here, how the navigator follows them in `follow.rs`.
//!
//! * **Start surveying** ends the static fine alignment now and enters
//!   navigation (the phase in which still periods become stations). The
//!   fine alignment applies a zero-velocity update every cycle without
//!   asking the still detector: once the rig starts moving the string
//!   those updates are false, so the surface must be able to end it before
//!   the 60 s the probe would otherwise wait. Refused (not ready) during
//!   the coarse alignment and for the first [`MIN_FINE_ALIGNMENT_SAMPLES`]
//!   of the fine one; acknowledged, with nothing to do, once navigating
//!   (a resend after a lost reply must not read as a refusal).
//! * **Take a station now** sends the current still period's station at
//!   once, flagged `REQUESTED`, with the survey its natural end would
//!   have sent (the older of its last two settled checkpoints,
//!   `SURVEY_SETTLE_EPOCHS`). The filter is not touched: the still period
//!   goes on with its zero-velocity and bias updates, but sends nothing
//!   more. Refused when not navigating (not ready) or not still.
//! * **Toolface indexing**: for the next `positions` still periods that
//!   last the procedure's dwell time at a toolface [`INDEX_MIN_TURN_RAD`]
//!   or more from the previous dwell's, the station is sent as soon as the
//!   dwell time is reached, flagged `INDEXING_DWELL` (its toolface and
//!   sigma are the dwell's); the procedure ends after the last. The first
//!   dwell is the toolface the tool is at.
//!
//! One rule keeps the stations unambiguous: a still period sends at most
//! one station frame, whatever made it (its end, the longest station, a
//! request, a dwell), and a repeated "take a station" in the same still
//! period sends that frame again (the host's resend after a lost reply).

use crate::conventions::DEG;
use crate::probe::still::DETECTION_DELAY_SAMPLES;
use crate::protocol::uplink::IndexingProcedure;
use crate::protocol::StationSurvey;
use crate::timing::SAMPLE_INTERVAL_S;

mod follow;

/// The fewest fine-alignment samples after which "start surveying" ends
/// the fine alignment: the still detector's delay (1.95 s) of
/// zero-velocity updates, so the filter has been aided before it runs
/// free and the detector (which runs through the fine alignment) knows
/// from the first navigating cycle whether the probe is still (a probe
/// judged moving lets its roll follow the accelerometer roll, with its
/// noise in the roll's variance). The tilt
/// needs no more: the coarse levelling already sits on the
/// accelerometer-bias floor (derivation section 3b; measured on the
/// navigator's still samples, roll sigma 0.0610 deg at the first fine
/// cycle, 0.0650 deg at 1 s, 0.0674 deg at 60 s; the test below). What the
/// rest would add is the gyrocompassed heading's refinement, which the
/// frames' azimuth sigma reports (undetermined beyond 10 deg): ending
/// early costs azimuth accuracy, honestly shown, not honesty.
pub const MIN_FINE_ALIGNMENT_SAMPLES: u32 = DETECTION_DELAY_SAMPLES;

/// The smallest toolface change (rad) that makes a still period a new
/// indexing dwell: 5 deg, half the finest spacing the command allows (36
/// positions, 10 deg apart) and some 50 times a station's toolface sigma
/// (~0.1 deg), so a pause at the same position is never counted twice and
/// every position the surface turns to is.
pub const INDEX_MIN_TURN_RAD: f64 = 5.0 * DEG;

/// Why the navigator refused a command (the NAK reasons of
/// `protocol::uplink::NakReason` of the same names).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Refusal {
    /// Still aligning (or not long enough to end the alignment).
    NotReady,
    /// Not still: moving, or still for less than the detector's delay.
    NotStill,
}

/// A toolface-indexing procedure in progress.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Indexing {
    pub procedure: IndexingProcedure,
    /// Dwells reported so far.
    pub reported: u8,
    /// The last reported dwell's toolface (rad).
    last_toolface: Option<f32>,
    /// The current still period was judged (reported or not a new
    /// position).
    judged: bool,
}

impl Indexing {
    /// Zero-velocity updates (still cycles) by which a still period has
    /// lasted the dwell time: the first comes after the detector's delay.
    fn dwell_epochs(&self) -> u32 {
        let samples = (f64::from(self.procedure.dwell_s) / SAMPLE_INTERVAL_S) as u32;
        samples.saturating_sub(DETECTION_DELAY_SAMPLES - 1).max(1)
    }
}

/// What the commands keep between cycles.
#[derive(Default)]
pub(super) struct CommandState {
    /// The station frame the current still period already sent.
    sent: Option<StationSurvey>,
    indexing: Option<Indexing>,
}

#[cfg(test)]
mod tests;
