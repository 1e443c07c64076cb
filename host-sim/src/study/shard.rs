//! A study in shards, whatever the study: `--shard K/N` runs the K-th of
//! N slices of its jobs and writes a shard file; `study merge` checks the
//! shards belong together and gives back every job's outcome, from which
//! the study makes the outputs one process makes (docs/study-scale-out.md).
//! Two studies shard today: the lateral study
//! ([`super::lateral::shard`]) and the drilling-coverage study
//! ([`super::coverage_shard`]); each says what its configuration and a
//! job's outcome are ([`ShardedStudy`]).
//!
//! The slices: the study's jobs in their fixed order, job `i` (from 0) in
//! shard `i mod N + 1`. Round the list so, every shard gets its share of
//! the long and the short jobs.
//!
//! A shard carries the study's inputs whole (the study's configuration:
//! its files as text), so the merge needs no file of the shards' machine
//! and refuses shards of another study; and each of its jobs' outcome as
//! bytes ([`super::lateral::shard_codec`]), exact to the bit.

use anyhow::{bail, Context, Result};
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

/// The shard file's format version (its second field), every study's.
/// Version 2: the runs drill their own tortuous holes (shards of version
/// 1 drilled the plan exactly, and hold no tortuosity).
pub const SHARD_VERSION: u32 = 2;

/// A study that runs in shards.
pub trait ShardedStudy {
    /// The shard file's "format" (its first field).
    const FORMAT: &'static str;
    /// The study as errors name it ("lateral study").
    const NAME: &'static str;
    /// Everything that makes the study's results, threads aside: two
    /// shards belong to the same study when theirs are equal.
    type Spec: Clone + PartialEq + Serialize + DeserializeOwned;
    /// One job's outcome.
    type Outcome;
    fn encode(outcome: &Self::Outcome) -> Vec<u8>;
    fn decode(bytes: &[u8]) -> Result<Self::Outcome>;
}

/// A file given as text: its name (a path, or a built-in well's label)
/// and content.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SourceText {
    pub name: String,
    pub text: String,
}

/// A number as a study's configuration keeps it: as the command line
/// prints it (Rust's shortest text that reads back to the same bits; a
/// JSON number may be read back a bit off).
pub fn exact_text(v: f64) -> String {
    v.to_string()
}

pub fn exact_number(text: &str, what: &str) -> Result<f64> {
    text.parse()
        .with_context(|| format!("{what} {text:?} is not a number"))
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
    /// [`ShardedStudy::encode`]'s bytes, hexadecimal.
    pub outcome: String,
}

/// A shard file.
#[derive(Serialize, Deserialize)]
#[serde(bound(serialize = "", deserialize = ""))]
pub struct ShardFile<S: ShardedStudy> {
    pub format: String,
    pub version: u32,
    pub shard: ShardIndex,
    /// The whole study's jobs.
    pub jobs: usize,
    pub configuration: S::Spec,
    pub threads: usize,
    pub wall_s: f64,
    pub outcomes: Vec<EncodedOutcome>,
}

impl<S: ShardedStudy> ShardFile<S> {
    /// The shard of `outcomes` (every job of the study, those of `shard`
    /// run); `None` when a job of it did not run.
    pub fn new(
        spec: &S::Spec,
        shard: ShardIndex,
        outcomes: &[Option<S::Outcome>],
        threads: usize,
        wall_s: f64,
    ) -> Option<Self> {
        let encoded = shard
            .jobs(outcomes.len())
            .into_iter()
            .map(|job| {
                outcomes[job].as_ref().map(|o| EncodedOutcome {
                    job,
                    outcome: to_hex(&S::encode(o)),
                })
            })
            .collect::<Option<Vec<_>>>()?;
        Some(Self {
            format: S::FORMAT.into(),
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
        let not_one = format!("{name} is not a {} shard", S::NAME);
        let value: serde_json::Value =
            serde_json::from_str(text).with_context(|| format!("{not_one} (not JSON)"))?;
        match shard_format(&value) {
            Some(f) if f == S::FORMAT => {}
            Some(f) => bail!(
                "{not_one} (its \"format\" is \"{f}\", not \"{}\")",
                S::FORMAT
            ),
            None => bail!("{not_one} (it has no \"format\" \"{}\")", S::FORMAT),
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

/// A shard file's "format", whichever study's (`None`: not a JSON object
/// with one): what `study merge` dispatches on.
pub fn shard_format(value: &serde_json::Value) -> Option<&str> {
    value.get("format").and_then(|f| f.as_str())
}

/// What the shards of one study give together.
pub struct Merged<S: ShardedStudy> {
    pub spec: S::Spec,
    /// The threads the shards ran on (the largest where they differ).
    pub threads: usize,
    /// The shards' wall times added: the work, not the elapsed time.
    pub wall_s: f64,
    pub jobs: usize,
    /// Every job's outcome (all `Some` after [`merge`]).
    pub outcomes: Vec<Option<S::Outcome>>,
}

/// The shards (each with its name, read one at a time: only the
/// outcomes stay in memory) checked to make one study, whole: the same
/// configuration and shard count, every shard once, every job of each.
pub fn merge<S: ShardedStudy>(
    shards: impl IntoIterator<Item = Result<(String, ShardFile<S>)>>,
) -> Result<Merged<S>> {
    let mut shards = shards.into_iter();
    let Some(first) = shards.next() else {
        bail!("no shard to merge");
    };
    let (first_name, first) = first?;
    let (count, jobs) = (first.shard.count, first.jobs);
    let mut merged = Merged::<S> {
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
                .and_then(|b| S::decode(&b))
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

/// The fields in which two configurations differ, by name.
fn differences(a: &impl Serialize, b: &impl Serialize) -> Vec<String> {
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

/// Lower-case hexadecimal, two digits a byte.
pub fn to_hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

pub fn from_hex(text: &str) -> Result<Vec<u8>> {
    if text.len() % 2 != 0 || !text.is_ascii() {
        bail!("not hexadecimal bytes");
    }
    (0..text.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&text[i..i + 2], 16).context("not hexadecimal bytes"))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A study whose job outcome is a byte: what the merge's checks need.
    struct Bytes;

    impl ShardedStudy for Bytes {
        const FORMAT: &'static str = "test shard";
        const NAME: &'static str = "test study";
        type Spec = String;
        type Outcome = u8;
        fn encode(o: &u8) -> Vec<u8> {
            vec![*o]
        }
        fn decode(b: &[u8]) -> Result<u8> {
            match b {
                [o] => Ok(*o),
                _ => bail!("not one byte"),
            }
        }
    }

    fn shard(k: usize, spec: &str) -> Result<(String, ShardFile<Bytes>)> {
        let all: Vec<Option<u8>> = (0..5u8).map(Some).collect();
        let index = ShardIndex { index: k, count: 2 };
        let file =
            ShardFile::<Bytes>::new(&spec.to_string(), index, &all, 1, 1.0).expect("every job ran");
        Ok((format!("s{k}"), file))
    }

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
    fn the_merge_takes_every_shard_once_of_one_study() {
        let merged = merge([shard(2, "a"), shard(1, "a")]).expect("merged");
        assert_eq!(merged.outcomes, (0..5u8).map(Some).collect::<Vec<_>>());
        assert_eq!(merged.wall_s, 2.0);
        let e = |r: Result<Merged<Bytes>>| format!("{:#}", r.err().expect("refused"));
        assert!(e(merge([shard(1, "a")])).contains("shard 2/2 missing"));
        assert!(e(merge([shard(1, "a"), shard(1, "a")])).contains("shard 1/2 given twice"));
        assert!(e(merge([shard(1, "a"), shard(2, "b")])).contains("s2 is a shard of another study"));
    }

    #[test]
    fn a_file_that_is_not_a_shard_is_named() {
        let parse = |text: &str, name| {
            format!(
                "{:#}",
                ShardFile::<Bytes>::parse(text, name)
                    .err()
                    .expect("refused")
            )
        };
        let e = parse("{\"a\": 1}", "x.json");
        assert!(e.contains("x.json is not a test study shard"), "{e}");
        let e = parse("not json", "y.json");
        assert!(e.contains("y.json is not a test study shard"), "{e}");
        let e = parse("{\"format\": \"other shard\"}", "w.json");
        assert!(e.contains("its \"format\" is \"other shard\""), "{e}");
        let e = parse("{\"format\": \"test shard\", \"version\": 99}", "z.json");
        assert!(e.contains("version 99"), "{e}");
        assert!(from_hex("0g").is_err());
        assert!(from_hex("abc").is_err());
        assert!(from_hex("é0").is_err());
        assert_eq!(
            from_hex(&to_hex(&[0, 255, 16])).expect("hex"),
            vec![0, 255, 16]
        );
    }
}
