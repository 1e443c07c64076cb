//! Surveys: stations to positions with their uncertainty, the survey of a
//! drilling capture, and the job file that describes a run.
//!
//! Stage 6 of the data's way (see `lib.rs`): uses `formats` (the station
//! and depth files), `sim` (the simulator's plans where a survey is checked
//! against its truth) and `replay` (a capture's stations).
//!
//! - [`iscwsa`]: the ISCWSA wellbore position-uncertainty model (SPE 67616,
//!   SPE 90408) and the probe's own tool model.
//! - [`listing`]: a station file positioned by minimum curvature with its
//!   NEV covariance and ellipses, a drilling capture's stations paired with
//!   depth, the listing, its figures, anti-collision.
//! - [`job`]: the job file (site, tie-in, calibration, tool model).
//! - [`well_survey`]: a station file's survey as `host-sim survey` makes
//!   it (positions, the model's covariance, an offset well's separation).
//! - [`outputs`]: that survey's listing, CSV, JSON, WITSML and figures.
//! - [`streamed`]: a station file of any length surveyed in constant
//!   memory, its listing and CSV written row by row.
//! - [`capture`]: the survey of a drilling capture with its depth log.
//! - [`simulated`]: a simulated drilling run surveyed end to end and
//!   checked against its truth (`host-sim drill`).
//! - [`stations`]: the probe's downlink to the survey's stations (each
//!   station's start sigma, stations sent again), positioned from the tie-on:
//!   the one collector the capture survey, the dashboard and the studies use.

pub mod capture;
pub mod iscwsa;
pub mod job;
pub mod listing;
pub mod outputs;
pub mod simulated;
pub mod station_qc;
pub mod stations;
pub mod streamed;
pub mod well_survey;
