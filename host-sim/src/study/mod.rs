//! Monte Carlo studies over simulated runs (`host-sim study ...`).

pub mod drilling_coverage;
pub mod drilling_run;
pub mod rins_probe;
