//! Sensor-noise analysis and calibration: what the paper's team
//! did in MATLAB to characterise the SCC1300 (MGWD paper section 3.2),
//! done in the host tool.
//!
//! - [`allan`], [`allan_fit`]: Allan deviation with confidence intervals and
//!   the noise coefficients (random walk, bias instability, rate random walk);
//!   [`allan_analysis`] runs them on a record's columns, [`allan_report`]
//!   gives their tables and plot.
//! - [`arfit`]: autocorrelation and AR(p) fitting (Yule-Walker, Burg,
//!   covariance method), order selection, the model file the filter loads;
//!   [`ar_analysis`] runs them on a record's columns, [`arfit_report`]
//!   gives their tables.
//! - [`calibration`]: six-position calibration of accelerometer triads and
//!   gyro biases (paper Table 3), by least squares or total least squares;
//!   [`six_position`] runs it on a table's columns and makes the file,
//!   [`calibration_report`] gives its tables.
//! - [`tls`]: total least squares and Moore-Penrose reconstruction (TLS
//!   paper eq. 14-23).
//! - [`csv_input`], [`units`], [`plot`], [`stats`]: the analysis commands'
//!   column input and units, SVG plots, chi-square.
//!
//! Stage 2 of the data's way (see `lib.rs`): uses `formats` (the capture
//! and the sample CSV it reads). Its model files (AR models, calibration)
//! feed the simulator and the probe's configuration, so it comes before
//! `sim`.

pub mod allan;
pub mod allan_analysis;
pub mod allan_fit;
pub mod allan_report;
pub mod ar_analysis;
pub mod ar_file;
pub mod arfit;
pub mod arfit_report;
pub mod calibration;
pub mod calibration_file;
pub mod calibration_report;
pub mod csv_input;
pub mod plot;
pub mod six_position;
pub mod stats;
pub mod tls;
pub mod units;
