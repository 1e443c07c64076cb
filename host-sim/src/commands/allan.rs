//! `host-sim allan FILE --rate HZ [--json]`: overlapping Allan deviation of
//! every column of a static record, with confidence intervals, the fitted
//! noise coefficients and a log-log SVG plot.

use super::print_out;
use anyhow::{bail, Result};
use host_sim::analysis::allan::{allan_deviation, averaging_factors, AllanPoint, TauSet};
use host_sim::analysis::allan_fit::{bias_instability_factor, fit_noise, NoiseCoefficients};
use host_sim::analysis::csv_input::{read_analysis_input, AnalysisInput};
use host_sim::analysis::plot::{loglog_svg, Labels, Series, Style};
use host_sim::analysis::units::{deviation_unit, report_noise, InputUnit, Quantity, Reported};
use indicatif::{ProgressBar, ProgressStyle};
use serde::Serialize;
use std::path::PathBuf;

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

#[derive(Serialize)]
struct SensorReport {
    name: String,
    input_unit: InputUnit,
    /// Unit of `tau` is s; of `oadev`, `adev` and the intervals this one.
    oadev_unit: &'static str,
    samples: usize,
    /// Allan deviations in SI units (rad/s or m/s^2) or the raw unit.
    points: Vec<AllanPoint>,
    /// Noise coefficients in SI units.
    fit: NoiseCoefficients,
    /// The same in report units: random walk, bias instability, rate random walk.
    report: [Reported; 3],
}

#[derive(Serialize)]
struct Report {
    file: String,
    rate_hz: f64,
    bias_instability_factor: f64,
    sensors: Vec<SensorReport>,
}

pub fn run(args: Args) -> Result<()> {
    let AnalysisInput {
        table,
        selected,
        units,
    } = read_analysis_input(&args.file, args.rate, args.columns.as_deref(), &args.units)?;
    let set = if args.all_taus {
        TauSet::All
    } else {
        TauSet::Octave
    };
    let n = table.rows();
    // Every tau costs O(n): all n/2 of them would take hours on a long record.
    const ALL_TAUS_LIMIT: usize = 100_000;
    if args.all_taus && n > ALL_TAUS_LIMIT {
        bail!("--all-taus on {n} samples is O(n^2); use it on at most {ALL_TAUS_LIMIT} samples (octave taus have no limit)");
    }
    if n < 4 {
        bail!(
            "{}: {n} samples are too few for an Allan deviation",
            args.file.display()
        );
    }
    let work = (selected.len() * averaging_factors(n, set).len()) as u64 * n as u64;
    let bar = if work > 5_000_000 {
        ProgressBar::new(work)
    } else {
        ProgressBar::hidden()
    };
    bar.set_style(
        ProgressStyle::with_template("{msg:>8} [{bar:40}] {percent:>3}% {elapsed}/{eta}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let mut sensors = Vec::new();
    for (&col, unit) in selected.iter().zip(&units) {
        bar.set_message(table.names[col].clone());
        let y: Vec<f64> = table.data[col].iter().map(|v| v * unit.to_si()).collect();
        let points = allan_deviation(&y, args.rate, set, |k| bar.inc(k));
        let fit = fit_noise(&points);
        let report = report_noise(
            unit.quantity(),
            fit.random_walk,
            fit.bias_instability,
            fit.rate_random_walk,
        );
        sensors.push(SensorReport {
            name: table.names[col].clone(),
            input_unit: *unit,
            oadev_unit: match unit.quantity() {
                Quantity::AngularRate => "rad/s",
                Quantity::SpecificForce => "m/s^2",
                Quantity::Other => "input unit",
            },
            samples: n,
            points,
            fit,
            report,
        });
    }
    bar.finish_and_clear();
    let units_q: Vec<_> = units.iter().map(|u| u.quantity()).collect();
    if !args.no_plot {
        let path = args
            .plot
            .clone()
            .unwrap_or_else(|| args.file.with_extension("allan.svg"));
        plot(&path, &sensors, &units_q)?;
        eprintln!("plot written to {}", path.display());
    }
    let report = Report {
        file: args.file.display().to_string(),
        rate_hz: args.rate,
        bias_instability_factor: bias_instability_factor(),
        sensors,
    };
    if args.json {
        print_out(&(serde_json::to_string_pretty(&report)? + "\n"))?;
    } else {
        print_out(&tables(&report, &units_q))?;
    }
    Ok(())
}

fn tables(report: &Report, quantities: &[Quantity]) -> String {
    use std::fmt::Write;
    let mut out = String::new();
    for (s, &q) in report.sensors.iter().zip(quantities) {
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

fn plot(path: &std::path::Path, sensors: &[SensorReport], quantities: &[Quantity]) -> Result<()> {
    let mut series = Vec::new();
    for (i, (s, &q)) in sensors.iter().zip(quantities).enumerate() {
        let (_, k) = deviation_unit(q);
        let taus: Vec<f64> = s.points.iter().map(|p| p.tau).collect();
        series.push(Series {
            name: s.name.clone(),
            points: s.points.iter().map(|p| (p.tau, p.oadev * k)).collect(),
            error_bars: s
                .points
                .iter()
                .map(|p| (p.ci_low * k, p.ci_high * k))
                .collect(),
            style: Style::Markers,
            colour: i,
        });
        let names = [
            "quantization",
            "random walk",
            "bias instability",
            "rate random walk",
        ];
        for (term, name) in names.iter().enumerate() {
            let pts: Vec<(f64, f64)> = taus
                .iter()
                .map(|&t| (t, s.fit.terms_at(t)[term] * k))
                .collect();
            if pts.iter().any(|p| p.1 > 0.0) {
                series.push(Series {
                    name: format!("{} fit: {name}", s.name),
                    points: pts,
                    error_bars: vec![],
                    style: Style::Line,
                    colour: i,
                });
            }
        }
    }
    let units: Vec<&str> = quantities.iter().map(|&q| deviation_unit(q).0).collect();
    let y = format!("overlapping Allan deviation ({})", units.join(", "));
    loglog_svg(
        path,
        &Labels {
            title: "Allan deviation",
            x: "tau (s)",
            y: &y,
        },
        &series,
    )
}
