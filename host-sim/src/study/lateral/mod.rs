//! `host-sim study lateral`: which gyro meets the MGWD paper's design
//! requirement (`/work/shared/paper/mgwd.md`: attitude error under 0.1 deg,
//! horizontal position error under 1 m per 1000 m of well). The study
//! drills the repository's laterals in simulation with a gyro of each grade
//! ([`crate::study::grade`]), runs the probe's navigator and the survey on
//! them ([`crate::study::drilling_run`]) and compares the errors with what
//! the probe and the survey predict (docs/lateral-study.md).
//!
//! The files, in the order the data meets them:
//! - [`wells`]: the study's wells (built-in laterals or plan files) and
//!   the command line's drilling parameters;
//! - [`run`]: the jobs (Monte Carlo runs, covariance analyses, sweep
//!   points) in one pool over the cores, and the study's results;
//! - [`covariance`]: the covariance analysis (one error-free run per grade
//!   and well), its agreement with the Monte Carlo, and the sweep over gyro
//!   bias instability and ARW;
//! - [`summary`]: the statistics per grade and well and whether the
//!   requirement is met, with [`stations`] (every run's stations),
//!   [`correlation`] (the station azimuth errors' correlation along the
//!   well) and [`consistency`] (the azimuth sigma through stations and
//!   drilling);
//! - [`table`]: the terminal tables and the CSV, with `csv` (a CSV
//!   cell's quoting, which the station list shares);
//! - [`figures`]: the study's figures, drawn by [`plots`];
//! - [`grade_table`]: the README's grade table and its CSV
//!   (`study grade-table`);
//! - [`shard`]: the study in shards run apart (`--shard K/N`) and merged
//!   ([`crate::study::shard`]), each job's outcome kept exact by
//!   `shard_codec`.

pub mod consistency;
pub mod correlation;
pub mod covariance;
mod csv;
pub mod figures;
pub mod grade_table;
pub mod plots;
pub mod run;
pub mod shard;
pub(crate) mod shard_codec;
pub mod stations;
pub mod summary;
pub mod table;
pub mod wells;

pub use run::{study, GradeInfo, LateralStudy, StudyConfig, WellInfo, WellOwsg};
pub use wells::{DrillingOverrides, Well, BUILTIN_WELLS};
