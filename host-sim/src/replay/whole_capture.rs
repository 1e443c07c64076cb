//! A whole capture replayed at once: its frames (or its decoded items,
//! replies to uplink commands included) through a [`Replayer`], the rows
//! and summary at the end; and the station links of a capture replayed bit
//! for bit, for the survey.

use mwd_core::calibration::ProbeCalibration;
use mwd_core::earth::Position;
use mwd_core::probe::StationLink;
use mwd_core::protocol::{Frame, Payload, StationSurvey};

use crate::formats::capture::Capture;
use crate::replay::replayer::Replayer;
use crate::replay::rows::{encoded_payload, ReplayRow, ReplaySummary};

/// How many items a replay of a file takes between writing out (and
/// forgetting) its settled rows ([`Replayer::write_settled`]): no one
/// waits for a file's rows, so they go in batches.
pub const FILE_BATCH_ITEMS: usize = 4096;

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
