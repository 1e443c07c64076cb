//! Library side of the host tool, laid out by the data's way from the
//! probe's capture to the survey a person signs. The CLI in `main.rs`
//! (`commands/`) only parses arguments and calls this library; the system
//! tests use it too.
//!
//! The stages below are declared in the order the data meets them. A stage
//! uses only the stages above it (and `mwd_core`); `tests/layering.rs`
//! fails when one imports a later one. Each stage's `mod.rs` says what it
//! does and which stages it uses.

// 1. Reading and writing the tool's files (the probe's capture, the sample
//    CSV, the depth log, figures) and how values are shown to people.
pub mod formats;

// 2. Sensor noise (Allan deviation, AR models) and the six-position
//    calibration, measured from records; its model files feed the simulator.
pub mod analysis;

// 3. The probe's motion and sensors simulated, and the drilling of a
//    lateral along a well plan.
pub mod sim;

// 4. A capture (file or serial port) through the probe's own navigation
//    code, compared with what the probe sent.
pub mod replay;

// 5. Coarse alignment of a static record and what a static probe can
//    observe.
pub mod alignment;

// 6. Stations to positions with their ISCWSA uncertainty, the survey of a
//    drilling capture, the job file, the listing and its figures.
pub mod survey;

// 7. Monte Carlo studies of simulated drilling by gyro grade.
pub mod study;

// 8. The papers' experiments reproduced.
pub mod paper;

// 9. The probe's live display as a local web page.
#[cfg(feature = "dashboard")]
pub mod dashboard;
