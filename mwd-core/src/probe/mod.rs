//! The probe's navigation: what it does with each raw sample, the same code
//! on the probe's Cortex-M4F and in the host's replay (which must reproduce
//! the probe's solutions bit for bit).
//!
//! * [`raw`]: a raw sample's counts to calibrated body-frame rates and force.
//! * [`navigator`]: coarse alignment, fine alignment, navigation with
//!   station surveys at still periods.
//! * [`navigator::commands`]: the surface's survey commands (start
//!   surveying, take a station now, toolface indexing).
//! * [`still`]: the still detector.
//! * [`station`]: a station's drilling angles and their covariance.
//! * [`station_link`]: a station's errors' link to the previous station's.
//! * [`tie_in`]: a start from a parent well's survey instead of the
//!   static alignment.

pub mod navigator;
pub mod raw;
pub mod station;
pub mod station_link;
pub mod still;
#[cfg(test)]
mod test_support;
pub mod tie_in;

pub use navigator::{Navigator, NavigatorScalar};
pub use raw::body_sample;
pub use station_link::StationLink;
pub use tie_in::{TieIn, TieInAngle, TieInError};
