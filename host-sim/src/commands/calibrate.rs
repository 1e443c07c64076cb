//! `host-sim calibrate FILE`: six-position calibration of accelerometer
//! triads (LS and TLS side by side) and gyro biases with earth rate
//! accounted for, like the paper's Table 3; writes a calibration file.
//! The calibration is `host_sim::analysis::six_position`'s, the report
//! `host_sim::analysis::calibration_report`'s; this module reads the
//! options and prints.

use super::output::print_out;
use anyhow::{ensure, Context, Result};
use clap::builder::{PossibleValuesParser, TypedValueParser};
use host_sim::analysis::calibration_report::report;
use host_sim::analysis::csv_input::read_columns;
use host_sim::analysis::six_position::{
    fit, position_data, GyroColumn, PositionData, TriadColumns,
};
use host_sim::analysis::tls::FitMethod;
use host_sim::analysis::units::InputUnit;
use std::path::PathBuf;

use super::site::SiteArgs;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// CSV with a header: a `position` column (1 = +x up, 2 = x down,
    /// 3 = +y up, 4 = y down, 5 = +z up, 6 = z down) and the sensor columns.
    pub file: PathBuf,
    /// An accelerometer triad: its x,y,z column names (repeat for more
    /// triads); default: the simulator's.
    #[arg(long, default_values = ["accel_x_m_s2,accel_y_m_s2,accel_z_m_s2"])]
    pub accel: Vec<String>,
    /// A gyro: column:axis, e.g. gx:x (repeat for more gyros); default: the
    /// simulator's.
    #[arg(long, default_values = ["gyro_x_rad_s:x", "gyro_z_rad_s:z"])]
    pub gyro: Vec<String>,
    /// Unit of the accelerometer columns (m/s2, g, mg).
    #[arg(long, default_value = "m/s2")]
    pub accel_unit: String,
    /// Unit of the gyro columns (rad/s, deg/s, deg/h).
    #[arg(long, default_value = "rad/s")]
    pub gyro_unit: String,
    /// The site of the test: its latitude sets earth rate, latitude and
    /// height normal gravity (`--latitude` is the same as `--lat`).
    #[command(flatten)]
    pub site: SiteArgs,
    /// Gravity magnitude (m/s^2); default: normal gravity at latitude and height.
    #[arg(long)]
    pub gravity: Option<f64>,
    /// Method whose triad calibration goes into the file.
    #[arg(long, value_parser = fit_method(), default_value = "tls")]
    pub method: FitMethod,
    /// Calibration file to write (default: FILE with extension `.cal.json`).
    #[arg(long)]
    pub output: Option<PathBuf>,
}

/// `--method`: `ls` or `tls`.
fn fit_method() -> impl TypedValueParser<Value = FitMethod> {
    PossibleValuesParser::new(["ls", "tls"]).map(|name| match name.as_str() {
        "ls" => FitMethod::Ls,
        _ => FitMethod::Tls,
    })
}

pub fn run(args: Args) -> Result<()> {
    let data = read_position_data(&args)?;
    let site = args.site.position();
    let gravity = args
        .gravity
        .unwrap_or_else(|| mwd_core::earth::normal_gravity(site.lat, site.height));
    ensure!(
        gravity.is_finite() && gravity > 0.0,
        "gravity must be positive, got {gravity}"
    );
    let fit = fit(&data, gravity, site.lat)?;
    let path = args
        .output
        .clone()
        .unwrap_or_else(|| args.file.with_extension("cal.json"));
    fit.calibration_file(args.method, args.site.lat)?
        .save(&path)?;
    let latitude_deg = args.site.lat;
    print_out(&report(
        &args.file,
        latitude_deg,
        args.method,
        &data,
        &fit,
        &path,
    ))
}

/// The table's sensor columns, as the options name them, averaged per
/// position.
fn read_position_data(args: &Args) -> Result<PositionData> {
    let table = read_columns(&args.file)?;
    let accel_si = InputUnit::parse(&args.accel_unit)?.to_si();
    let gyro_si = InputUnit::parse(&args.gyro_unit)?.to_si();
    let triads: Vec<TriadColumns> = args
        .accel
        .iter()
        .map(|spec| TriadColumns::parse(spec))
        .collect::<Result<_>>()?;
    let gyros: Vec<GyroColumn> = args
        .gyro
        .iter()
        .map(|spec| GyroColumn::parse(spec))
        .collect::<Result<_>>()?;
    position_data(&table, &triads, &gyros, accel_si, gyro_si)
        .with_context(|| format!("{}", args.file.display()))
}
