//! A well plan for the drilling simulator: the tie-on in the parent well,
//! then sections by measured depth (holds, and build/turn curves at a
//! dogleg severity to a target direction), with the drilling parameters.
//! Read from JSON (serde); every field documented in
//! `docs/drilling-simulation.md`. [`Plan::build`] checks it and turns it
//! into stations whose minimum-curvature path (`mwd_core::survey`) is the
//! simulated hole.
//!
//! Files: `file` (the plan file and its checks, the sections built into
//! stations), `drilling_params` (the drilling parameters, vibration and
//! depth errors), `built` (the built plan: arcs, and the hole at any MD),
//! `tortuosity` (the hole as drilled around the plan, drawn per run).
mod built;
mod drilling_params;
mod file;
#[cfg(test)]
mod tests;
mod tortuosity;

pub use built::{BuiltPlan, BuiltSection, PathPoint};
pub use drilling_params::{
    is_single_dwell, DepthErrors, DrillingParams, Tortuosity, Vibration, MAX_CONNECTION_DWELLS,
};
pub use file::{Plan, Section, Site, TieOnSpec, MAX_DLS_DEG_PER_30M, MAX_PLAN_LENGTH_M};
pub use tortuosity::{CurvatureWalk, DrilledPath};
