//! Navigation core of the gyro MWD probe: no_std, no heap, no unsafe. The
//! same code runs on the probe's Cortex-M4F and on the host.
//!
//! * Frames and angles: [`conventions`]; the earth: [`earth`].
//! * Navigation: [`attitude`], [`mechanization`], coarse [`alignment`].
//! * Sensors: [`sensor_units`] (SCC1300 counts), [`sensor_noise`] (error
//!   budget), [`calibration`] (correction step), [`ar`] (AR(p) noise).
//! * The filter: [`error_model`], [`kalman`], [`measurement`],
//!   [`fine_alignment`].
//! * The wire protocol: [`protocol`].
#![no_std]
#![forbid(unsafe_code)]

pub mod alignment;
pub mod ar;
pub mod attitude;
pub mod calibration;
pub mod conventions;
pub mod earth;
pub mod error_model;
pub mod fine_alignment;
pub mod kalman;
pub mod measurement;
pub mod mechanization;
pub mod probe;
pub mod protocol;
pub mod sensor_noise;
pub mod sensor_units;
