//! `host-sim arfit FILE --rate HZ`: autocorrelation, AR(p) fits by the
//! three methods in the paper's sign convention (Tables 4-5), order
//! selection help, and the model file the filter loads.

use super::print_out;
use anyhow::{Context, Result};
use host_sim::analysis::ar_file::{ArModelEntry, ArModelFile, ArQuantity};
use host_sim::analysis::arfit::{autocorrelation, fit_ar, order_scores, ArFit, ArMethod};
use host_sim::analysis::csv_input::{read_analysis_input, AnalysisInput};
use host_sim::analysis::units::{InputUnit, Quantity};
use mwd_core::conventions::DEG;
use std::fmt::Write;
use std::path::PathBuf;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// Numeric column file (CSV / whitespace), one column per sensor.
    pub file: PathBuf,
    /// Sample rate of the record (Hz).
    #[arg(long)]
    pub rate: f64,
    /// Model order p (the paper uses 4).
    #[arg(long, default_value_t = 4)]
    pub order: usize,
    /// Method whose models go into the model file (the paper's: Yule-Walker).
    #[arg(long, value_enum, default_value = "yule-walker")]
    pub method: ArMethod,
    /// Highest order in the AIC/BIC table.
    #[arg(long, default_value_t = 10)]
    pub max_order: usize,
    /// Autocorrelation lags to print.
    #[arg(long, default_value_t = 8)]
    pub lags: usize,
    /// Unit of the columns: one for all or one per column (rad/s, deg/s,
    /// deg/h, m/s2, g, mg, raw) or `auto` (from name suffixes like `_rad_s`). Variances are written in SI units squared.
    #[arg(long, default_value = "auto")]
    pub units: String,
    /// Only these columns (header names, comma separated); default: all but time.
    #[arg(long)]
    pub columns: Option<String>,
    /// Fit the raw series without removing its mean.
    #[arg(long)]
    pub no_demean: bool,
    /// Model file to write (default: FILE with extension `.ar.json`).
    #[arg(long)]
    pub output: Option<PathBuf>,
    /// Print every fit as JSON instead of tables.
    #[arg(long)]
    pub json: bool,
}

const METHODS: [ArMethod; 3] = [ArMethod::YuleWalker, ArMethod::Burg, ArMethod::Covariance];

fn quantity_of(unit: InputUnit) -> ArQuantity {
    match unit.quantity() {
        Quantity::AngularRate => ArQuantity::AngularRate,
        Quantity::SpecificForce => ArQuantity::SpecificForce,
        Quantity::Other => ArQuantity::Other,
    }
}

pub fn run(args: Args) -> Result<()> {
    let AnalysisInput {
        table,
        selected,
        units,
    } = read_analysis_input(&args.file, args.rate, args.columns.as_deref(), &args.units)?;
    let demean = !args.no_demean;
    let mut out = String::new();
    let mut entries = Vec::new();
    let mut all_fits: Vec<(String, ArFit)> = Vec::new();
    let _ = writeln!(
        out,
        "AR({}) fits, paper convention z_k = -sum a_i z_(k-i) + e_k, beta = var(e)",
        args.order
    );
    let header: String = (1..=args.order)
        .map(|i| format!("{:>10}", format!("a{i}")))
        .collect();
    let _ = writeln!(
        out,
        "{:<14} {:<12}{header} {:>13} {:>13}",
        "sensor", "method", "beta (SI)", "beta (report)"
    );
    for (&col, &unit) in selected.iter().zip(&units) {
        let name = &table.names[col];
        let x: Vec<f64> = table.data[col].iter().map(|v| v * unit.to_si()).collect();
        for method in METHODS {
            let fit =
                fit_ar(&x, args.order, method, demean).with_context(|| format!("column {name}"))?;
            let coeffs: String = fit
                .coefficients
                .iter()
                .map(|a| format!("{a:>10.4}"))
                .collect();
            let (report, report_unit) = match unit.quantity() {
                // The paper's Table 5 betas are (deg/s)^2 (project assumption).
                Quantity::AngularRate => (fit.noise_variance * (1.0 / DEG).powi(2), "(deg/s)^2"),
                Quantity::SpecificForce => (fit.noise_variance, "(m/s^2)^2"),
                Quantity::Other => (fit.noise_variance, "u^2"),
            };
            let _ = writeln!(
                out,
                "{name:<14} {:<12}{coeffs} {:>13.4e} {:>9.4e} {report_unit}",
                method.to_string(),
                fit.noise_variance,
                report
            );
            if method == args.method {
                entries.push(ArModelEntry::from_fit(
                    name,
                    quantity_of(unit),
                    args.rate,
                    &fit,
                ));
            }
            all_fits.push((name.clone(), fit));
        }
    }
    for (&col, &unit) in selected.iter().zip(&units) {
        let name = &table.names[col];
        let x: Vec<f64> = table.data[col].iter().map(|v| v * unit.to_si()).collect();
        let acf = autocorrelation(&x, args.lags);
        let acf: String = acf.iter().skip(1).map(|r| format!("{r:>8.3}")).collect();
        let _ = writeln!(
            out,
            "\n{name}: autocorrelation at lags 1..{}:{acf}",
            args.lags
        );
        let scores = order_scores(&x, args.max_order, args.method, demean)
            .with_context(|| format!("column {name}"))?;
        let best_aic = scores
            .iter()
            .min_by(|a, b| a.aic.total_cmp(&b.aic))
            .map_or(0, |s| s.order);
        let best_bic = scores
            .iter()
            .min_by(|a, b| a.bic.total_cmp(&b.bic))
            .map_or(0, |s| s.order);
        let _ = writeln!(
            out,
            "{:>4} {:>13} {:>9} {:>15} {:>15}  ({})",
            "p", "sigma^2", "k_p", "AIC", "BIC", args.method
        );
        for s in &scores {
            let mark = match (s.order == best_aic, s.order == best_bic) {
                (true, true) => "  <- AIC, BIC",
                (true, false) => "  <- AIC",
                (false, true) => "  <- BIC",
                _ => "",
            };
            let _ = writeln!(
                out,
                "{:>4} {:>13.5e} {:>9.4} {:>15.2} {:>15.2}{mark}",
                s.order, s.noise_variance, s.reflection, s.aic, s.bic
            );
        }
    }
    let path = args
        .output
        .clone()
        .unwrap_or_else(|| args.file.with_extension("ar.json"));
    ArModelFile::new(entries).save(&path)?;
    let _ = writeln!(
        out,
        "\nmodel file ({}, order {}) written to {}",
        args.method,
        args.order,
        path.display()
    );
    if args.json {
        print_out(&(serde_json::to_string_pretty(&all_fits)? + "\n"))
    } else {
        print_out(&out)
    }
}
