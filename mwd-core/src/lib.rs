//! Navigation core of the gyro MWD probe: no_std, no heap, no unsafe. The
//! same code runs on the probe's Cortex-M4F and on the host.
//!
//! * Frames and angles: [`conventions`]; the earth: [`earth`]; the 20 Hz
//!   clock: [`timing`].
//! * Sensors: [`probe_sample`] (what the probe senses), [`sensor_units`]
//!   (SCC1300 counts), [`sensor_noise`] (error budget), [`calibration`]
//!   (correction step), [`ar`] (AR(p) noise).
//! * Navigation: [`attitude`], [`mechanization`], coarse [`alignment`].
//! * The filter: [`kalman`] (the generic machinery, a leaf),
//!   [`error_model`] (the 33/39-state model), [`aid_sources`] (one file per
//!   measurement), [`fine_alignment`] (the closed loop).
//! * The probe's navigation, raw sample to solution: [`probe`].
//! * Wellbore surveys (stations, north references, minimum curvature
//!   positions from a tie-on): [`survey`].
//! * The wire protocol: [`protocol`]; what the host configures and its
//!   record in flash: [`config`].
#![no_std]
#![forbid(unsafe_code)]

pub mod aid_sources;
pub mod alignment;
pub mod ar;
pub mod attitude;
pub mod calibration;
pub mod config;
pub mod conventions;
pub mod earth;
pub mod error_model;
pub mod fine_alignment;
pub mod kalman;
pub mod mechanization;
pub mod probe;
pub mod probe_sample;
pub mod protocol;
pub mod redundant;
pub mod sensor_noise;
pub mod sensor_units;
pub mod survey;
pub mod timing;
