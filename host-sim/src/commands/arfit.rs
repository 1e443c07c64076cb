//! `host-sim arfit FILE --rate HZ`: autocorrelation, AR(p) fits by the
//! three methods in the paper's sign convention (Tables 4-5), order
//! selection help, and the model file the filter loads. The analysis is
//! `host_sim::analysis::ar_analysis`'s; this module reads the options and
//! reports.

use super::output::print_out;
use anyhow::Result;
use host_sim::analysis::ar_analysis::{analyse_columns, model_file, ArOptions, ColumnAr};
use host_sim::analysis::arfit::{ArFit, ArMethod};
use host_sim::analysis::csv_input::read_analysis_input;
use host_sim::analysis::units::Quantity;
use mwd_core::conventions::DEG;
use std::fmt::Write;
use std::path::{Path, PathBuf};

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

pub fn run(args: Args) -> Result<()> {
    let input = read_analysis_input(&args.file, args.rate, args.columns.as_deref(), &args.units)?;
    let options = ArOptions {
        order: args.order,
        method: args.method,
        max_order: args.max_order,
        lags: args.lags,
        demean: !args.no_demean,
    };
    let columns = analyse_columns(&input, &options)?;
    let path = args
        .output
        .clone()
        .unwrap_or_else(|| args.file.with_extension("ar.json"));
    model_file(&columns, args.method, args.rate).save(&path)?;
    if args.json {
        let fits: Vec<(&str, &ArFit)> = columns
            .iter()
            .flat_map(|c| c.fits.iter().map(|f| (c.name.as_str(), f)))
            .collect();
        print_out(&(serde_json::to_string_pretty(&fits)? + "\n"))
    } else {
        print_out(&report(&columns, &options, &path))
    }
}

/// The fits table, each column's autocorrelation and order scores, and
/// where the model file went.
fn report(columns: &[ColumnAr], options: &ArOptions, path: &Path) -> String {
    let mut out = String::new();
    fits_table(&mut out, columns, options.order);
    for column in columns {
        order_table(&mut out, column, options);
    }
    let _ = writeln!(
        out,
        "\nmodel file ({}, order {}) written to {}",
        options.method,
        options.order,
        path.display()
    );
    out
}

/// Every column's fits by every method, like the paper's Tables 4-5.
fn fits_table(out: &mut String, columns: &[ColumnAr], order: usize) {
    let _ = writeln!(
        out,
        "AR({order}) fits, paper convention z_k = -sum a_i z_(k-i) + e_k, beta = var(e)"
    );
    let header: String = (1..=order)
        .map(|i| format!("{:>10}", format!("a{i}")))
        .collect();
    let _ = writeln!(
        out,
        "{:<14} {:<12}{header} {:>13} {:>13}",
        "sensor", "method", "beta (SI)", "beta (report)"
    );
    for column in columns {
        for fit in &column.fits {
            let coeffs: String = fit
                .coefficients
                .iter()
                .map(|a| format!("{a:>10.4}"))
                .collect();
            let (report, report_unit) = match column.unit.quantity() {
                // The paper's Table 5 betas are (deg/s)^2 (project assumption).
                Quantity::AngularRate => (fit.noise_variance * (1.0 / DEG).powi(2), "(deg/s)^2"),
                Quantity::SpecificForce => (fit.noise_variance, "(m/s^2)^2"),
                Quantity::Other => (fit.noise_variance, "u^2"),
            };
            let _ = writeln!(
                out,
                "{:<14} {:<12}{coeffs} {:>13.4e} {:>9.4e} {report_unit}",
                column.name,
                fit.method.to_string(),
                fit.noise_variance,
                report
            );
        }
    }
}

/// One column's autocorrelation and its AIC/BIC by order, best marked.
fn order_table(out: &mut String, column: &ColumnAr, options: &ArOptions) {
    let acf: String = column
        .autocorrelation
        .iter()
        .skip(1)
        .map(|r| format!("{r:>8.3}"))
        .collect();
    let _ = writeln!(
        out,
        "\n{}: autocorrelation at lags 1..{}:{acf}",
        column.name, options.lags
    );
    let _ = writeln!(
        out,
        "{:>4} {:>13} {:>9} {:>15} {:>15}  ({})",
        "p", "sigma^2", "k_p", "AIC", "BIC", options.method
    );
    let (best_aic, best_bic) = (column.best_aic(), column.best_bic());
    for s in &column.scores {
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
