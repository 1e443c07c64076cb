//! The drilling-coverage study in shards ([`super::shard`]): its jobs are
//! its seeds in order (job `k`: seed `first_seed + k`), its configuration
//! [`CoverageSpec`] (the plan as text), a job's outcome the run's, kept
//! exact by the lateral study's codec (`lateral::shard_codec`, the same
//! [`RunOutcome`]). A merge gives the runs in seed order, from which
//! [`summary_of`] makes the summary one process makes.

use super::drilling_coverage::{summary_of, Summary};
use super::drilling_run::{run, RunConfig, RunOutcome, Scalar};
use super::lateral::shard_codec::{decode_run, encode_run};
use super::shard::{exact_number, Merged, ShardIndex, ShardedStudy, SourceText};
use super::{run_jobs_until, StudyRuns};
use crate::sim::plan::Vibration;
use crate::sim::Plan;
use anyhow::{Context, Result};
use serde::{Deserialize, Serialize};

/// The drilling-coverage study's shard file format (its first field).
pub const COVERAGE_SHARD_FORMAT: &str = "host-sim drilling-coverage study shard";

/// Everything that makes a drilling-coverage study's results, threads
/// aside (numbers as their exact text, [`super::shard::exact_text`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CoverageSpec {
    /// The plan: its path as given (or how the built-in one is named) and
    /// its text.
    pub plan: SourceText,
    pub runs: usize,
    pub first_seed: u64,
    pub tie_in_azimuth_sigma_deg: String,
    /// `--vibration`'s level as the command line names it (`None`: the
    /// plan's).
    pub vibration: Option<String>,
    pub uncalibrated: bool,
    pub scalar: Scalar,
}

impl CoverageSpec {
    pub fn tie_in_azimuth_sigma_deg(&self) -> Result<f64> {
        exact_number(&self.tie_in_azimuth_sigma_deg, "the tie-in azimuth sigma")
    }

    /// The runs' configuration: the plan checked as a plan file is, with
    /// `vibration` (the level [`Self::vibration`] names) instead of its
    /// own; the SCC1300, the study's gyro.
    pub fn config(&self, vibration: Option<Vibration>) -> Result<RunConfig> {
        let mut plan = Plan::parse(&self.plan.text, &self.plan.name)?;
        if let Some(v) = vibration {
            plan.drilling.vibration = v;
        }
        let mut config = RunConfig::new(
            plan,
            self.tie_in_azimuth_sigma_deg()?.to_radians(),
            super::grade::Grade::scc1300()?,
        )?;
        config.uncalibrated = self.uncalibrated;
        config.scalar = self.scalar;
        Ok(config)
    }
}

/// The drilling-coverage study as [`super::shard`] runs it in shards.
pub struct Coverage;

impl ShardedStudy for Coverage {
    const FORMAT: &'static str = COVERAGE_SHARD_FORMAT;
    const NAME: &'static str = "drilling-coverage study";
    type Spec = CoverageSpec;
    type Outcome = Result<RunOutcome, String>;
    fn encode(outcome: &Self::Outcome) -> Vec<u8> {
        encode_run(outcome)
    }
    fn decode(bytes: &[u8]) -> Result<Self::Outcome> {
        decode_run(bytes)
    }
}

/// A drilling-coverage study's shard file.
pub type CoverageShardFile = super::shard::ShardFile<Coverage>;

/// The seeds of `shard` among `runs`' on its threads (each error as
/// "seed N: ..."); every other seed, and those `runs.stop` kept from
/// starting, `None`.
pub fn run_shard(
    config: &RunConfig,
    runs: &StudyRuns,
    shard: ShardIndex,
) -> Vec<Option<Result<RunOutcome, String>>> {
    let mine = shard.jobs(runs.runs);
    let ran = run_jobs_until(mine.len(), runs.threads, runs.progress, runs.stop, |i| {
        let seed = runs.first_seed + mine[i] as u64;
        run(config, seed).map_err(|e| format!("seed {seed}: {e:#}"))
    });
    let mut outcomes: Vec<Option<_>> = (0..runs.runs).map(|_| None).collect();
    for (&job, outcome) in mine.iter().zip(ran) {
        outcomes[job] = outcome;
    }
    outcomes
}

impl Merged<Coverage> {
    /// The study's summary, as one process makes it: the runs in seed
    /// order, the shards' wall times added.
    pub fn summary(self) -> Result<Summary> {
        let first_seed = self.spec.first_seed;
        let results = self
            .outcomes
            .into_iter()
            .enumerate()
            .map(|(k, o)| {
                let outcome = o.with_context(|| format!("run {k} missing after the merge"))?;
                Ok((first_seed + k as u64, outcome))
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(summary_of(&results, self.spec.runs, self.wall_s))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::study::lateral::BUILTIN_WELLS;
    use crate::study::run_checks::StationCheck;
    use crate::study::shard::{exact_text, merge, ShardFile};

    fn spec() -> CoverageSpec {
        CoverageSpec {
            plan: SourceText {
                name: "the built-in 100 m lateral".into(),
                text: BUILTIN_WELLS[0].1.into(),
            },
            runs: 3,
            first_seed: 7,
            tie_in_azimuth_sigma_deg: exact_text(0.5),
            vibration: None,
            uncalibrated: false,
            scalar: Scalar::F64,
        }
    }

    #[test]
    fn a_spec_makes_the_runs_configuration() {
        let config = spec().config(Some(Vibration::NONE)).expect("config");
        assert_eq!(config.tie_in_azimuth_sigma, 0.5f64.to_radians());
        assert_eq!(config.scalar, Scalar::F64);
        assert_eq!(config.plan.drilling.vibration, Vibration::NONE);
        let mut bad = spec();
        bad.plan.text = "{".into();
        let e = format!("{:#}", bad.config(None).expect_err("refused"));
        assert!(
            e.starts_with("the built-in 100 m lateral: not a well plan"),
            "{e}"
        );
    }

    #[test]
    fn merged_runs_come_back_in_seed_order() {
        let outcome = |k: u64| -> Option<Result<RunOutcome, String>> {
            Some(if k == 1 {
                Err("seed 8: failed".into())
            } else {
                Ok(RunOutcome::of_stations(7 + k, Vec::<StationCheck>::new()))
            })
        };
        let all: Vec<_> = (0..3).map(outcome).collect();
        let shard = |k| -> Result<(String, ShardFile<Coverage>)> {
            let index = ShardIndex { index: k, count: 2 };
            let file = ShardFile::<Coverage>::new(&spec(), index, &all, 1, 0.5).expect("ran");
            Ok((format!("s{k}"), file))
        };
        let summary = merge([shard(2), shard(1)])
            .expect("merged")
            .summary()
            .expect("summary");
        assert_eq!(summary.runs, 3);
        assert_eq!(summary.failed_runs, vec!["seed 8: failed".to_string()]);
        assert_eq!(summary.wall_s, 1.0);
        assert!(summary.interrupted.is_none());
    }
}
