//! The papers' experiments reproduced, each beside the paper's own figures
//! (their errata in `docs/paper-errata.md`).
//!
//! Stage 8 of the data's way (see `lib.rs`): uses any earlier stage.
//!
//! - [`mgwd`]: the MGWD paper's 60 s static test (section 4), coarse then
//!   fine alignment; [`mgwd_report`]: its report beside the paper's
//!   figures, and its figures.
//! - [`tls`]: the TLS paper's gyro-free IMU decoupling (Ding et al. 2011);
//!   [`tls_report`]: its Tables 1-2 beside the paper's.
//! - [`rins`]: the redundant-RINS paper's semi-physical simulation;
//!   [`rins_report`]: its report and the strapdown check's.

pub mod mgwd;
pub mod mgwd_report;
pub mod rins;
pub mod rins_report;
pub mod tls;
pub mod tls_report;
