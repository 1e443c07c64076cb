//! The report of `host-sim allan`: each column's overlapping Allan
//! deviation by tau with its confidence interval and the fitted noise
//! coefficients as tables, and the log-log plot of the deviations with
//! the fitted noise terms ([`crate::analysis::allan_analysis`] computes
//! them).

use crate::analysis::allan_analysis::{AllanReport, SensorAllan};
use crate::analysis::allan_fit::bias_instability_factor;
use crate::analysis::plot::{loglog_svg, Labels, Series, Style};
use crate::analysis::units::{deviation_unit, Quantity};
use anyhow::Result;
use std::fmt::Write;
use std::path::Path;

/// Each sensor's deviations by tau with their confidence intervals and
/// its noise coefficients, as tables.
pub fn tables(report: &AllanReport) -> String {
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
pub fn plot(path: &Path, sensors: &[SensorAllan]) -> Result<()> {
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
