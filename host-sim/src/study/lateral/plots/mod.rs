//! Figures of the lateral study (issue 14): the error growth along MD with
//! the predicted bounds, per sensor grade, and the sweep of the TD error
//! over gyro bias and ARW as a contour map. Each is written as SVG and PNG
//! of the same drawing through the survey figures' [`Figure`] and
//! [`write_svg_png`] (embedded font, so PNG text needs no system fonts).
//!
//! Undetermined values (NaN) are never drawn as numbers: a line is broken
//! at them, and a sweep cell without a value is left blank.

pub mod contour;

use crate::formats::figure::{plot_error, write_svg_png, Figure, FONT};
use crate::survey::listing::plot::SIZE;
use anyhow::{anyhow, bail, Result};
use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

/// One grade's error along MD.
#[derive(Clone, Debug, PartialEq)]
pub struct AlongMdSeries {
    pub grade: String,
    pub md_m: Vec<f64>,
    /// RMS over the runs of the error at each station (NaN: undetermined).
    pub rms_error: Vec<f64>,
    /// The predicted 1-sigma at each station (NaN: undetermined).
    pub predicted_sigma: Vec<f64>,
}

/// Writes `STEM.svg` and `STEM.png`: per grade one colour, the RMS error
/// as markers joined by a line, the predicted 1-sigma dashed and 2-sigma
/// dotted, on a log y axis over MD.
pub fn plot_error_along_md(
    stem: &Path,
    title: &str,
    y_label: &str,
    series: &[AlongMdSeries],
) -> Result<[PathBuf; 2]> {
    for s in series {
        if s.rms_error.len() != s.md_m.len() || s.predicted_sigma.len() != s.md_m.len() {
            bail!(
                "grade {}: {} MDs, {} RMS errors and {} predicted sigmas (one each per station)",
                s.grade,
                s.md_m.len(),
                s.rms_error.len(),
                s.predicted_sigma.len()
            );
        }
    }
    let (dir, name) = split_stem(stem)?;
    let figure = AlongMd {
        title,
        y_label,
        series,
    };
    write_svg_png(dir, name, SIZE, &figure)
}

/// The sweep: `value[b][a]` at bias `bias_deg_per_h[b]` and ARW
/// `arw_deg_per_sqrt_h[a]` (e.g. TD horizontal 1-sigma, m per 1000 m;
/// NaN where undetermined).
pub struct Sweep<'a> {
    pub title: &'a str,
    pub bias_deg_per_h: &'a [f64],
    pub arw_deg_per_sqrt_h: &'a [f64],
    pub value: &'a [Vec<f64>],
    /// The contour drawn bold (the paper's requirement).
    pub requirement: f64,
    /// What the value is, with its unit (colour bar and requirement).
    pub label: &'a str,
    /// Named grades marked on the map: (name, bias deg/h, ARW deg/sqrt(h)).
    pub grades: &'a [(String, f64, f64)],
}

/// Writes `STEM.svg` and `STEM.png`: log-log axes, the value as a colour
/// map (log colour scale, with a colour bar), contour lines at 1-3-10
/// steps, the requirement's contour bold, and the grades as markers.
pub fn plot_sweep_contour(stem: &Path, sweep: &Sweep) -> Result<[PathBuf; 2]> {
    check_axis("bias", sweep.bias_deg_per_h)?;
    check_axis("ARW", sweep.arw_deg_per_sqrt_h)?;
    if sweep.value.len() != sweep.bias_deg_per_h.len()
        || sweep
            .value
            .iter()
            .any(|r| r.len() != sweep.arw_deg_per_sqrt_h.len())
    {
        bail!(
            "sweep: the values must be {} rows (biases) of {} (ARWs)",
            sweep.bias_deg_per_h.len(),
            sweep.arw_deg_per_sqrt_h.len()
        );
    }
    if !(sweep.requirement.is_finite() && sweep.requirement > 0.0) {
        bail!(
            "sweep: the requirement must be a positive number (got {})",
            sweep.requirement
        );
    }
    let (dir, name) = split_stem(stem)?;
    write_svg_png(dir, name, SIZE, &SweepFigure::new(sweep)?)
}

/// `STEM` as (directory, file stem) for [`write_svg_png`].
fn split_stem(stem: &Path) -> Result<(&Path, &str)> {
    let name = stem
        .file_name()
        .and_then(|n| n.to_str())
        .ok_or_else(|| anyhow!("{}: not a file name for the figures", stem.display()))?;
    let dir = match stem.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    Ok((dir, name))
}

fn check_axis(name: &str, v: &[f64]) -> Result<()> {
    if v.len() < 2 {
        bail!("sweep: at least two {name} values are needed for a map");
    }
    if !v.iter().all(|x| x.is_finite() && *x > 0.0) || v.windows(2).any(|w| w[1] <= w[0]) {
        bail!("sweep: the {name} values must be positive and increasing (a log axis)");
    }
    Ok(())
}

/// The runs of points with finite x and positive finite y (drawable on a
/// log y axis): a line is broken where a value is undetermined.
fn drawable_runs(x: &[f64], y: &[f64]) -> Vec<Vec<(f64, f64)>> {
    let mut runs = vec![Vec::new()];
    for (&a, &b) in x.iter().zip(y) {
        if a.is_finite() && b.is_finite() && b > 0.0 {
            if let Some(r) = runs.last_mut() {
                r.push((a, b));
            }
        } else if runs.last().is_some_and(|r| !r.is_empty()) {
            runs.push(Vec::new());
        }
    }
    runs.retain(|r| !r.is_empty());
    runs
}

/// A tick label: plain digits from 0.01 to 9999, else a power of ten.
fn tick(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    if (0.01..10_000.0).contains(&v.abs()) {
        let s = format!("{v:.3}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        format!("{v:.0e}")
    }
}

/// (low, high) of a log axis holding the positive finite values, with a
/// factor `pad` of room; `None` if there are none.
fn log_range(values: impl Iterator<Item = f64>, pad: f64) -> Option<(f64, f64)> {
    let (lo, hi) = values
        .filter(|v| v.is_finite() && *v > 0.0)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    (lo <= hi).then(|| {
        if lo == hi {
            (lo / 10.0, hi * 10.0)
        } else {
            (lo / pad, hi * pad)
        }
    })
}

struct AlongMd<'a> {
    title: &'a str,
    y_label: &'a str,
    series: &'a [AlongMdSeries],
}

impl Figure for AlongMd<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<()> {
        let x = self.series.iter().flat_map(|s| s.md_m.iter().copied());
        let (x0, x1) = x
            .filter(|v| v.is_finite())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                (a.min(v), b.max(v))
            });
        let y = self.series.iter().flat_map(|s| {
            let two = s.predicted_sigma.iter().map(|v| 2.0 * v);
            s.rms_error
                .iter()
                .copied()
                .chain(s.predicted_sigma.iter().copied())
                .chain(two)
        });
        if x0 >= x1 {
            bail!("nothing to plot along MD: fewer than two stations with an MD");
        }
        // nothing determined at all: an empty decade-wide axis, no numbers
        let (y0, y1) = log_range(y, 1.5).unwrap_or((0.1, 10.0));
        root.fill(&WHITE).map_err(plot_error)?;
        let area = root.titled(self.title, (FONT, 20)).map_err(plot_error)?;
        let mut chart = ChartBuilder::on(&area)
            .margin(15)
            .x_label_area_size(50)
            .y_label_area_size(80)
            .build_cartesian_2d(x0..x1, (y0..y1).log_scale())
            .map_err(plot_error)?;
        chart
            .configure_mesh()
            .x_desc("MD (m)")
            .y_desc(self.y_label)
            .x_label_formatter(&|v| format!("{v:.0}"))
            .y_label_formatter(&|v| tick(*v))
            .label_style((FONT, 14))
            .axis_desc_style((FONT, 16))
            .draw()
            .map_err(plot_error)?;
        for (i, s) in self.series.iter().enumerate() {
            let colour = Palette99::pick(i).to_rgba();
            for (k, run) in drawable_runs(&s.md_m, &s.rms_error).into_iter().enumerate() {
                let ann = chart
                    .draw_series(LineSeries::new(run.clone(), colour.stroke_width(1)))
                    .map_err(plot_error)?;
                if k == 0 {
                    ann.label(s.grade.as_str())
                        .legend(move |(x, y)| Circle::new((x + 10, y), 4, colour.filled()));
                }
                chart
                    .draw_series(run.into_iter().map(|p| Circle::new(p, 3, colour.filled())))
                    .map_err(plot_error)?;
            }
            for run in drawable_runs(&s.md_m, &s.predicted_sigma) {
                let two: Vec<(f64, f64)> = run.iter().map(|&(x, y)| (x, 2.0 * y)).collect();
                chart
                    .draw_series(DashedLineSeries::new(run, 10, 6, colour.stroke_width(2)))
                    .map_err(plot_error)?;
                chart
                    .draw_series(DashedLineSeries::new(
                        two,
                        2,
                        5,
                        colour.mix(0.7).stroke_width(2),
                    ))
                    .map_err(plot_error)?;
            }
        }
        // the line styles' key, once for every grade
        let key: [(&str, u32, u32); 2] =
            [("predicted 1-sigma", 10, 6), ("predicted 2-sigma", 2, 5)];
        chart
            .draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())
            .map_err(plot_error)?
            .label("RMS error (markers)")
            .legend(|(x, y)| Circle::new((x + 10, y), 3, BLACK.filled()));
        for (label, dash, gap) in key {
            chart
                .draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())
                .map_err(plot_error)?
                .label(label)
                .legend(move |(x, y)| {
                    DashedPathElement::new(
                        vec![(x, y), (x + 24, y)],
                        dash,
                        gap,
                        BLACK.stroke_width(2),
                    )
                });
        }
        chart
            .configure_series_labels()
            .label_font((FONT, 14))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .position(SeriesLabelPosition::UpperLeft)
            .draw()
            .map_err(plot_error)?;
        Ok(())
    }
}

mod sweep;
use sweep::SweepFigure;

#[cfg(test)]
mod tests;
