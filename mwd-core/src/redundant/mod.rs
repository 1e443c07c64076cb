//! Redundant rotational INS fusion (the [RINS] paper, Wang et al.): a
//! dual-axis master and a single-axis hot backup, whose difference feeds a
//! reduced-order Kalman filter that learns the backup's azimuth gyro drift,
//! and a prediction model that compensates the backup's position and
//! velocity once the master fails. `docs/redundant-rins.md` has the model,
//! the equations with the paper's numbers and the errata (RINS-1 to RINS-7 in
//! `docs/paper-errata.md`).
//!
//! * [`model`]: the full 17-state difference model (eq. 1-8) and the
//!   reduced 8-state one by F_r = T F T^T, G_r = T G (eq. 9-18).
//! * [`measurement`]: velocity and latitude/longitude differences
//!   (eq. 21-24), one type for both filters.
//! * [`observability`]: the stripped observability matrix of the
//!   piece-wise constant system (eq. 25-26) and its rank.
//! * [`prediction`]: the backup's error prediction after the master fails
//!   (eq. 31-32) and the compensation of its output (eq. 33).
//!
//! Frame: the paper's east-north-up, kept here (and only here) so that every
//! block reads as printed; the rest of the project is NED
//! (`crate::conventions`). Position errors are latitude and longitude
//! errors in radians, as in the paper (f64 on the host keeps them exact).
//! The filters themselves are the generic machinery of [`crate::kalman`].

pub mod measurement;
pub mod model;
pub mod observability;
pub mod prediction;

pub use measurement::DifferenceMeasurement;
pub use model::{
    full_dynamics, full_noise_input, navigation_block, reduced_dynamics, reduced_noise_input,
    reduction, transition, Motion, FULL_STATES, NOISE_INPUTS, REDUCED_STATES,
};
pub use observability::{nondimensional, observability_block, stripped_rank};
pub use prediction::{compensate, BackupOutput, DriftPrediction};

/// Indices of the states shared by both models (eq. 1 and eq. 7): attitude-
/// error difference east, north, up; velocity-error difference east, north;
/// latitude and longitude error difference.
pub mod index {
    pub const PHI_E: usize = 0;
    pub const PHI_N: usize = 1;
    pub const PHI_U: usize = 2;
    pub const DV_E: usize = 3;
    pub const DV_N: usize = 4;
    pub const D_LAT: usize = 5;
    pub const D_LON: usize = 6;
    /// The reduced model's eighth state: the backup's azimuth (body z) gyro
    /// drift eps_z (rad/s).
    pub const DRIFT_Z: usize = 7;
    /// The full model's bias blocks (eq. 1, 3-4): backup gyro drift x y z,
    /// master gyro drift x y z, backup accelerometer bias x y, master x y.
    pub const EPS_1: usize = 7;
    pub const EPS_2: usize = 10;
    pub const NABLA_1: usize = 13;
    pub const NABLA_2: usize = 15;
}
