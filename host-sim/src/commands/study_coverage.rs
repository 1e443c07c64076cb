//! `host-sim study drilling-coverage`: the coverage study of the probe's
//! station sigmas over seeded simulated laterals (docs/drilling-survey.md),
//! in one process or in shards (`--shard K/N`, merged by `study merge`,
//! docs/study-scale-out.md). All three make the runs' configuration from
//! the same [`CoverageSpec`], so a merge reports what one process does.

use super::limits::azimuth_sigma_deg;
use super::runs::{print_and_write_json, progress_bar, stop_on_ctrl_c, SeedsAndThreads};
use super::simulate::VibrationLevel;
use super::study_lateral::StudyOutputs;
use anyhow::{bail, Context, Result};
use clap::ValueEnum;
use host_sim::formats::files::write_json;
use host_sim::formats::text_records::read_small_file;
use host_sim::study::coverage_shard::{run_shard, CoverageShardFile, CoverageSpec};
use host_sim::study::drilling_coverage::{study, table, Summary};
use host_sim::study::drilling_run::Scalar;
use host_sim::study::lateral::BUILTIN_WELLS;
use host_sim::study::shard::{exact_text, merge as merge_shards, ShardIndex, SourceText};
use std::path::{Path, PathBuf};

/// How the header names the built-in plan.
const BUILTIN_PLAN: &str = "the built-in 100 m lateral";

#[derive(clap::Args, Debug)]
pub struct CoverageArgs {
    /// Well plan (JSON, docs/drilling-simulation.md); default: the
    /// built-in 100 m lateral (host-sim/data/plans/lateral-100m.json).
    #[arg(long)]
    pub plan: Option<PathBuf>,
    /// Number of runs (seeds first-seed, first-seed + 1, ...).
    #[arg(long, default_value_t = 200, value_parser = clap::value_parser!(u64).range(1..=100_000))]
    pub runs: u64,
    #[command(flatten)]
    pub seeds: SeedsAndThreads,
    /// 1-sigma of the parent well's azimuth at the tie-in, deg.
    #[arg(long, default_value_t = 0.5, value_parser = azimuth_sigma_deg)]
    pub tie_in_azimuth_sigma_deg: f64,
    /// Vibration level instead of the plan's.
    #[arg(long, value_enum)]
    pub vibration: Option<VibrationLevel>,
    /// Run the probe without the calibration of the simulated parts'
    /// deterministic errors (as `simulate`'s captures and the QEMU probe).
    #[arg(long)]
    pub uncalibrated: bool,
    /// The navigator filter's scalar: f32 computes as the probe does (this
    /// study stands for it); f64 is faster on x86 hosts.
    #[arg(long, value_enum, default_value = "f32")]
    pub scalar: Scalar,
    /// Write the summary here (JSON).
    #[arg(long, conflicts_with = "shard")]
    pub json: Option<PathBuf>,
    /// Run only the K-th of N slices of the study's seeds (K from 1) and
    /// write them to --shard-file; `host-sim study merge` makes the
    /// outputs from all N (docs/study-scale-out.md).
    #[arg(long, value_name = "K/N", value_parser = ShardIndex::parse, requires = "shard_file")]
    pub shard: Option<ShardIndex>,
    /// The shard's file (JSON), with --shard.
    #[arg(long, value_name = "FILE", requires = "shard")]
    pub shard_file: Option<PathBuf>,
}

const PROGRESS: &str = "{bar:40} {pos}/{len} runs, {elapsed} (eta {eta})";

pub fn run(args: CoverageArgs) -> Result<()> {
    let spec = spec(&args)?;
    let config = spec.config(vibration(&spec)?)?;
    let threads = args.seeds.threads();
    if let Some(shard) = args.shard {
        let path = args
            .shard_file
            .as_deref()
            .context("--shard needs --shard-file")?;
        let mine = shard.jobs(spec.runs).len();
        let bar = progress_bar(mine as u64, PROGRESS)?;
        let stop = stop_on_ctrl_c(Some(&bar))?;
        let started = std::time::Instant::now();
        let outcomes = run_shard(
            &config,
            &args.seeds.runs(args.runs, &|| bar.inc(1), &stop),
            shard,
        );
        bar.finish_and_clear();
        let wall_s = started.elapsed().as_secs_f64();
        let Some(file) = CoverageShardFile::new(&spec, shard, &outcomes, threads, wall_s) else {
            bail!("interrupted: shard {shard} not written");
        };
        write_json(path, &file)?;
        outln!(
            "drilling coverage shard {shard}: {mine} of the study's {} runs, {threads} threads, {wall_s:.1} s; wrote {}",
            spec.runs,
            path.display()
        );
        return Ok(());
    }
    let bar = progress_bar(args.runs, PROGRESS)?;
    let stop = stop_on_ctrl_c(Some(&bar))?;
    let summary = study(&config, &args.seeds.runs(args.runs, &|| bar.inc(1), &stop));
    bar.finish_and_clear();
    report(&spec, threads, &summary, args.json.as_deref())
}

/// `study merge` of drilling-coverage shards: the table and `--json` as
/// one process writes them (the lateral study's other outputs refused).
pub fn merge(shards: &[PathBuf], outputs: &StudyOutputs) -> Result<()> {
    for (flag, given) in [
        ("--csv", outputs.csv.is_some()),
        ("--stations-csv", outputs.stations_csv.is_some()),
        ("--plots", outputs.plots.is_some()),
    ] {
        if given {
            bail!("{flag}: a drilling-coverage study writes its table and --json only");
        }
    }
    let files = shards.iter().map(|path| {
        let name = path.display().to_string();
        let text =
            std::fs::read_to_string(path).with_context(|| format!("reading the shard {name}"))?;
        Ok((name.clone(), CoverageShardFile::parse(&text, &name)?))
    });
    let merged = merge_shards(files)?;
    let (spec, threads) = (merged.spec.clone(), merged.threads);
    // the configuration checked as the shards' command line checked it
    spec.config(vibration(&spec)?)?;
    let summary = merged.summary()?;
    report(&spec, threads, &summary, outputs.json.as_deref())
}

/// The study's header, table and JSON; an error when it was interrupted.
fn report(
    spec: &CoverageSpec,
    threads: usize,
    summary: &Summary,
    json: Option<&Path>,
) -> Result<()> {
    outln!(
        "drilling coverage: {} ({} runs from seed {}, tie-in azimuth sigma {} deg, {} threads, filter {}{})",
        spec.plan.name,
        spec.runs,
        spec.first_seed,
        spec.tie_in_azimuth_sigma_deg()?,
        threads,
        spec.scalar.name(),
        if spec.uncalibrated {
            ", uncalibrated"
        } else {
            ""
        }
    );
    print_and_write_json(&table(summary), json, summary)?;
    if let Some(i) = summary.interrupted {
        bail!(
            "interrupted after {} of {} runs: the outputs above hold the runs done",
            i.jobs_done,
            i.jobs
        );
    }
    Ok(())
}

/// The study's inputs whole: the plan's text (checked as it is read),
/// numbers as given.
fn spec(args: &CoverageArgs) -> Result<CoverageSpec> {
    let plan = match &args.plan {
        Some(path) => SourceText {
            name: path.display().to_string(),
            text: read_small_file(path)
                .with_context(|| format!("reading the plan {}", path.display()))?,
        },
        None => SourceText {
            name: BUILTIN_PLAN.into(),
            text: BUILTIN_WELLS
                .iter()
                .find(|(n, _)| *n == "100m")
                .context("no built-in 100 m lateral")?
                .1
                .into(),
        },
    };
    let vibration = args
        .vibration
        .and_then(|v| v.to_possible_value())
        .map(|v| v.get_name().to_string());
    Ok(CoverageSpec {
        plan,
        runs: args.runs as usize,
        first_seed: args.seeds.first_seed,
        tie_in_azimuth_sigma_deg: exact_text(args.tie_in_azimuth_sigma_deg),
        vibration,
        uncalibrated: args.uncalibrated,
        scalar: args.scalar,
    })
}

/// The vibration the spec names, as `--vibration` reads it.
fn vibration(spec: &CoverageSpec) -> Result<Option<host_sim::sim::plan::Vibration>> {
    spec.vibration
        .as_deref()
        .map(|name| {
            VibrationLevel::from_str(name, false)
                .map(VibrationLevel::vibration)
                .map_err(|_| {
                    anyhow::anyhow!(
                        "the vibration level {name:?} is not one of none, moderate, harsh"
                    )
                })
        })
        .transpose()
}
