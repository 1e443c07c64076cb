//! The lateral study in shards ([`crate::study::shard`]): its
//! configuration ([`StudySpec`]), its jobs' outcomes ([`super::shard_codec`])
//! and the study rebuilt from a merge ([`Merged::study`]).
//!
//! The slices: the study's jobs in their fixed order ([`StudyJobs`],
//! longest wells first, whatever the threads), so every shard gets its
//! share of the long and the short wells. A shard carries the grade and
//! plan files as text, so the merge needs no file of the shards' machine.

use super::covariance::SweepGrid;
use super::run::{JobOutcome, LateralStudy, StudyConfig, StudyJobs};
use super::shard_codec::{decode, encode};
use super::wells::{DrillingOverrides, Well};
use crate::study::drilling_run::Scalar;
use crate::study::grade::{self, Grade};
pub use crate::study::shard::{
    exact_number, exact_text, merge, Merged, ShardIndex, ShardedStudy, SourceText,
};
use anyhow::{bail, Result};
use serde::{Deserialize, Serialize};

/// The lateral study's shard file format (its first field).
pub const SHARD_FORMAT: &str = "host-sim lateral study shard";

/// The lateral study as [`crate::study::shard`] runs it in shards.
pub struct Lateral;

impl ShardedStudy for Lateral {
    const FORMAT: &'static str = SHARD_FORMAT;
    const NAME: &'static str = "lateral study";
    type Spec = StudySpec;
    type Outcome = JobOutcome;
    fn encode(outcome: &JobOutcome) -> Vec<u8> {
        encode(outcome)
    }
    fn decode(bytes: &[u8]) -> Result<JobOutcome> {
        decode(bytes)
    }
}

/// A lateral study's shard file.
pub type ShardFile = crate::study::shard::ShardFile<Lateral>;

/// Everything that makes the study's results, threads aside: two shards
/// belong to the same study when theirs are equal. Decimal numbers are
/// kept as text (Rust's shortest exact form), read back to the same bits.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StudySpec {
    /// `--grades` as given (empty: all).
    pub grades: Vec<String>,
    pub grade_files: Vec<SourceText>,
    /// The wells' plans, named by their labels.
    pub wells: Vec<SourceText>,
    pub rop_m_per_h: Option<String>,
    pub stand_length_m: Option<String>,
    pub connection_still_s: Option<String>,
    /// `--dwells` (absent in the shards of a study without it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub connection_dwells: Option<u32>,
    pub tortuosity_deg_per_30m: Option<String>,
    pub tortuosity_length_m: Option<String>,
    pub tie_in_azimuth_sigma_deg: String,
    pub runs: usize,
    pub first_seed: u64,
    pub monte_carlo: bool,
    /// The sweep's points per axis.
    pub sweep: Option<u64>,
    pub scalar: Scalar,
}

impl StudySpec {
    pub fn overrides(&self) -> Result<DrillingOverrides> {
        let read =
            |v: &Option<String>, what| v.as_deref().map(|t| exact_number(t, what)).transpose();
        Ok(DrillingOverrides {
            rop_m_per_h: read(&self.rop_m_per_h, "the rate of penetration")?,
            stand_length_m: read(&self.stand_length_m, "the stand length")?,
            connection_still_s: read(&self.connection_still_s, "the connection still time")?,
            connection_dwells: self.connection_dwells,
            tortuosity_deg_per_30m: read(&self.tortuosity_deg_per_30m, "the tortuosity")?,
            tortuosity_length_m: read(
                &self.tortuosity_length_m,
                "the tortuosity's correlation length",
            )?,
        })
    }

    /// The study on `threads` threads: the grade files and plans parsed
    /// as the command line parses them.
    pub fn config(&self, threads: usize) -> Result<StudyConfig> {
        let from_files = self
            .grade_files
            .iter()
            .map(|f| Grade::parse(&f.text, &f.name))
            .collect::<Result<Vec<_>>>()?;
        let grades = grade::select_parsed(&self.grades, from_files)?;
        let overrides = self.overrides()?;
        let wells = self
            .wells
            .iter()
            .map(|w| Well::parse(&w.name, &w.text, &overrides))
            .collect::<Result<Vec<_>>>()?;
        Ok(StudyConfig {
            grades,
            wells,
            runs: self.runs,
            first_seed: self.first_seed,
            threads,
            tie_in_azimuth_sigma: exact_number(
                &self.tie_in_azimuth_sigma_deg,
                "the tie-in azimuth sigma",
            )?
            .to_radians(),
            monte_carlo: self.monte_carlo,
            sweep: self.sweep.map(|n| SweepGrid::default_grid(n as usize)),
            scalar: self.scalar,
        })
    }
}

impl Merged<Lateral> {
    /// The study's results, as one process gives them: the shards'
    /// configuration on their threads, its jobs checked against the
    /// shards' (a host-sim of another version may make other jobs).
    pub fn study(self) -> Result<LateralStudy> {
        let config = self.spec.config(self.threads)?;
        let jobs = StudyJobs::new(&config)?;
        if jobs.len() != self.jobs {
            bail!(
                "the shards' study has {} jobs, this host-sim makes {} of its configuration: shards of another version",
                self.jobs,
                jobs.len()
            );
        }
        Ok(jobs.assemble(self.outcomes, self.wall_s, self.threads))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_file_of_another_study_is_no_lateral_shard() {
        let text = "{\"format\": \"host-sim drilling-coverage study shard\", \"version\": 1}";
        let e = format!(
            "{:#}",
            ShardFile::parse(text, "c.json").err().expect("refused")
        );
        assert!(e.contains("c.json is not a lateral study shard"), "{e}");
        assert!(e.contains("drilling-coverage"), "{e}");
    }
}
