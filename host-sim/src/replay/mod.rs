//! Replay of a probe capture on the host: the raw-sample frames go through
//! the probe's own navigation code (`mwd_core::probe::Navigator`, the same
//! source the firmware runs), and where the capture also holds the probe's
//! navigation frames, each replayed solution is compared with the probe's
//! bit for bit (as encoded frames, so NaN placeholders compare equal).
//!
//! The comparison only means something while the replay's navigator has
//! seen exactly the samples the probe's did. A boot event starts a new run
//! (a new navigator, as the probe rebooted); a raw frame lost in a sequence
//! gap (the sample counter skips where frames were lost), a capture that
//! starts after the probe's first sample, or samples the probe's own
//! navigation dropped (a samples-dropped event) put the replay out of step:
//! from there to the next boot its solutions are still given, but not
//! compared, and the summary says from which sample.
//!
//! Station surveys (kind 4) are replayed the same way: the replay's
//! navigator finishes its stations at the same samples, and each is
//! compared bit for bit with the probe's station of the same number
//! ([`Replayer::stations`]). The replay's navigator keeps the station
//! links (`Navigator::track_station_links`, which do not feed back: the
//! solutions and stations are the same with them), so a station replayed
//! bit for bit also gives the link the probe's filter held but does not
//! send (the survey's chain, `survey_error::link_chain`).
//!
//! The probe's replies to uplink commands (kind 5) tell the replay which
//! commands changed the navigation and where ([`commands`]): an
//! acknowledged start surveying, take a station, toolface indexing or
//! re-align is carried out on the replay's navigator between the same two
//! samples as on the probe. To know that place, a raw frame is replayed
//! only once the probe's navigation frame of its sample (or a later one)
//! has come, or [`SETTLE_AFTER_SAMPLES`] later raw frames did (a capture
//! without navigation frames). What the replay cannot repeat (a command
//! whose place was lost with frames, a re-align with settings the downlink
//! does not carry) stops the comparison there; a reply lost altogether
//! shows as the probe's navigation mode differing from the replay's, which
//! stops it too and says so.
//!
//! Stage 4 of the data's way (see `lib.rs`): may use `formats`,
//! `analysis` and `sim`; it uses `formats` (the capture, how values are
//! shown).
//!
//! The files, by what they do:
//! - `rows.rs`: what a replay gives, its rows and summaries, and what
//!   "identical" means (the encoded frame, bit for bit);
//! - `step_loss.rs`: where and why the replay went out of step;
//! - [`commands`]: the uplink commands as the replay reads them;
//! - `replayer/`: the [`Replayer`], stepping through the frames, comparing
//!   with the probe's own, carrying out the commands and settling its rows;
//! - `rows_csv.rs`: the rows as CSV;
//! - `whole_capture.rs`: a whole capture replayed at once ([`replay`],
//!   [`replay_capture`]) and the station links it gives the survey;
//! - [`live`]: the probe's stream replayed as it arrives.

pub mod commands;
pub mod file_replay;
pub mod live;
mod replayer;
pub mod report;
mod rows;
mod rows_csv;
mod step_loss;
mod whole_capture;

pub use replayer::{Replayer, SETTLE_AFTER_SAMPLES};
pub use rows::{ReplayRow, ReplaySummary, StationRow, StationSummary};
pub use rows_csv::{azimuth_cells, write_csv, write_csv_rows, CSV_HEADER};
pub use step_loss::{StepLoss, StepLossReason};
pub use whole_capture::{
    replay, replay_capture, replay_with, replayed_station_links, FILE_BATCH_ITEMS,
};

#[cfg(test)]
mod tests;
