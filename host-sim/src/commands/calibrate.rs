//! `host-sim calibrate FILE`: six-position calibration of accelerometer
//! triads (LS and TLS side by side) and gyro biases with earth rate
//! accounted for, like the paper's Table 3; writes a calibration file.
//! The calibration is `host_sim::analysis::six_position`'s; this module
//! reads the options and reports.

use super::output::print_out;
use anyhow::{ensure, Context, Result};
use clap::builder::{PossibleValuesParser, TypedValueParser};
use host_sim::analysis::calibration::TriadResult;
use host_sim::analysis::csv_input::read_columns;
use host_sim::analysis::six_position::{
    fit, position_data, GyroColumn, PositionData, SixPositionFit, TriadColumns,
};
use host_sim::analysis::tls::FitMethod;
use host_sim::analysis::units::InputUnit;
use std::fmt::Write;
use std::path::{Path, PathBuf};

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
    print_out(&report(&args, &data, &fit, &path))
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

/// The report: samples per position, each triad's LS and TLS estimates,
/// the gyro biases, and where the file went.
fn report(args: &Args, data: &PositionData, fit: &SixPositionFit, path: &Path) -> String {
    let mut out = String::new();
    let counts: Vec<String> = data
        .means
        .iter()
        .map(|m| format!("{} {}", m.face, m.samples))
        .collect();
    let _ = writeln!(
        out,
        "six-position calibration of {} ({})",
        args.file.display(),
        counts.join(", ")
    );
    let _ = writeln!(
        out,
        "gravity {:.5} m/s^2, earth rate up {:.4} deg/h at {:.5} deg",
        fit.gravity,
        fit.earth_rate_up.to_degrees() * 3600.0,
        args.site.lat
    );
    for triad in &fit.triads {
        let _ = writeln!(out, "\naccelerometer triad {}:", triad.columns.joined());
        triad_rows(&mut out, &triad.ls, &triad.tls);
    }
    gyro_rows(&mut out, fit);
    let _ = writeln!(
        out,
        "\ncalibration ({} triads, gyro biases) written to {}",
        args.method.to_string().to_uppercase(),
        path.display()
    );
    out
}

fn triad_rows(out: &mut String, ls: &TriadResult, tls: &TriadResult) {
    let axes = ["x", "y", "z"];
    let _ = writeln!(
        out,
        "  {:<28} {:>14} {:>14} {:>12}",
        "", "LS", "TLS", "+- 1 se"
    );
    for (i, axis) in axes.iter().enumerate() {
        let _ = writeln!(
            out,
            "  {:<28} {:>14.6} {:>14.6} {:>12.2e}",
            format!("bias {axis} (m/s^2)"),
            ls.coupling.h[i][3],
            tls.coupling.h[i][3],
            tls.bias_se[i]
        );
    }
    for (i, axis) in axes.iter().enumerate() {
        let (l, t) = (ls.coupling.h[i][i] - 1.0, tls.coupling.h[i][i] - 1.0);
        let _ = writeln!(
            out,
            "  {:<28} {:>14.1} {:>14.1} {:>12.1}",
            format!("scale error {axis} (ppm)"),
            l * 1e6,
            t * 1e6,
            tls.k_se[i][i] * 1e6
        );
    }
    for i in 0..3 {
        for j in (0..3).filter(|&j| j != i) {
            let name = format!("coupling {}<-{} (mrad)", axes[i], axes[j]);
            let _ = writeln!(
                out,
                "  {:<28} {:>14.4} {:>14.4} {:>12.4}",
                name,
                ls.coupling.h[i][j] * 1e3,
                tls.coupling.h[i][j] * 1e3,
                tls.k_se[i][j] * 1e3
            );
        }
    }
}

/// The gyro biases (deg/s and deg/h) and earth-rate scale factors.
fn gyro_rows(out: &mut String, fit: &SixPositionFit) {
    if !fit.gyros.is_empty() {
        let _ = writeln!(
            out,
            "\n  {:<10} {:>16} {:>14} {:>12} {:>14}",
            "gyro", "bias (deg/s)", "bias (deg/h)", "+- 1 se", "scale (earth)"
        );
    }
    for (gyro, g) in &fit.gyros {
        let deg = g.bias.to_degrees();
        let _ = writeln!(
            out,
            "  {:<10} {:>16.9} {:>14.3} {:>12.3} {:>8.3} +- {:.3}",
            format!("{} ({})", gyro.column, gyro.axis_name()),
            deg,
            deg * 3600.0,
            g.bias_se.to_degrees() * 3600.0,
            g.scale,
            g.scale_se
        );
    }
}
