//! The AR model file `host-sim arfit` writes and the filter set-up loads:
//! JSON, one entry per sensor, coefficients in the paper's (`aryule`) sign
//! convention and the innovation variance in SI units squared
//! ((m/s^2)^2 for accelerometers, (rad/s)^2 for gyros).
//!
//! ```json
//! {"format": "mwd-ar-models", "version": 1, "models": [
//!   {"sensor": "ax", "quantity": "specific-force", "method": "yule-walker",
//!    "order": 4, "sample_rate_hz": 20.0, "coefficients": [0.33, ...],
//!    "noise_variance": 0.0034, "noise_variance_unit": "(m/s^2)^2",
//!    "std_errors": [...], "reflection": [...]}]}
//! ```
//!
//! Files: [`limits`] (the physical range of every field), `model_check`
//! (what a channel measures and the check of one model), `file` (the
//! entries and the file read, checked and written), `filter_axes` (the
//! filter's channels and the mapping of a file's models onto them).

mod file;
mod filter_axes;
pub mod limits;
mod model_check;

pub use file::{ArModelEntry, ArModelFile, FORMAT, VERSION};
pub use filter_axes::{AxisSource, FilterAxis, DERIVED_RATE, FILTER_AXES};
pub use model_check::{check_ar, largest_root_modulus, ArQuantity};
