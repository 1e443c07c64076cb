//! What a replay gives: one row per replayed solution and per replayed
//! station survey, each with how it compares with the probe's own, and the
//! summaries of both; and what "the same as the probe's" means here: the
//! same frame body, bit for bit (NaN placeholders compare equal).

use mwd_core::probe::StationLink;
use mwd_core::protocol::frame::MAX_BODY_LEN;
use mwd_core::protocol::{encode_body, NavSolution, Payload, StationSurvey};

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

/// A navigation solution's frame body ([`encoded_payload`]).
pub(super) fn encoded(nav: &NavSolution) -> Vec<u8> {
    encoded_payload(&Payload::Nav(*nav))
}

/// The frame body (sequence number 0): the comparison bit for bit, NaN
/// placeholders equal.
pub(super) fn encoded_payload(payload: &Payload) -> Vec<u8> {
    let mut body = [0u8; MAX_BODY_LEN];
    let len = encode_body(0, payload, &mut body).unwrap_or(0);
    body[..len].to_vec()
}
