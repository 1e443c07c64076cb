//! Alignment of a still probe on the host: the coarse solution of a
//! recorded or simulated static run, and what its measurements can
//! determine.
//!
//! Stage 5 of the data's way (see `lib.rs`): uses `formats` (the sample
//! CSV and the capture it reads) and `sim` (the simulated runs it checks).
//!
//! - [`coarse`]: calibration, static segments (toolface positions) and the
//!   core's coarse alignment with its bounds.
//! - [`observability`]: the observability of the navigation errors with and
//!   without sensor biases, under toolface indexing;
//!   [`observability_report`]: its ranks and per-state report as text.
//! - [`demo`]: the paper's static test simulated and coarse-aligned, with
//!   toolface indexing (`host-sim demo`).

pub mod coarse;
pub mod demo;
pub mod observability;
pub mod observability_report;
