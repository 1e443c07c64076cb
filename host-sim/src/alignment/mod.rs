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
//!   without sensor biases, under toolface indexing.

pub mod coarse;
pub mod observability;
