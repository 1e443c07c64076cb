//! Aiding sources of the error-state filter, one file each (as PX4's
//! `aid_sources/`): each builds a [`crate::kalman::Measurement`] from what
//! the probe knows at that instant.
//!
//! The error states are computed - true, so a measurement's `z` is the
//! computed quantity minus its reference: for a zero-velocity update
//! `z = v_computed - 0 = dv` (paper eq. 47) and the row selects the
//! velocity error. Eq. 48 prints "H12, H13" as the unit blocks; the
//! velocity and position blocks are H12 and H23 (erratum 5,
//! docs/paper-errata.md).
//!
//! The non-holonomic constraint (no velocity across the tool axis while
//! drilling) is not in the paper: derivation section 4b.

mod attitude_angle;
mod axial_speed;
mod drilling_toolface;
mod earth_rate;
mod heading_reference;
mod non_holonomic;
mod zero_position;
mod zero_velocity;

pub(crate) use attitude_angle::attitude_angle_scalar;
pub use axial_speed::{AxialSpeed, AXIAL_SPEED_VARIANCE};
pub use drilling_toolface::{DrillingToolface, ForceBlock, TOOLFACE_BLOCK_SAMPLES};
pub use earth_rate::{attitude_rows, long_run_variance, predicted_rates, EarthRate};
pub use heading_reference::{HeadingReference, HeadingReferenceError};
pub use non_holonomic::{BhaCrossMotion, NonHolonomic, CROSS_AXES, DRILLING_VARIANCE};
pub use zero_position::ZeroPosition;
pub use zero_velocity::ZeroVelocity;
