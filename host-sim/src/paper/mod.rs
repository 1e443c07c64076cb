//! The papers' experiments reproduced, each beside the paper's own figures
//! (their errata in `docs/paper-errata.md`).
//!
//! Stage 8 of the data's way (see `lib.rs`): uses any earlier stage.
//!
//! - [`mgwd`]: the MGWD paper's 60 s static test (section 4), coarse then
//!   fine alignment.
//! - [`tls`]: the TLS paper's gyro-free IMU decoupling (Ding et al. 2011).
//! - [`rins`]: the redundant-RINS paper's semi-physical simulation.

pub mod mgwd;
pub mod rins;
pub mod tls;
