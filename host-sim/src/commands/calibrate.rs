//! `host-sim calibrate FILE`: six-position calibration of accelerometer
//! triads (LS and TLS side by side) and gyro biases with earth rate
//! accounted for, like the paper's Table 3; writes a calibration file.

use super::allan::print_out;
use anyhow::{bail, Context, Result};
use host_sim::analysis::calibration::{
    calibrate_gyro, calibrate_triad, earth_rate_up, position_means, TriadResult,
};
use host_sim::analysis::calibration_file::{
    CalibrationFile, GyroEntry, TriadEntry, FORMAT, VERSION,
};
use host_sim::analysis::csv_input::read_columns;
use host_sim::analysis::tls::FitMethod;
use host_sim::analysis::units::InputUnit;
use std::fmt::Write;
use std::path::PathBuf;

use super::site::SiteArgs;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// CSV with a header: a `position` column (1 = +x up, 2 = x down,
    /// 3 = +y up, 4 = y down, 5 = +z up, 6 = z down) and the sensor columns.
    pub file: PathBuf,
    /// An accelerometer triad: its x,y,z column names (repeat for more triads).
    #[arg(long, default_values = ["ax,ay,az"])]
    pub accel: Vec<String>,
    /// A gyro: column:axis, e.g. gx:x (repeat for more gyros).
    #[arg(long, default_values = ["gx:x", "gz:z"])]
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
    #[arg(long, value_parser = ["ls", "tls"], default_value = "tls")]
    pub method: String,
    /// Calibration file to write (default: FILE with extension `.cal.json`).
    #[arg(long)]
    pub output: Option<PathBuf>,
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

pub fn run(args: Args) -> Result<()> {
    let table = read_columns(&args.file)?;
    let accel_si = InputUnit::parse(&args.accel_unit)?.to_si();
    let gyro_si = InputUnit::parse(&args.gyro_unit)?.to_si();
    let site = args.site.position();
    let lat = site.lat;
    let gravity = args
        .gravity
        .unwrap_or_else(|| mwd_core::earth::normal_gravity(lat, site.height));
    if !(gravity.is_finite() && gravity > 0.0) {
        bail!("gravity must be positive, got {gravity}");
    }
    let omega_up = earth_rate_up(lat);
    let positions = table
        .column("position")
        .with_context(|| format!("{}", args.file.display()))?;
    // Every sensor column converted to SI, in the order they are named.
    let mut names: Vec<String> = Vec::new();
    let mut data: Vec<Vec<f64>> = Vec::new();
    let mut col_of = |name: &str, scale: f64| -> Result<usize> {
        let col = table
            .column(name)
            .with_context(|| format!("{}", args.file.display()))?;
        names.push(name.to_string());
        data.push(col.iter().map(|v| v * scale).collect());
        Ok(data.len() - 1)
    };
    let mut triads = Vec::new();
    for spec in &args.accel {
        let cols: Vec<&str> = spec.split(',').map(str::trim).collect();
        let [x, y, z] = cols.as_slice() else {
            bail!("--accel wants three column names x,y,z, got `{spec}`")
        };
        triads.push((
            [x.to_string(), y.to_string(), z.to_string()],
            [
                col_of(x, accel_si)?,
                col_of(y, accel_si)?,
                col_of(z, accel_si)?,
            ],
        ));
    }
    let mut gyros = Vec::new();
    for spec in &args.gyro {
        let Some((name, axis)) = spec.split_once(':') else {
            bail!("--gyro wants column:axis, got `{spec}`")
        };
        let axis_idx = match axis.trim() {
            "x" => 0,
            "y" => 1,
            "z" => 2,
            other => bail!("--gyro {spec}: axis `{other}` is not x, y or z"),
        };
        gyros.push((
            name.trim().to_string(),
            axis.trim().to_string(),
            axis_idx,
            col_of(name.trim(), gyro_si)?,
        ));
    }
    let refs: Vec<&[f64]> = data.iter().map(Vec::as_slice).collect();
    let means =
        position_means(positions, &refs).with_context(|| format!("{}", args.file.display()))?;
    let mut out = String::new();
    let counts: Vec<String> = means
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
        "gravity {gravity:.5} m/s^2, earth rate up {:.4} deg/h at {:.5} deg",
        omega_up.to_degrees() * 3600.0,
        args.site.lat
    );
    let use_tls = args.method == "tls";
    let mut accel_entries = Vec::new();
    for (names3, cols) in &triads {
        let ls = calibrate_triad(&means, *cols, gravity, FitMethod::Ls)?;
        let tls = calibrate_triad(&means, *cols, gravity, FitMethod::Tls)?;
        let _ = writeln!(out, "\naccelerometer triad {}:", names3.join(","));
        triad_rows(&mut out, &ls, &tls);
        let chosen = if use_tls { &tls } else { &ls };
        let cal = chosen
            .coupling
            .to_triad_calibration()
            .with_context(|| format!("triad {}", names3.join(",")))?;
        accel_entries.push(TriadEntry {
            columns: names3.clone(),
            bias: cal.bias,
            correction: cal.correction,
        });
    }
    let mut gyro_entries = Vec::new();
    if !gyros.is_empty() {
        let _ = writeln!(
            out,
            "\n  {:<10} {:>16} {:>14} {:>12} {:>14}",
            "gyro", "bias (deg/s)", "bias (deg/h)", "+- 1 se", "scale (earth)"
        );
    }
    for (name, axis, axis_idx, col) in &gyros {
        let g = calibrate_gyro(&means, *col, *axis_idx, omega_up)?;
        let deg = g.bias.to_degrees();
        let _ = writeln!(
            out,
            "  {:<10} {:>16.9} {:>14.3} {:>12.3} {:>8.3} +- {:.3}",
            format!("{name} ({axis})"),
            deg,
            deg * 3600.0,
            g.bias_se.to_degrees() * 3600.0,
            g.scale,
            g.scale_se
        );
        gyro_entries.push(GyroEntry {
            column: name.clone(),
            axis: axis.clone(),
            bias: g.to_core().bias,
            scale: 1.0,
        });
    }
    let file = CalibrationFile {
        format: FORMAT.into(),
        version: VERSION,
        method: args.method.clone(),
        latitude_deg: args.site.lat,
        gravity,
        accel: accel_entries,
        gyro: gyro_entries,
    };
    let path = args
        .output
        .clone()
        .unwrap_or_else(|| args.file.with_extension("cal.json"));
    file.save(&path)?;
    let _ = writeln!(
        out,
        "\ncalibration ({} triads, gyro biases) written to {}",
        args.method.to_uppercase(),
        path.display()
    );
    print_out(&out)
}
