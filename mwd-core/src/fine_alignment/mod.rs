//! Quasi-stationary fine alignment (paper section 3.2.3 and 4): from the
//! coarse alignment, run the strapdown mechanization and the 33-state
//! filter (or the 39-state one with sensor biases) at the sample rate with zero-velocity and zero-position updates,
//! feeding the estimated navigation errors back into the mechanization
//! after every update (closed loop) and zeroing them in the filter.
//!
//! Only the navigation errors are fed back: the AR states are the filter's
//! memory of the coloured sensor noise, not a correction of the solution,
//! so they stay in the state; so do the bias estimates (the mechanization
//! takes raw samples: the filter's dynamics carry the bias's effect).
//!
//! The files: `config.rs` (the settings), `filter.rs` (the filter and its
//! step), `bias.rs` (the sensor-bias states' random walk and the
//! accelerometer biases kept at rest), `attitude.rs` (the attitude and
//! its covariance set or widened from outside), `aiding.rs` (measurements
//! between steps), `linearization.rs` (where the error model is
//! linearised) and `held_axis.rs` (the time update with the tool-axis
//! rate held).

mod aiding;
mod attitude;
mod bias;
mod config;
mod filter;
mod held_axis;
mod linearization;

pub use config::{
    ArInitialCovariance, BiasWalk, FineAlignmentConfig, SpecificForceInModel, TiltPrior,
};
pub use filter::{FineAlignment, StepNoise, StepReport};
pub use held_axis::predict_holding_axis;
pub use linearization::{MAX_LINEARIZATION_HEADING_LAG_RAD, MAX_LINEARIZATION_TURN_RAD};

#[cfg(test)]
mod tests;
