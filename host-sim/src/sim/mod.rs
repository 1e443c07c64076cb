//! Trajectory and sensor simulation of the probe.
pub mod model_file;
pub mod sensor;
pub mod trajectory;

pub use model_file::SensorModelFile;
pub use sensor::{DeterministicErrors, SensorModel, SensorSimulator, SimSample};
pub use trajectory::{Motion, Trajectory};

/// Only for `coarse.rs`'s tests, edited elsewhere while this alias goes:
/// everything else takes `mwd_core::probe::timing::SAMPLE_INTERVAL_S`.
#[cfg(test)]
pub use mwd_core::probe::timing::SAMPLE_INTERVAL_S as SAMPLE_INTERVAL;
