//! `host-sim arfit FILE --rate HZ`: autocorrelation, AR(p) fits by the
//! three methods in the paper's sign convention (Tables 4-5), order
//! selection help, and the model file the filter loads. The analysis is
//! `host_sim::analysis::ar_analysis`'s, the report
//! `host_sim::analysis::arfit_report`'s; this module reads the options and
//! prints.

use super::output::print_out;
use anyhow::Result;
use host_sim::analysis::ar_analysis::{analyse_columns, model_file, ArOptions};
use host_sim::analysis::arfit::{ArFit, ArMethod};
use host_sim::analysis::arfit_report::report;
use host_sim::analysis::csv_input::read_analysis_input;
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
