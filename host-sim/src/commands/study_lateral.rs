//! `host-sim study lateral`: the command line of
//! [`host_sim::study::lateral`]: grades, wells, drilling parameters, a
//! progress bar over every job, the tables, CSV and JSON.

use super::limits::{azimuth_sigma_deg, number_in};
use super::runs::{progress_bar, stop_on_ctrl_c, SeedsAndThreads};
use anyhow::{Context, Result};
use host_sim::formats::files::{write_json, write_text};
use host_sim::study::drilling_run::Scalar;
use host_sim::study::grade;
use host_sim::study::lateral::covariance::SweepGrid;
use host_sim::study::lateral::figures::plots;
use host_sim::study::lateral::stations::stations_csv;
use host_sim::study::lateral::table::{csv, table};
use host_sim::study::lateral::{study, DrillingOverrides, LateralStudy, StudyConfig, Well};
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
fn rop(text: &str) -> Result<f64, String> {
    number_in(text, "the rate of penetration", (0.1, 500.0), "m/h")
}

fn stand_length(text: &str) -> Result<f64, String> {
    number_in(text, "the stand length", (1.0, 1000.0), "m")
}

fn connection_still(text: &str) -> Result<f64, String> {
    number_in(text, "the still time at connections", (0.0, 86_400.0), "s")
}

#[derive(clap::Args, Debug)]
pub struct LateralArgs {
    /// Gyro grades by name (default: all built-in ones and those of
    /// --grade-file): scc1300, high-end-mems, ge-mwd-2020, navigation.
    #[arg(long, value_delimiter = ',')]
    pub grades: Vec<String>,
    /// A grade file (JSON, host-sim/data/grades/): adds a grade, or
    /// replaces the built-in one of the same name. Repeatable.
    #[arg(long = "grade-file")]
    pub grade_files: Vec<PathBuf>,
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
    /// 1-sigma of the parent well's azimuth at the tie-in, deg.
    #[arg(long = "tie-in-azimuth-sigma", alias = "tie-in-azimuth-sigma-deg", default_value_t = 0.5, value_parser = azimuth_sigma_deg)]
    pub tie_in_azimuth_sigma_deg: f64,
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
}

pub fn run(args: LateralArgs) -> Result<()> {
    let grades = grade::select(&args.grades, &args.grade_files)?;
    let overrides = DrillingOverrides {
        rop_m_per_h: args.rop_m_per_h,
        stand_length_m: args.stand_length_m,
        connection_still_s: args.connection_still_s,
    };
    let wells = wells(&args, &overrides)?;
    let threads = args.seeds.threads();
    let config = StudyConfig {
        grades,
        wells,
        runs: args.runs as usize,
        first_seed: args.seeds.first_seed,
        threads,
        tie_in_azimuth_sigma: args.tie_in_azimuth_sigma_deg.to_radians(),
        monte_carlo: !args.covariance_only,
        sweep: args.sweep.map(|n| SweepGrid::default_grid(n as usize)),
        scalar: args.scalar,
    };
    let pairs = (config.grades.len() * config.wells.len()) as u64;
    let sweep_points = args.sweep.map_or(0, |n| n * n) * config.wells.len() as u64;
    let runs = if args.covariance_only { 0 } else { args.runs };
    let jobs = pairs * (runs + 1) + sweep_points;
    let bar = progress_bar(
        jobs,
        "{bar:40} {pos}/{len} runs (Monte Carlo, covariance analysis, sweep), {elapsed} (eta {eta})",
    )?;
    let stop = stop_on_ctrl_c(Some(&bar))?;
    let result = study(&config, &|| bar.inc(1), &stop)?;
    bar.finish_and_clear();
    let names: Vec<&str> = config.grades.iter().map(|g| g.name()).collect();
    let wells: Vec<&str> = config.wells.iter().map(|w| w.label.as_str()).collect();
    outln!(
        "lateral study: grades {}; wells {}; {} runs each from seed {}; tie-in azimuth sigma {} deg; {} threads; filter {}; {:.1} s",
        names.join(", "),
        wells.join(", "),
        runs,
        args.seeds.first_seed,
        args.tie_in_azimuth_sigma_deg,
        threads,
        args.scalar.name(),
        result.wall_s
    );
    out!("{}", table(&result));
    write_outputs(&args, &result)?;
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

/// The wells: `--plan`s, else the built-in laterals of `--well`.
fn wells(args: &LateralArgs, overrides: &DrillingOverrides) -> Result<Vec<Well>> {
    if args.plans.is_empty() {
        let names: &[&str] = match args.well {
            WellChoice::Short => &["100m"],
            WellChoice::Long => &["1000m"],
            WellChoice::Both => &["100m", "1000m"],
        };
        names
            .iter()
            .map(|n| Well::builtin(n, overrides))
            .collect::<Result<_>>()
    } else {
        args.plans
            .iter()
            .map(|p| Well::load(p, overrides))
            .collect::<Result<_>>()
    }
}

/// `--json`, `--csv`, `--stations-csv` and `--plots` (each file said as
/// written).
fn write_outputs(args: &LateralArgs, result: &LateralStudy) -> Result<()> {
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
