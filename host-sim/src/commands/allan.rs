//! `host-sim allan FILE --rate HZ [--json]`: overlapping Allan deviation of
//! every column of a static record, with confidence intervals, the fitted
//! noise coefficients and a log-log SVG plot. The analysis is
//! `host_sim::analysis::allan_analysis`'s; this module reads the options
//! and reports.

use super::output::print_out;
use anyhow::{bail, Result};
use host_sim::analysis::allan::TauSet;
use host_sim::analysis::allan_analysis::{analyse_columns, work, AllanReport, SensorAllan};
use host_sim::analysis::allan_fit::bias_instability_factor;
use host_sim::analysis::csv_input::{read_analysis_input, AnalysisInput};
use host_sim::analysis::plot::{loglog_svg, Labels, Series, Style};
use host_sim::analysis::units::{deviation_unit, Quantity};
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

fn tables(report: &AllanReport) -> String {
    use std::fmt::Write;
    let mut out = String::new();
    for s in &report.sensors {
        let q = s.quantity();
        let (unit, k) = deviation_unit(q);
        let _ = writeln!(
            out,
            "{}: {} samples at {} Hz, deviations in {unit}",
            s.name, s.samples, report.rate_hz
        );
        let _ = writeln!(
            out,
            "{:>12} {:>12} {:>12} {:>12} {:>12} {:>9} {:>6}",
            "tau (s)", "OADEV", "ADEV", "-1 sigma", "+1 sigma", "edf", "alpha"
        );
        for p in &s.points {
            let adev = p.adev.map_or("-".to_string(), |a| format!("{:.5e}", a * k));
            let _ = writeln!(
                out,
                "{:>12.4} {:>12.5e} {:>12} {:>12.5e} {:>12.5e} {:>9.1} {:>6}",
                p.tau,
                p.oadev * k,
                adev,
                p.ci_low * k,
                p.ci_high * k,
                p.edf,
                p.alpha
            );
        }
        let [rw, bi, rrw] = &s.report;
        let _ = writeln!(
            out,
            "  random walk {:.4e} {}, bias instability {:.4e} {} (floor = {:.3} B), rate random walk {:.4e} {}",
            rw.value, rw.unit, bi.value, bi.unit, bias_instability_factor(), rrw.value, rrw.unit
        );
        if q == Quantity::AngularRate {
            // The paper's Table 2 quotes the gyro ARW as a noise density.
            let density = s.fit.random_walk.to_degrees();
            let _ = writeln!(
                out,
                "  (random walk as a density: {density:.6e} deg/s/sqrt(Hz))"
            );
        }
        let _ = writeln!(out);
    }
    out
}

/// The log-log plot: each sensor's deviations with their intervals, and
/// the fitted noise terms in its colour.
fn plot(path: &std::path::Path, sensors: &[SensorAllan]) -> Result<()> {
    let mut series = Vec::new();
    for (colour, s) in sensors.iter().enumerate() {
        let (_, k) = deviation_unit(s.quantity());
        series.push(Series {
            name: s.name.clone(),
            points: s.points.iter().map(|p| (p.tau, p.oadev * k)).collect(),
            error_bars: s
                .points
                .iter()
                .map(|p| (p.ci_low * k, p.ci_high * k))
                .collect(),
            style: Style::Markers,
            colour,
        });
        series.extend(fit_terms(s, k, colour));
    }
    let units: Vec<&str> = sensors
        .iter()
        .map(|s| deviation_unit(s.quantity()).0)
        .collect();
    let y = format!("overlapping Allan deviation ({})", units.join(", "));
    let labels = Labels {
        title: "Allan deviation",
        x: "tau (s)",
        y: &y,
    };
    loglog_svg(path, &labels, &series)
}

/// The noise terms of a sensor's fit at its taus, scaled by `k`; terms
/// that are zero throughout are left out.
fn fit_terms(s: &SensorAllan, k: f64, colour: usize) -> Vec<Series> {
    let names = [
        "quantization",
        "random walk",
        "bias instability",
        "rate random walk",
    ];
    let mut series = Vec::new();
    for (term, name) in names.iter().enumerate() {
        let points: Vec<(f64, f64)> = s
            .points
            .iter()
            .map(|p| (p.tau, s.fit.terms_at(p.tau)[term] * k))
            .collect();
        if points.iter().any(|p| p.1 > 0.0) {
            series.push(Series {
                name: format!("{} fit: {name}", s.name),
                points,
                error_bars: vec![],
                style: Style::Line,
                colour,
            });
        }
    }
    series
}
