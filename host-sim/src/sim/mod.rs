//! Trajectory and sensor simulation of the probe: scripted motions at one
//! place (`trajectory`) and the drilling of a lateral along a well plan
//! (`plan`, `drilling`), with the SCC1300's errors (`sensor`, its model
//! file `model_file`) and the probe's physical input stream (`stream`);
//! and what a simulation writes (`outputs`: the samples as a capture or
//! CSV, a lateral's truth and depth log). The simulator writes the same
//! captures the probe sends, with the truth beside them.
//!
//! Stage 3 of the data's way (see `lib.rs`): uses `formats` (the sample it
//! produces, the captures it writes) and `analysis` (the AR model and
//! calibration files its sensor model reads).

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
