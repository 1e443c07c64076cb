//! `host-sim study lateral`: the command line of
//! [`host_sim::study::lateral`]: grades, wells, drilling parameters, a
//! progress bar over every job, the tables, CSV and JSON.

use super::limits::{azimuth_sigma_deg, number_in};
use super::runs::{progress_bar, stop_on_ctrl_c, GradeChoice, SeedsAndThreads};
use anyhow::{Context, Result};
use host_sim::formats::files::{write_json, write_text};
use host_sim::formats::text_records::read_small_file;
use host_sim::sim::plan::MAX_CONNECTION_DWELLS;
use host_sim::study::drilling_run::Scalar;
use host_sim::study::grade::{self, Grade};
use host_sim::study::lateral::figures::plots;
use host_sim::study::lateral::run::StudyJobs;
use host_sim::study::lateral::shard::{
    self, exact_number, exact_text, ShardFile, ShardIndex, SourceText, StudySpec,
};
use host_sim::study::lateral::stations::stations_csv;
use host_sim::study::lateral::table::{csv, table};
use host_sim::study::lateral::{
    study, DrillingOverrides, LateralStudy, StudyConfig, Well, BUILTIN_WELLS,
};
use std::path::PathBuf;

#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq)]
pub enum WellChoice {
    #[value(name = "100m")]
    Short,
    #[value(name = "1000m")]
    Long,
    Both,
}

/// The plan's own ranges (`sim::plan::DrillingParams`), checked here too
/// so a bad number is refused before any work.
pub(super) fn rop(text: &str) -> Result<f64, String> {
    number_in(text, "the rate of penetration", (0.1, 500.0), "m/h")
}

fn stand_length(text: &str) -> Result<f64, String> {
    number_in(text, "the stand length", (1.0, 1000.0), "m")
}

pub(super) fn connection_still(text: &str) -> Result<f64, String> {
    number_in(text, "the still time at connections", (0.0, 86_400.0), "s")
}

/// The tortuosity's ranges (`sim::plan::Tortuosity`), shared with `drill`.
pub fn tortuosity(text: &str) -> Result<f64, String> {
    number_in(text, "the tortuosity", (0.0, 10.0), "deg/30 m")
}

pub fn tortuosity_length(text: &str) -> Result<f64, String> {
    number_in(
        text,
        "the tortuosity's correlation length",
        (1.0, 1000.0),
        "m",
    )
}

#[derive(clap::Args, Debug)]
pub struct LateralArgs {
    #[command(flatten)]
    pub grade_choice: GradeChoice,
    /// The built-in laterals (ignored when --plan is given).
    #[arg(long, value_enum, default_value = "both")]
    pub well: WellChoice,
    /// A well plan instead (JSON, docs/drilling-simulation.md). Repeatable.
    #[arg(long = "plan")]
    pub plans: Vec<PathBuf>,
    /// Runs per grade and well (seeds first-seed, first-seed + 1, ...).
    #[arg(long, default_value_t = 200, value_parser = clap::value_parser!(u64).range(1..=100_000))]
    pub runs: u64,
    #[command(flatten)]
    pub seeds: SeedsAndThreads,
    /// Rate of penetration, m/h (default: the plan's).
    #[arg(long = "rop", value_parser = rop)]
    pub rop_m_per_h: Option<f64>,
    /// MD between connections, m (default: the plan's).
    #[arg(long = "stand-length", value_parser = stand_length)]
    pub stand_length_m: Option<f64>,
    /// Still time at each connection, s (default: the plan's).
    #[arg(long = "connection-still", value_parser = connection_still)]
    pub connection_still_s: Option<f64>,
    /// Split each connection's still time into N equal dwells, the
    /// orienter indexing the toolface 360/N deg between them (2: 180 deg,
    /// 4: 90 deg; default: the plan's, else 1; docs/toolface-indexing.md).
    #[arg(long = "dwells", value_name = "N",
          value_parser = clap::value_parser!(u32).range(1..=i64::from(MAX_CONNECTION_DWELLS)))]
    pub connection_dwells: Option<u32>,
    /// The hole's tortuosity: RMS of each component (build, walk) of its
    /// curvature's deviation from the plan, deg/30 m; 0 drills the plan
    /// exactly (default: the plan's, else 1 deg/100 ft;
    /// docs/drilling-simulation.md).
    #[arg(long = "tortuosity", value_name = "DEG_PER_30M", value_parser = tortuosity)]
    pub tortuosity_deg_per_30m: Option<f64>,
    /// The tortuosity's correlation length along MD, m (default: the
    /// plan's, else 10 m).
    #[arg(long = "tortuosity-length", value_name = "M", value_parser = tortuosity_length)]
    pub tortuosity_length_m: Option<f64>,
    /// 1-sigma of the parent well's azimuth at the tie-in, deg.
    #[arg(long = "tie-in-azimuth-sigma", alias = "tie-in-azimuth-sigma-deg", default_value_t = 0.5, value_parser = azimuth_sigma_deg)]
    pub tie_in_azimuth_sigma_deg: f64,
    #[command(flatten)]
    pub outputs: StudyOutputs,
    /// Covariance analysis only (one error-free run per grade and well,
    /// seconds to a minute), no Monte Carlo.
    #[arg(long)]
    pub covariance_only: bool,
    /// Also sweep the first grade's gyro bias instability (0.001-10 deg/h)
    /// and ARW (0.001-3 deg/sqrt(h)) by covariance analysis, this many
    /// log-spaced values of each.
    #[arg(long, value_parser = clap::value_parser!(u64).range(2..=20))]
    pub sweep: Option<u64>,
    /// The navigator filter's scalar: f64 gives the probe's f32 figures
    /// (docs/lateral-study.md), faster on x86 hosts.
    #[arg(long, value_enum, default_value = "f64")]
    pub scalar: Scalar,
    /// Run only the K-th of N slices of the study's jobs (K from 1) and
    /// write them to --shard-file; `host-sim study merge` makes the
    /// outputs from all N (docs/study-scale-out.md).
    #[arg(long, value_name = "K/N", value_parser = ShardIndex::parse, requires = "shard_file",
          conflicts_with_all = ["json", "csv", "stations_csv", "plots"])]
    pub shard: Option<ShardIndex>,
    /// The shard's file (JSON), with --shard.
    #[arg(long, value_name = "FILE", requires = "shard")]
    pub shard_file: Option<PathBuf>,
}

/// What a lateral study writes (`study lateral` and `study merge`).
#[derive(clap::Args, Debug)]
pub struct StudyOutputs {
    /// Write the results here (JSON: summaries and the along-MD arrays).
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Write one row per grade and well here (CSV).
    #[arg(long)]
    pub csv: Option<PathBuf>,
    /// Write every run's stations here, one row each (CSV: signed
    /// azimuth and inclination errors with their sigmas, at the station's
    /// start and end).
    #[arg(long, value_name = "CSV")]
    pub stations_csv: Option<PathBuf>,
    /// Directory for the plots (SVG and PNG): error growth along MD per
    /// grade against the predicted sigmas, and the sweep's contour map.
    #[arg(long)]
    pub plots: Option<PathBuf>,
}

pub fn run(args: LateralArgs) -> Result<()> {
    let spec = spec(&args)?;
    let threads = args.seeds.threads();
    let config = spec.config(threads)?;
    if let Some(shard) = args.shard {
        return run_shard(&args, &spec, &config, shard);
    }
    let pairs = (config.grades.len() * config.wells.len()) as u64;
    let sweep_points = args.sweep.map_or(0, |n| n * n) * config.wells.len() as u64;
    let runs = if args.covariance_only { 0 } else { args.runs };
    let jobs = pairs * (runs + 1) + sweep_points;
    let bar = progress_bar(jobs, PROGRESS)?;
    let stop = stop_on_ctrl_c(Some(&bar))?;
    let result = study(&config, &|| bar.inc(1), &stop)?;
    bar.finish_and_clear();
    report(&result, args.tie_in_azimuth_sigma_deg, &args.outputs)
}

const PROGRESS: &str =
    "{bar:40} {pos}/{len} runs (Monte Carlo, covariance analysis, sweep), {elapsed} (eta {eta})";

/// The study's first line and tables on standard output, its files, its
/// errors; an error when it was interrupted.
pub fn report(result: &LateralStudy, tie_in_sigma_deg: f64, outputs: &StudyOutputs) -> Result<()> {
    let names: Vec<&str> = result.grades.iter().map(|g| g.file.name.as_str()).collect();
    let wells: Vec<String> = result
        .wells
        .iter()
        .map(|w| match w.connection_dwells {
            1 => w.label.clone(),
            n => format!("{} (connections indexed: {n} dwells)", w.label),
        })
        .collect();
    outln!(
        "lateral study: grades {}; wells {}; {} runs each from seed {}; tie-in azimuth sigma {} deg; {} threads; filter {}; {:.1} s",
        names.join(", "),
        wells.join(", "),
        result.runs_per_grade_and_well,
        result.first_seed,
        tie_in_sigma_deg,
        result.threads,
        result.filter_scalar.name(),
        result.wall_s
    );
    out!("{}", table(result));
    write_outputs(outputs, result)?;
    for e in &result.errors {
        eprintln!("error: {e}");
    }
    if let Some(i) = result.interrupted {
        anyhow::bail!(
            "interrupted after {} of {} jobs: the outputs above hold the runs done",
            i.jobs_done,
            i.jobs
        );
    }
    Ok(())
}

/// `--shard K/N`: the K-th slice of the jobs into `--shard-file`, whole
/// or not at all (an interrupted shard writes nothing).
fn run_shard(
    args: &LateralArgs,
    spec: &StudySpec,
    config: &StudyConfig,
    shard: ShardIndex,
) -> Result<()> {
    let path = args
        .shard_file
        .as_deref()
        .context("--shard needs --shard-file")?;
    let started = std::time::Instant::now();
    let jobs = StudyJobs::new(config)?;
    let mine = shard.jobs(jobs.len());
    let bar = progress_bar(mine.len() as u64, PROGRESS)?;
    let stop = stop_on_ctrl_c(Some(&bar))?;
    let outcomes = jobs.run(&mine, &|| bar.inc(1), &stop);
    bar.finish_and_clear();
    let wall_s = started.elapsed().as_secs_f64();
    let Some(file) = ShardFile::new(spec, shard, &outcomes, config.threads, wall_s) else {
        anyhow::bail!("interrupted: shard {shard} not written");
    };
    write_json(path, &file)?;
    let runs = mine.iter().filter(|&&j| jobs.is_monte_carlo(j)).count();
    outln!(
        "lateral study shard {shard}: {} of the study's {} jobs ({runs} Monte Carlo runs), {} threads, {wall_s:.1} s; wrote {}",
        mine.len(),
        jobs.len(),
        config.threads,
        path.display()
    );
    Ok(())
}

#[derive(clap::Args, Debug)]
pub struct MergeArgs {
    /// The shard files, every one of the study (any order): a lateral
    /// study's, or a drilling-coverage study's (which writes its table and
    /// --json only).
    #[arg(required = true, value_name = "SHARD")]
    pub shards: Vec<PathBuf>,
    #[command(flatten)]
    pub outputs: StudyOutputs,
}

/// `study merge` of lateral study shards: the shards checked to make one
/// study, whose outputs are then written as `study lateral` writes them.
pub fn merge(args: MergeArgs) -> Result<()> {
    let shards = args.shards.iter().map(|path| {
        let name = path.display().to_string();
        let text =
            std::fs::read_to_string(path).with_context(|| format!("reading the shard {name}"))?;
        let shard = ShardFile::parse(&text, &name)?;
        Ok((name, shard))
    });
    let merged = shard::merge(shards)?;
    let tie_in_sigma_deg = exact_number(
        &merged.spec.tie_in_azimuth_sigma_deg,
        "the tie-in azimuth sigma",
    )?;
    let result = merged.study()?;
    report(&result, tie_in_sigma_deg, &args.outputs)
}

/// The study's inputs whole: grade files and plans read (each checked
/// as it is read, in the command line's order), numbers as given.
fn spec(args: &LateralArgs) -> Result<StudySpec> {
    let mut grade_files = Vec::new();
    let mut from_files = Vec::new();
    for path in &args.grade_choice.grade_files {
        let text = read_small_file(path)
            .with_context(|| format!("reading the grade file {}", path.display()))?;
        let name = path.display().to_string();
        from_files.push(Grade::parse(&text, &name)?);
        grade_files.push(SourceText { name, text });
    }
    grade::select_parsed(&args.grade_choice.grades, from_files)?;
    let overrides = DrillingOverrides {
        rop_m_per_h: args.rop_m_per_h,
        stand_length_m: args.stand_length_m,
        connection_still_s: args.connection_still_s,
        connection_dwells: args.connection_dwells,
        tortuosity_deg_per_30m: args.tortuosity_deg_per_30m,
        tortuosity_length_m: args.tortuosity_length_m,
    };
    let text = |v: Option<f64>| v.map(exact_text);
    Ok(StudySpec {
        grades: args.grade_choice.grades.clone(),
        grade_files,
        wells: wells(args, &overrides)?,
        rop_m_per_h: text(args.rop_m_per_h),
        stand_length_m: text(args.stand_length_m),
        connection_still_s: text(args.connection_still_s),
        connection_dwells: args.connection_dwells,
        tortuosity_deg_per_30m: text(args.tortuosity_deg_per_30m),
        tortuosity_length_m: text(args.tortuosity_length_m),
        tie_in_azimuth_sigma_deg: exact_text(args.tie_in_azimuth_sigma_deg),
        runs: args.runs as usize,
        first_seed: args.seeds.first_seed,
        monte_carlo: !args.covariance_only,
        sweep: args.sweep,
        scalar: args.scalar,
    })
}

/// The wells' plans: `--plan`s, else the built-in laterals of `--well`;
/// each checked with `overrides` as it is read.
fn wells(args: &LateralArgs, overrides: &DrillingOverrides) -> Result<Vec<SourceText>> {
    let source = |name: String, text: String| -> Result<SourceText> {
        Well::parse(&name, &text, overrides)?;
        Ok(SourceText { name, text })
    };
    if !args.plans.is_empty() {
        return args
            .plans
            .iter()
            .map(|path| {
                let text = read_small_file(path)
                    .with_context(|| format!("reading the plan {}", path.display()))?;
                source(path.display().to_string(), text)
            })
            .collect();
    }
    let names: &[&str] = match args.well {
        WellChoice::Short => &["100m"],
        WellChoice::Long => &["1000m"],
        WellChoice::Both => &["100m", "1000m"],
    };
    names
        .iter()
        .map(|name| {
            let (label, text) = BUILTIN_WELLS
                .iter()
                .find(|(n, _)| n == name)
                .with_context(|| format!("no built-in well {name:?}"))?;
            source(label.to_string(), text.to_string())
        })
        .collect()
}

/// `--json`, `--csv`, `--stations-csv` and `--plots` (each file said as
/// written).
fn write_outputs(args: &StudyOutputs, result: &LateralStudy) -> Result<()> {
    if let Some(path) = &args.json {
        write_json(path, result)?;
    }
    if let Some(path) = &args.csv {
        write_text(path, &csv(result))?;
    }
    if let Some(path) = &args.stations_csv {
        let tables = result
            .summaries
            .iter()
            .map(|s| (s.grade.as_str(), s.well.as_str(), s.station_rows.as_slice()));
        write_text(path, &stations_csv(tables))?;
    }
    if let Some(dir) = &args.plots {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        for path in plots(result, dir)? {
            outln!("wrote {}", path.display());
        }
    }
    Ok(())
}
