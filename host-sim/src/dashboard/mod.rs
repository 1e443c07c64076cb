//! `host-sim dashboard`: the probe's live display as a local web page, in
//! the spirit of the MGWD paper's data-collection software (both sensor
//! boards' data and curves, the calibration, parameter setting and system
//! control). docs/dashboard.md.
//!
//! Stage 9 of the data's way (see `lib.rs`), the last: uses `formats` (the
//! frames), `replay` (the live decoding) and `survey` (the job, and the
//! stations collected and positioned as the survey does).
//!
//! - [`source`]: frames from a serial port (recorded raw as they arrive)
//!   or a capture replayed at a chosen pace; the probe's commands.
//! - [`state`]: what the page shows, in bounded buffers, and its updates.
//! - [`view`], [`stations`]: frames and stations as people read them;
//!   [`well_view`]: the stations drawn in plan and section against the
//!   job's well plan.
//! - [`server`]: the page (uPlot embedded) and server-sent events, over
//!   [`connection`]s with a deadline.
//! - [`access`]: who may read and command: the Host, the Origin, the
//!   run's token.
//! - [`launch`]: a dashboard started from its source, with the calibration
//!   in use as the page shows it.

pub mod access;
pub mod connection;
pub mod launch;
pub mod ring;
pub mod server;
pub mod source;
pub mod state;
pub mod stations;
pub mod view;
pub mod well_view;
