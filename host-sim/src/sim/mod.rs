//! Trajectory and sensor simulation of the probe.
pub mod model_file;
pub mod sensor;
pub mod trajectory;

pub use model_file::SensorModelFile;
pub use sensor::{DeterministicErrors, SensorModel, SensorSimulator, SimSample};
pub use trajectory::{Motion, Trajectory};
