//! The report of `host-sim calibrate`: the samples per position, each
//! accelerometer triad's LS and TLS estimates side by side with their
//! standard errors, the gyro biases and earth-rate scale factors (like the
//! paper's Table 3), and where the calibration file went
//! ([`crate::analysis::six_position`] computes them).

use crate::analysis::calibration::TriadResult;
use crate::analysis::six_position::{PositionData, SixPositionFit};
use crate::analysis::tls::FitMethod;
use std::fmt::Write;
use std::path::Path;

/// The report: samples per position, each triad's LS and TLS estimates,
/// the gyro biases, and where the file went.
///
/// `file` is the input, `latitude_deg` the site's, `method` the one whose
/// triad calibration went into the file at `path`.
pub fn report(
    file: &Path,
    latitude_deg: f64,
    method: FitMethod,
    data: &PositionData,
    fit: &SixPositionFit,
    path: &Path,
) -> String {
    let mut out = String::new();
    let counts: Vec<String> = data
        .means
        .iter()
        .map(|m| format!("{} {}", m.face, m.samples))
        .collect();
    let _ = writeln!(
        out,
        "six-position calibration of {} ({})",
        file.display(),
        counts.join(", ")
    );
    let _ = writeln!(
        out,
        "gravity {:.5} m/s^2, earth rate up {:.4} deg/h at {:.5} deg",
        fit.gravity,
        fit.earth_rate_up.to_degrees() * 3600.0,
        latitude_deg
    );
    for triad in &fit.triads {
        let _ = writeln!(out, "\naccelerometer triad {}:", triad.columns.joined());
        triad_rows(&mut out, &triad.ls, &triad.tls);
    }
    gyro_rows(&mut out, fit);
    let _ = writeln!(
        out,
        "\ncalibration ({} triads, gyro biases) written to {}",
        method.to_string().to_uppercase(),
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
