//! The tool's files and texts: reading and writing every file format the
//! host tool shares with the probe or with people, and how values are
//! shown to people.
//!
//! Stage 1 of the data's way (see `lib.rs`): it uses only `mwd_core`, so
//! every later stage can read and write files through it.
//!
//! - [`capture`]: the probe's UART stream (`.bin`), written, decoded, read
//!   as a stream, summarised, and as CSV; [`capture_export`]: a capture
//!   file decoded to its summary and CSV.
//! - [`samples_csv`]: the probe-sample CSV (a sample and its truth a row).
//! - [`depth_log`]: the surface's depth log (time to measured depth).
//! - [`station_csv`]: the survey station file (MD, inclination, azimuth).
//! - [`text_records`], [`ranges`]: text tables read record by record with
//!   bounded lines, and the physical range of each number in them.
//! - [`display`]: angles and their uncertainty as people read them.
//! - [`figure`]: a drawing written as SVG and PNG (the embedded font).
//! - [`uplink_session`]: commands sent to a live probe over its serial
//!   port and its replies awaited.
//! - [`files`]: output files written and the depth log read with the path
//!   in every error.

pub mod capture;
pub mod capture_export;
pub mod depth_log;
pub mod display;
pub mod figure;
pub mod files;
pub mod fixed;
pub mod ranges;
pub mod samples_csv;
pub mod station_csv;
pub mod text_records;
pub mod uplink_session;
