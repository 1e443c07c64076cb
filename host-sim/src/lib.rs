//! Library side of the host tool, laid out by the data's way from the
//! probe's capture to the survey a person signs. The CLI in `main.rs`
//! (`commands/`) only parses arguments and calls this library; the system
//! tests use it too.
//!
//! The stages, in the order the data meets them. A stage uses only the
//! stages above it (and `mwd_core`); `tests/layering.rs` fails when one
//! imports a later one.
//!
//! 1. [`formats`]: reading and writing the tool's files (the probe's
//!    capture, the sample CSV, the depth log, the model and calibration
//!    files) and how values are shown to people.
//! 2. [`sim`]: the probe's motion and sensors simulated, and the drilling
//!    of a lateral along a well plan.
//! 3. [`replay`]: a capture (file or serial port) through the probe's own
//!    navigation code, compared with what the probe sent.
//! 4. [`analysis`]: sensor noise (Allan deviation, AR models) and the
//!    six-position calibration.
//! 5. [`alignment`]: coarse alignment of a static record and what a static
//!    probe can observe.
//! 6. [`survey`]: stations to positions with their ISCWSA uncertainty, the
//!    survey of a drilling capture, the job file, the listing and its
//!    figures.
//! 7. [`study`]: Monte Carlo studies of simulated drilling by gyro grade.
//! 8. [`paper`]: the papers' experiments reproduced.
//! 9. [`dashboard`]: the probe's live display as a local web page.

pub mod alignment;
pub mod analysis;
#[cfg(feature = "dashboard")]
pub mod dashboard;
pub mod formats;
pub mod paper;
pub mod replay;
pub mod sim;
pub mod study;
pub mod survey;
