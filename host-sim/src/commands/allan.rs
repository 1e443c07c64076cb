//! `host-sim allan FILE --rate HZ [--json]`: overlapping Allan deviation of
//! every column of a static record, with confidence intervals, the fitted
//! noise coefficients and a log-log SVG plot. The analysis is
//! `host_sim::analysis::allan_analysis`'s, the tables and plot
//! `host_sim::analysis::allan_report`'s; this module reads the options and
//! prints.

use super::output::print_out;
use anyhow::{bail, Result};
use host_sim::analysis::allan::TauSet;
use host_sim::analysis::allan_analysis::{analyse_columns, work, AllanReport};
use host_sim::analysis::allan_report::{plot, tables};
use host_sim::analysis::csv_input::{read_analysis_input, AnalysisInput};
use indicatif::{ProgressBar, ProgressStyle};
use std::path::PathBuf;

/// Longest record `--all-taus` takes: every tau costs O(n), all n/2 of
/// them would take hours on a long record.
const ALL_TAUS_LIMIT: usize = 100_000;
/// Work (sample visits) beyond which a progress bar is worth showing.
const PROGRESS_WORK: u64 = 5_000_000;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// Numeric column file (CSV / whitespace), one column per sensor.
    pub file: PathBuf,
    /// Sample rate of the record (Hz).
    #[arg(long)]
    pub rate: f64,
    /// Unit of the columns: one for all, or one per column, comma separated
    /// (rad/s, deg/s, deg/h, m/s2, g, mg, raw), or `auto`: from
    /// suffixes of the column names such as `_rad_s`, `_m_s2`.
    #[arg(long, default_value = "auto")]
    pub units: String,
    /// Only these columns (header names, comma separated); default: all but time.
    #[arg(long)]
    pub columns: Option<String>,
    /// Every averaging factor m = 1 .. n/2 instead of octaves (O(n^2)).
    #[arg(long)]
    pub all_taus: bool,
    /// Print machine-readable JSON instead of tables.
    #[arg(long)]
    pub json: bool,
    /// Where to write the log-log plot (default: FILE with extension `.allan.svg`).
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// Do not write a plot.
    #[arg(long)]
    pub no_plot: bool,
}

pub fn run(args: Args) -> Result<()> {
    let input = read_analysis_input(&args.file, args.rate, args.columns.as_deref(), &args.units)?;
    let set = tau_set(&args, &input)?;
    let bar = progress_bar(work(&input, set));
    let sensors = analyse_columns(
        &input,
        args.rate,
        set,
        |name| bar.set_message(name.to_string()),
        |k| bar.inc(k),
    )?;
    bar.finish_and_clear();
    if !args.no_plot {
        let path = args
            .plot
            .clone()
            .unwrap_or_else(|| args.file.with_extension("allan.svg"));
        plot(&path, &sensors)?;
        eprintln!("plot written to {}", path.display());
    }
    let report = AllanReport::new(args.file.display().to_string(), args.rate, sensors);
    if args.json {
        print_out(&(serde_json::to_string_pretty(&report)? + "\n"))
    } else {
        print_out(&tables(&report))
    }
}

/// Octave taus, or with `--all-taus` every one (on a record short enough).
fn tau_set(args: &Args, input: &AnalysisInput) -> Result<TauSet> {
    let n = input.table.rows();
    if args.all_taus && n > ALL_TAUS_LIMIT {
        bail!("--all-taus on {n} samples is O(n^2); use it on at most {ALL_TAUS_LIMIT} samples (octave taus have no limit)");
    }
    if n < 4 {
        bail!(
            "{}: {n} samples are too few for an Allan deviation",
            args.file.display()
        );
    }
    Ok(if args.all_taus {
        TauSet::All
    } else {
        TauSet::Octave
    })
}

/// A progress bar for long analyses, a hidden one for short ones.
fn progress_bar(work: u64) -> ProgressBar {
    let bar = if work > PROGRESS_WORK {
        ProgressBar::new(work)
    } else {
        ProgressBar::hidden()
    };
    bar.set_style(
        ProgressStyle::with_template("{msg:>8} [{bar:40}] {percent:>3}% {elapsed}/{eta}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar
}
