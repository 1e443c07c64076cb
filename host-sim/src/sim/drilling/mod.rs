//! The drilling simulator: a lateral drilled along a
//! [`BuiltPlan`](crate::sim::plan::BuiltPlan) with an orienter on coiled
//! tubing or a sliding motor (no string rotation).
//!
//! * Schedule: a still period at the tie-on, then per stand: drilling at
//!   the rate of penetration (linear speed ramps at both ends), a still
//!   period at the connection, an orienter toolface turn; a final still
//!   period. While sliding, occasional toolface steps (Poisson).
//! * Truth: MD(t) from the schedule; direction and position at MD from the
//!   plan's minimum-curvature arcs (`mwd_core::survey::Segment::at`);
//!   gravity toolface = the section's toolface (a hold's setting, a curve's
//!   arc direction) + the orienter's steps. C_b^n from (toolface,
//!   inclination - 90 deg, azimuth) by `conventions::dcm_from_euler`.
//! * Ideal sensor outputs over each 50 ms interval: omega_ib^b = the exact
//!   rotation vector of C_b^n(t0)^T C_b^n(t1) / dt (omega_nb^b) + the mean
//!   of C_n^b (omega_ie^n + omega_en^n) (Simpson, 3 points); specific force
//!   f^b = mean of C_n^b (a^n + (2 omega_ie^n + omega_en^n) x v^n - g^n)
//!   (Simpson), with a^n = ROP' t + ROP^2 kappa (k x t) along the arc.
//! * Then the vibration as the 20 Hz samples see it (white, the in-band
//!   power the sensor's low-pass lets through; shocks), and the SCC1300's
//!   error model ([`SensorErrors`](crate::sim::sensor::SensorErrors)).
//!
//! Files: `phase` (the schedule's pieces: the rig's phases and the
//! orienter's toolface ramps), `schedule` (the schedule of a plan and the
//! truth at any instant), `samples` (the 20 Hz sample stream).
mod phase;
mod samples;
mod schedule;

pub use phase::{Connection, DrillState};
pub use samples::{rotation_vector, DrillSample, DrillingSimulator};
pub use schedule::{Drilling, Truth};
