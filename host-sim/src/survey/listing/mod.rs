//! `host-sim survey`: a station file (CSV,
//! [`station_csv`](crate::formats::station_csv)) read, positioned by
//! minimum curvature (`mwd_core::survey`) and, with an error model, given
//! its NEV covariance and error ellipse at every station
//! ([`crate::survey::iscwsa`]). Outputs are in metres whatever the input
//! unit.
//!
//! Files: `positions` (the rows: stations positioned from the tie-on),
//! `error_models` (the known error models and their run over the rows);
//! the survey of a drilling capture in [`drilling`], its text in
//! [`drilling_text`], the ellipses, the figures and the separation.

pub mod drilling;
pub mod drilling_text;
pub mod ellipse;
mod error_models;
pub mod plot;
mod positions;
pub mod separation;
pub mod station_gaps;
pub mod trajectory;

pub use crate::formats::station_csv::{
    read_stations, InputStation, LengthUnit, StationFile, StationReading, FOOT_M,
};
pub use error_models::{
    apply_model, file_validity, model, model_from_file, terms, Invalid, KnownModel, ModelRun,
    Validity, MODELS,
};
pub use positions::{
    closure_azimuth, compute, plus_tie_on, row, tie_on_m, tie_on_note, true_station,
    AzimuthReference, Row, TieOnInput,
};
