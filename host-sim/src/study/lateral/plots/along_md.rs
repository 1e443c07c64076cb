//! The error along MD ([`plot_error_along_md`]): per grade the RMS error
//! over the runs at each station against the predicted 1- and 2-sigma, on
//! a log y axis over MD; a line is broken where a value is undetermined.

use super::log_axis::{log_range, tick};
use super::split_stem;
use crate::formats::figure::{plot_error, write_svg_png, Figure, FONT};
use crate::survey::listing::plot::SIZE;
use anyhow::{bail, Result};
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

/// The runs of points with finite x and positive finite y (drawable on a
/// log y axis): a line is broken where a value is undetermined.
pub(super) fn drawable_runs(x: &[f64], y: &[f64]) -> Vec<Vec<(f64, f64)>> {
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
