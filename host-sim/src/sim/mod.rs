//! Trajectory and sensor simulation of the probe: scripted motions at one
//! place (`trajectory`) and the drilling of a lateral along a well plan
//! (`plan`, `drilling`), and what a simulation writes (`outputs`: the
//! samples as a capture or CSV, a lateral's truth and depth log).
pub mod drilling;
pub mod model_file;
pub mod outputs;
pub mod plan;
pub mod sensor;
pub mod stream;
pub mod trajectory;

pub use drilling::{DrillSample, DrillState, Drilling, DrillingSimulator, Truth};
pub use model_file::SensorModelFile;
pub use plan::{BuiltPlan, Plan};
pub use sensor::{DeterministicErrors, SensorErrors, SensorModel, SensorSimulator, SimSample};
pub use trajectory::{Motion, Trajectory};
