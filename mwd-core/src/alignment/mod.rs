//! Coarse alignment of a tool at rest (paper section 3.2.3): levelling from
//! averaged accelerometers, then heading from the earth rate the gyros see,
//! adapted to the probe's gyros (body x and z only).
//!
//! Physics the results respect, by design: with gyros across
//! the tool axis, the heading signal is mainly the cross-axis earth rate
//! Omega cos(lat) sin(heading), plus a pitch-dependent share of the
//! along-axis component. Heading is well determined for a tool heading north
//! or south (where the two candidates psi and 180 deg - psi explain the data
//! alike unless the tool is pitched: the north/south ambiguity, resolved from
//! a prior) and badly determined heading east or west. Gyro bias is
//! comparable with the earth rate, so a single position's heading is
//! bias-limited; toolface indexing (segments at different roll) reverses
//! the cross-axis gyros and lets the estimator separate bias from earth rate.
//!
//! Two methods:
//! * [`gyrocompass`]: eq. 27-29 generalised. Levelling per segment
//!   (eq. 27-28), then the heading that best explains the gyro means of all
//!   segments (eq. 29's tan psi = -omega_x / omega_y is its closed form for a
//!   level tool with a forward gyro), with gyro biases common to all segments
//!   estimated under their prior. The product's default.
//! * [`analytical`]: eq. 30, the TRIAD of gravity, earth rate and their cross
//!   product, with the unmeasured tool-axis rate reconstructed from the
//!   earth-rate magnitude (two signs: the north/south ambiguity).
//!
//! Every heading carries its 1-sigma uncertainty from the sensor error
//! budget ([`ImuNoise`](crate::sensor_noise::ImuNoise)), propagated
//! through the estimator by central differences, and flags for
//! ill-conditioning and ambiguity. The local (linearised) sigma is only a
//! floor: near east/west the misfit is far from quadratic in heading, so
//! the printed bound also covers every heading the data allow (the
//! profile-likelihood interval: misfit within [`COVERAGE_FACTOR`]^2 of
//! the estimate's), and the ill-conditioning flag
//! is raised when the geometry is weak anywhere in that interval, not only
//! at the estimate, which noise can pull away from east/west.
//!
//! The files: `segments.rs` (the static segments, what the alignment
//! needs besides them, and the checks that refuse them), `solution.rs`
//! (levelling and the two heading methods), `misfit.rs` (the heading's
//! misfit to the gyro means and its minima) and `uncertainty.rs` (the
//! heading's sigma, the headings the data allow, and the flags).

mod misfit;
mod segments;
mod solution;
mod uncertainty;

pub use segments::{AlignmentConfig, AlignmentError, SegmentSums, StaticSegment, MAX_SEGMENTS};
pub use solution::{
    analytical, gyrocompass, level_segment, HeadingEstimate, LevelEstimate, Uncertain,
    AMBIGUITY_CHI2,
};
pub use uncertainty::{COVERAGE_FACTOR, ILL_CONDITIONED_SENSITIVITY, MAX_DETERMINED_SIGMA};

#[cfg(test)]
mod tests;
