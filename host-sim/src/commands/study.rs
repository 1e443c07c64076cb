//! `host-sim study ...`: the studies' subcommands, and `rins-probe`'s
//! command line (`drilling-coverage` in [`super::study_coverage`],
//! `lateral` and `merge` in [`super::study_lateral`], `grade-table` in
//! [`super::study_grade_table`]).

use super::limits::{azimuth_sigma_deg, number_in};
use super::runs::{print_and_write_json, progress_bar, stop_on_ctrl_c, SeedsAndThreads};
use anyhow::Result;
use host_sim::sim::Plan;
use host_sim::study::coverage_shard::COVERAGE_SHARD_FORMAT;
use host_sim::study::lateral::wells::Well;
use host_sim::study::shard::shard_format;
use std::path::PathBuf;

#[derive(clap::Subcommand, Debug)]
pub enum StudyCommand {
    /// Seeded runs of a simulated lateral: do the probe's station sigmas
    /// and the survey's TD ellipse cover the errors?
    DrillingCoverage(CoverageArgs),
    /// A reference heading as the master for the first stations, the gyro
    /// probe as the backup (the redundant rotational INS paper's
    /// master/backup idea): azimuth error at TD with and without it, by gyro
    /// grade (docs/redundant-rins.md).
    RinsProbe(RinsProbeArgs),
    /// Which gyro meets the MGWD paper's requirement (attitude error under
    /// 0.1 deg, position error under 1 m per 1000 m): seeded laterals by
    /// gyro grade, station azimuth and TD position errors against the
    /// predicted sigmas (docs/lateral-study.md).
    // boxed: its options are most of the enum's size
    Lateral(Box<LateralArgs>),
    /// The outputs of a lateral or drilling-coverage study run in shards
    /// (`study lateral` or `study drilling-coverage` with `--shard K/N
    /// --shard-file FILE`, K = 1..N): the same tables and files as the
    /// study in one process (docs/study-scale-out.md).
    Merge(MergeArgs),
    /// README's grade table: the lateral study of every grade on both
    /// built-in wells, its figures per grade and well and whether the
    /// paper's requirement is met, between README.md's grade-table markers
    /// and in docs/results/grade-table.csv (nothing written unless every
    /// run succeeded).
    GradeTable(GradeTableArgs),
    /// Toolface indexing at a connection: the azimuth a still probe
    /// re-finds when its still time is split into dwells with the toolface
    /// turned between them, by gyro grade, against its printed sigma.
    Indexing(IndexingArgs),
}

pub use super::study_coverage::CoverageArgs;
pub use super::study_grade_table::GradeTableArgs;
pub use super::study_indexing::IndexingArgs;
pub use super::study_lateral::{LateralArgs, MergeArgs};

pub fn run(cmd: StudyCommand) -> Result<()> {
    match cmd {
        StudyCommand::DrillingCoverage(args) => super::study_coverage::run(args),
        StudyCommand::RinsProbe(args) => rins_probe(args),
        StudyCommand::Lateral(args) => super::study_lateral::run(*args),
        StudyCommand::Merge(args) => merge(args),
        StudyCommand::GradeTable(args) => super::study_grade_table::run(args),
        StudyCommand::Indexing(args) => super::study_indexing::run(args),
    }
}

/// `study merge`: the study its first shard names (by its "format"), a
/// lateral study's when it names none (whose merge then says why the file
/// is no shard).
fn merge(args: MergeArgs) -> Result<()> {
    if first_shard_format(&args.shards).as_deref() == Some(COVERAGE_SHARD_FORMAT) {
        return super::study_coverage::merge(&args.shards, &args.outputs);
    }
    super::study_lateral::merge(args)
}

/// The first shard's "format" (`None` when it is unreadable or has none).
fn first_shard_format(shards: &[PathBuf]) -> Option<String> {
    let text = std::fs::read_to_string(shards.first()?).ok()?;
    let value: serde_json::Value = serde_json::from_str(&text).ok()?;
    shard_format(&value).map(str::to_string)
}

#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq)]
pub enum GradeName {
    Scc1300,
    Tactical,
    Navigation,
}

fn reference_sigma_deg(text: &str) -> Result<f64, String> {
    number_in(text, "the reference azimuth sigma", (0.001, 30.0), "deg")
}

#[derive(clap::Args, Debug)]
pub struct RinsProbeArgs {
    /// Well plan (JSON, docs/drilling-simulation.md); default: the
    /// built-in 100 m lateral (host-sim/data/plans/lateral-100m.json).
    #[arg(long)]
    pub plan: Option<PathBuf>,
    /// Runs per grade (seeds first-seed, first-seed + 1, ...).
    #[arg(long, default_value_t = 50, value_parser = clap::value_parser!(u64).range(1..=100_000))]
    pub runs: u64,
    #[command(flatten)]
    pub seeds: SeedsAndThreads,
    /// Gyro grades (the SCC1300's gyro errors divided by 1, 10, 1000);
    /// default all three.
    #[arg(long, value_enum, value_delimiter = ',')]
    pub grades: Vec<GradeName>,
    /// Stations (the window's first) with a reference azimuth, then lost.
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u64).range(0..=1000))]
    pub reference_stations: u64,
    /// 1-sigma of each reference azimuth, deg.
    #[arg(long, default_value_t = 0.5, value_parser = reference_sigma_deg)]
    pub reference_sigma_deg: f64,
    /// 1-sigma of the parent well's azimuth at the tie-in, deg.
    #[arg(long, default_value_t = 0.5, value_parser = azimuth_sigma_deg)]
    pub tie_in_azimuth_sigma_deg: f64,
    /// Keep the SCC1300's white gyro noise (scale the bias and coloured
    /// noise only): it dithers the raw frame's gyro count, which a quieter
    /// gyro at rest does not (a diagnostic, docs/redundant-rins.md).
    #[arg(long)]
    pub white_noise_kept: bool,
    /// Write the summaries here (JSON).
    #[arg(long)]
    pub json: Option<PathBuf>,
}

fn rins_probe(args: RinsProbeArgs) -> Result<()> {
    use host_sim::study::rins_probe::table;
    let plan = study_plan(args.plan.as_deref())?;
    let threads = args.seeds.threads();
    let mut summaries = Vec::new();
    // One bar per grade: the note goes to standard error.
    let stop = stop_on_ctrl_c(None)?;
    for name in grade_names(&args) {
        summaries.push(rins_probe_grade(&args, &plan, name, &stop)?);
    }
    outln!(
        "rins-probe: {} ({} runs per grade from seed {}; reference sigma {} deg at the first {} stations, then lost; tie-in azimuth sigma {} deg; {} threads{})",
        plan_name(args.plan.as_deref()),
        args.runs,
        args.seeds.first_seed,
        args.reference_sigma_deg,
        args.reference_stations,
        args.tie_in_azimuth_sigma_deg,
        threads,
        if args.white_noise_kept {
            "; SCC1300 white gyro noise kept"
        } else {
            ""
        }
    );
    print_and_write_json(&table(&summaries), args.json.as_deref(), &summaries)?;
    if stop.load(std::sync::atomic::Ordering::Relaxed) {
        anyhow::bail!("interrupted: the outputs above hold the runs done");
    }
    Ok(())
}

/// `--grades`, by default all three.
fn grade_names(args: &RinsProbeArgs) -> Vec<GradeName> {
    if args.grades.is_empty() {
        vec![
            GradeName::Scc1300,
            GradeName::Tactical,
            GradeName::Navigation,
        ]
    } else {
        args.grades.clone()
    }
}

/// The rins-probe study of one grade, with its progress bar.
fn rins_probe_grade(
    args: &RinsProbeArgs,
    plan: &host_sim::sim::BuiltPlan,
    name: GradeName,
    stop: &std::sync::atomic::AtomicBool,
) -> Result<host_sim::study::rins_probe::GradeSummary> {
    use host_sim::study::rins_probe::{study, ProbeConfig, GRADES};
    let grade = GRADES[match name {
        GradeName::Scc1300 => 0,
        GradeName::Tactical => 1,
        GradeName::Navigation => 2,
    }];
    let config = ProbeConfig {
        plan: plan.clone(),
        tie_in_azimuth_sigma: args.tie_in_azimuth_sigma_deg.to_radians(),
        reference_sigma: args.reference_sigma_deg.to_radians(),
        reference_stations: args.reference_stations as usize,
        grade,
        white_noise_kept: args.white_noise_kept,
    };
    let bar = progress_bar(
        args.runs,
        "{msg} {bar:40} {pos}/{len} runs, {elapsed} (eta {eta})",
    )?;
    bar.set_message(grade.name);
    let summary = study(&config, &args.seeds.runs(args.runs, &|| bar.inc(1), stop));
    bar.finish_and_clear();
    Ok(summary)
}

/// `--plan`'s plan, or the built-in 100 m lateral (the binary carries it,
/// so a study runs from any directory).
fn study_plan(path: Option<&std::path::Path>) -> Result<host_sim::sim::BuiltPlan> {
    match path {
        Some(path) => Plan::load(path),
        None => Ok(Well::builtin("100m", &Default::default())?.plan),
    }
}

/// How the header names the plan.
fn plan_name(path: Option<&std::path::Path>) -> String {
    path.map_or_else(
        || "the built-in 100 m lateral".to_string(),
        |p| p.display().to_string(),
    )
}
