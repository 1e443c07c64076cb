//! Library side of the host tool: simulation, file formats, analysis. The
//! CLI in `main.rs` is a thin layer over it, and the system tests use it.

pub mod analysis;
pub mod capture;
pub mod coarse;
#[cfg(feature = "dashboard")]
pub mod dashboard;
pub mod display;
pub mod job;
pub mod live;
pub mod observability;
pub mod paper_mgwd;
pub mod replay;
pub mod rins;
pub mod samples_csv;
pub mod sim;
pub mod study;
pub mod survey_error;
pub mod survey_listing;
