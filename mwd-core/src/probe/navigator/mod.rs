//! The probe's navigation, run by its main loop (lower priority than
//! acquisition):
//! raw samples in, navigation-solution frames out. The probe must first be
//! still:
//! 1. coarse alignment: the first 5 s of samples are averaged, levelled and
//!    gyrocompassed (`crate::alignment`);
//! 2. fine alignment: the 39-state filter (33 AR-augmented states of the
//!    paper plus six sensor biases) with zero-velocity and zero-position
//!    updates, closed loop, until 60 s (the paper's test length), with the
//!    settings scaled to the SCC1300's error budget
//!    (`FineAlignmentConfig::physical`, the same the host's `paper mgwd`
//!    runs);
//! 3. navigation: the same filter without the zero updates, so the
//!    mechanization runs on (bias estimates still compensated through the
//!    filter's dynamics) and the reported uncertainties grow honestly;
//! 4. station surveys, within navigation: whenever the still detector
//!    (`super::still`, thresholds from the noise budget) finds the probe
//!    at rest (the string in the slips at a connection), each cycle gets a
//!    zero-velocity update (the filter re-levels through it: the velocity
//!    error is driven by the tilt error times g, derivation section 3),
//!    every block of [`SURVEY_SETTLE_EPOCHS`] still cycles gets a rate
//!    gyrocompass (the x and z gyros' block means against the earth rate
//!    at the filter's attitude: heading, tilt and both rate biases,
//!    `aid_sources::EarthRate`, derivation section 4e), and when motion
//!    resumes (or after [`MAX_STATION_SAMPLES`]) the
//!    navigator hands out a station survey ([`Navigator::take_station`]):
//!    inclination, azimuth and toolface of the last still cycle with their
//!    covariance (`super::station`). No zero-position update: the probe's
//!    position while drilling is not known. The station's cycle is in
//!    `stations.rs`.
//!
//! What the frames say besides the solution (docs/protocol.md, Kind 2;
//! docs/filter-derivation.md section 5b): during the coarse alignment the
//! attitude and velocity are NaN placeholders; after it the covariance
//! is health-checked every cycle (an invalid one is latched, its sigmas
//! sent as NaN), a tilt sigma beyond [`TILT_SIGMA_LIMIT_RAD`] marks the
//! solution invalid, a sample with no valid part is propagated on the held
//! sample (coasting), and with one part out the other carries on alone
//! (single part; azimuth not determined).
//!
//! Every sample first goes through the probe's calibration (the host's
//! six-position result, [`crate::calibration`]). The host replays the same
//! raw frames through this same code and must get the probe's solutions
//! bit for bit.
//!
//! The files, in the order a cycle meets them: `state.rs` (the navigator,
//! its phases and a station in progress, its constructors and settings),
//! `cycle.rs` (the entry points, one raw sample to its phase, a gap's
//! coasting), `coarse.rs` and `fine.rs` (the static and the fine
//! alignment), `navigation.rs` (a navigating cycle) with `drilling.rs`
//! (the drilling environment), `stations.rs` (station surveys),
//! `heading.rs` (the heading's loss and references), `frame.rs` (what a
//! frame reports); `tie_in_start.rs` (a start from a tie-in) and
//! [`commands`] (the surface's survey commands) between cycles.

mod coarse;
pub mod commands;
mod cycle;
mod drilling;
mod fine;
mod frame;
mod heading;
mod navigation;
mod readout;
mod state;
mod stations;
mod tie_in_start;

/// The largest roll or pitch 1-sigma (rad) for which the solution is
/// valid: the error model's limit (`crate::error_model`), re-exported
/// here where the frames and stations apply it.
pub use crate::error_model::TILT_SIGMA_LIMIT_RAD;
pub use cycle::{NavigatorScalar, UNMEASURED_FORCE_SIGMA, UNMEASURED_RATE_SIGMA};
pub use drilling::{
    DRILLING_ANGULAR_SIGMA_RAD_S, DRILLING_JITTER_LIMIT_M_S2, DRILLING_TOOLFACE_VARIANCE_PER_S,
    SINGLE_SAMPLE_ROLL_SIGMA_RAD,
};
pub use frame::VARIANCE_LIMIT;
pub use heading::AZIMUTH_SIGMA_LIMIT_RAD;
pub use state::{Navigator, MAX_STATION_SAMPLES, STATION_ZUPT_VARIANCE};
pub use stations::{EARTH_RATE_GATE, MIN_BIAS_UPDATE_SAMPLES, SURVEY_SETTLE_EPOCHS};

#[cfg(test)]
mod settings_tests;

#[cfg(test)]
mod tests;

#[cfg(test)]
mod station_tests;

#[cfg(test)]
mod slide_tests;

#[cfg(test)]
mod heading_tests;
