//! A lateral study in shards: `study lateral --shard K/N` runs the K-th
//! of N slices of the study's jobs and writes a shard file; `study merge`
//! checks the shards belong together and rebuilds the study's results
//! from them, the same as one process gives (docs/study-scale-out.md).
//!
//! The slices: the study's jobs in their fixed order ([`StudyJobs`],
//! longest wells first, whatever the threads), job `i` (from 0) in shard
//! `i mod N + 1`. Round the list so, every shard gets its share of the
//! long and the short wells.
//!
//! A shard carries the study's inputs whole ([`StudySpec`]: grade and
//! plan files as text), so the merge needs no file of the shards' machine
//! and refuses shards of another study; and each of its jobs' outcome as
//! bytes ([`super::shard_codec`]), exact to the bit.

use super::covariance::SweepGrid;
use super::run::{JobOutcome, LateralStudy, StudyConfig, StudyJobs};
use super::shard_codec::{decode, encode, from_hex, to_hex};
use super::wells::{DrillingOverrides, Well};
use crate::study::drilling_run::Scalar;
use crate::study::grade::{self, Grade};
use anyhow::{bail, Context, Result};
use serde::{Deserialize, Serialize};

/// The shard file's format name and version (its first two fields).
pub const SHARD_FORMAT: &str = "host-sim lateral study shard";
/// Version 2: the runs drill their own tortuous holes (shards of version
/// 1 drilled the plan exactly, and hold no tortuosity).
pub const SHARD_VERSION: u32 = 2;

/// A file given as text: its name (a path, or a built-in well's label)
/// and content.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SourceText {
    pub name: String,
    pub text: String,
}

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

/// A number as [`StudySpec`] keeps it: as the command line prints it
/// (Rust's shortest text that reads back to the same bits).
pub fn exact_text(v: f64) -> String {
    v.to_string()
}

pub fn exact_number(text: &str, what: &str) -> Result<f64> {
    text.parse()
        .with_context(|| format!("{what} {text:?} is not a number"))
}

impl StudySpec {
    pub fn overrides(&self) -> Result<DrillingOverrides> {
        let read =
            |v: &Option<String>, what| v.as_deref().map(|t| exact_number(t, what)).transpose();
        Ok(DrillingOverrides {
            rop_m_per_h: read(&self.rop_m_per_h, "the rate of penetration")?,
            stand_length_m: read(&self.stand_length_m, "the stand length")?,
            connection_still_s: read(&self.connection_still_s, "the connection still time")?,
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

/// Which slice of the study: `index` of `count`, from 1.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct ShardIndex {
    pub index: usize,
    pub count: usize,
}

impl ShardIndex {
    /// "K/N" with 1 <= K <= N <= 100000.
    pub fn parse(text: &str) -> Result<Self, String> {
        let bad = || format!("{text:?}: a shard is K/N, 1 <= K <= N <= 100000 (e.g. 2/8)");
        let (k, n) = text.split_once('/').ok_or_else(bad)?;
        let k: usize = k.trim().parse().map_err(|_| bad())?;
        let n: usize = n.trim().parse().map_err(|_| bad())?;
        if k == 0 || k > n || n > 100_000 {
            return Err(bad());
        }
        Ok(Self { index: k, count: n })
    }

    /// The jobs of this shard among a study's `jobs`.
    pub fn jobs(&self, jobs: usize) -> Vec<usize> {
        (self.index - 1..jobs).step_by(self.count).collect()
    }
}

impl std::fmt::Display for ShardIndex {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

/// One job's outcome in a shard file.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct EncodedOutcome {
    /// The job's index in the study (from 0).
    pub job: usize,
    /// [`super::shard_codec`]'s bytes, hexadecimal.
    pub outcome: String,
}

/// A shard file.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ShardFile {
    pub format: String,
    pub version: u32,
    pub shard: ShardIndex,
    /// The whole study's jobs.
    pub jobs: usize,
    pub configuration: StudySpec,
    pub threads: usize,
    pub wall_s: f64,
    pub outcomes: Vec<EncodedOutcome>,
}

impl ShardFile {
    /// The shard of `outcomes` (every job of `shard`, from
    /// [`StudyJobs::run`]); `None` when a job of it did not run.
    pub fn new(
        spec: &StudySpec,
        shard: ShardIndex,
        outcomes: &[Option<JobOutcome>],
        threads: usize,
        wall_s: f64,
    ) -> Option<Self> {
        let encoded = shard
            .jobs(outcomes.len())
            .into_iter()
            .map(|job| {
                outcomes[job].as_ref().map(|o| EncodedOutcome {
                    job,
                    outcome: to_hex(&encode(o)),
                })
            })
            .collect::<Option<Vec<_>>>()?;
        Some(Self {
            format: SHARD_FORMAT.into(),
            version: SHARD_VERSION,
            shard,
            jobs: outcomes.len(),
            configuration: spec.clone(),
            threads,
            wall_s,
            outcomes: encoded,
        })
    }

    /// A shard file's text; `name` (its path) in every error.
    pub fn parse(text: &str, name: &str) -> Result<Self> {
        let value: serde_json::Value = serde_json::from_str(text)
            .with_context(|| format!("{name} is not a lateral study shard (not JSON)"))?;
        if value.get("format").and_then(|f| f.as_str()) != Some(SHARD_FORMAT) {
            bail!("{name} is not a lateral study shard (its \"format\" is not \"{SHARD_FORMAT}\")");
        }
        let version = value.get("version").and_then(|v| v.as_u64());
        if version != Some(u64::from(SHARD_VERSION)) {
            bail!(
                "{name}: shard format version {}, this host-sim reads version {SHARD_VERSION}",
                version.map_or_else(|| "missing".into(), |v| v.to_string())
            );
        }
        serde_json::from_value(value).with_context(|| format!("{name}: a damaged shard file"))
    }
}

/// What the shards of one study give together.
pub struct Merged {
    pub spec: StudySpec,
    /// The threads the shards ran on (the largest where they differ).
    pub threads: usize,
    /// The shards' wall times added: the work, not the elapsed time.
    pub wall_s: f64,
    pub jobs: usize,
    pub outcomes: Vec<Option<JobOutcome>>,
}

/// The shards (each with its name, read one at a time: only the
/// outcomes stay in memory) checked to make one study, whole: the same
/// configuration and shard count, every shard once, every job of each.
pub fn merge(shards: impl IntoIterator<Item = Result<(String, ShardFile)>>) -> Result<Merged> {
    let mut shards = shards.into_iter();
    let Some(first) = shards.next() else {
        bail!("no shard to merge");
    };
    let (first_name, first) = first?;
    let (count, jobs) = (first.shard.count, first.jobs);
    let mut merged = Merged {
        spec: first.configuration.clone(),
        threads: 1,
        wall_s: 0.0,
        jobs,
        outcomes: (0..jobs).map(|_| None).collect(),
    };
    let mut seen: Vec<Option<String>> = vec![None; count];
    for item in std::iter::once(Ok((first_name.clone(), first))).chain(shards) {
        let (name, shard) = item?;
        if shard.configuration != merged.spec || shard.jobs != jobs {
            bail!(
                "{name} is a shard of another study than {first_name} (they differ in: {})",
                differences(&merged.spec, &shard.configuration).join(", ")
            );
        }
        if shard.shard.count != count {
            bail!(
                "{name} is shard {} but {first_name} is one of {count}: not the same split",
                shard.shard
            );
        }
        let slot = shard
            .shard
            .index
            .checked_sub(1)
            .and_then(|i| seen.get_mut(i))
            .with_context(|| format!("{name}: shard {} does not exist", shard.shard))?;
        if let Some(other) = slot {
            bail!("shard {} given twice: {other} and {name}", shard.shard);
        }
        *slot = Some(name.clone());
        let expected = shard.shard.jobs(jobs);
        if !shard
            .outcomes
            .iter()
            .map(|o| o.job)
            .eq(expected.iter().copied())
        {
            bail!(
                "{name}: shard {} holds {} jobs, not the {} of its slice of the study's {jobs}",
                shard.shard,
                shard.outcomes.len(),
                expected.len()
            );
        }
        for o in &shard.outcomes {
            let outcome = from_hex(&o.outcome)
                .and_then(|b| decode(&b))
                .with_context(|| format!("{name}: job {}'s outcome is damaged", o.job))?;
            merged.outcomes[o.job] = Some(outcome);
        }
        merged.threads = merged.threads.max(shard.threads);
        merged.wall_s += shard.wall_s;
    }
    let missing: Vec<String> = (1..=count)
        .filter(|k| seen[k - 1].is_none())
        .map(|k| format!("{k}/{count}"))
        .collect();
    if !missing.is_empty() {
        bail!(
            "shard {} missing: every shard of the study is needed",
            missing.join(", ")
        );
    }
    Ok(merged)
}

impl Merged {
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

/// The fields in which two configurations differ, by name.
fn differences(a: &StudySpec, b: &StudySpec) -> Vec<String> {
    let (Ok(serde_json::Value::Object(a)), Ok(serde_json::Value::Object(b))) =
        (serde_json::to_value(a), serde_json::to_value(b))
    else {
        return vec!["the configuration".into()];
    };
    let mut fields: Vec<String> = a
        .iter()
        .filter(|(k, v)| b.get(k.as_str()) != Some(v))
        .map(|(k, _)| k.clone())
        .collect();
    if fields.is_empty() {
        fields.push("the number of jobs".into());
    }
    fields
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_parse_and_slice_every_job_once() {
        assert_eq!(
            ShardIndex::parse("2/4"),
            Ok(ShardIndex { index: 2, count: 4 })
        );
        for bad in ["0/4", "5/4", "4", "a/4", "1/0", "1/100001", "-1/4"] {
            assert!(ShardIndex::parse(bad).is_err(), "{bad}");
        }
        let mut all: Vec<usize> = (1..=4)
            .flat_map(|k| ShardIndex { index: k, count: 4 }.jobs(10))
            .collect();
        assert_eq!(ShardIndex { index: 2, count: 4 }.jobs(10), vec![1, 5, 9]);
        all.sort_unstable();
        assert_eq!(all, (0..10).collect::<Vec<_>>());
        // more shards than jobs: the last ones empty
        assert!(ShardIndex { index: 5, count: 5 }.jobs(3).is_empty());
    }

    #[test]
    fn numbers_keep_their_bits_through_the_spec() {
        for v in [0.1 + 0.2, 0.5, 1e-300, 123.456_789_012_345_67] {
            assert_eq!(
                exact_number(&exact_text(v), "v").expect("number").to_bits(),
                v.to_bits()
            );
        }
    }

    #[test]
    fn a_file_that_is_not_a_shard_is_named() {
        let e = format!(
            "{:#}",
            ShardFile::parse("{\"a\": 1}", "x.json").unwrap_err()
        );
        assert!(e.contains("x.json is not a lateral study shard"), "{e}");
        let e = format!("{:#}", ShardFile::parse("not json", "y.json").unwrap_err());
        assert!(e.contains("y.json is not a lateral study shard"), "{e}");
        let text = format!("{{\"format\": \"{SHARD_FORMAT}\", \"version\": 99}}");
        let e = format!("{:#}", ShardFile::parse(&text, "z.json").unwrap_err());
        assert!(e.contains("version 99"), "{e}");
    }
}
