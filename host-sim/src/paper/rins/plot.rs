//! Figures 3-6 of the paper from a run, each as SVG and PNG through the
//! survey figures' renderer (`survey_listing::plot::write_svg_png`).

use super::{Record, Results};
use crate::formats::figure::{legend_line, plot_error, write_svg_png, Figure, FONT};
use anyhow::Result;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

const SIZE: (u32, u32) = (1000, 620);
const COLOURS: [RGBColor; 5] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
];

/// A line plot over the run's hours with a marker line at the failure.
struct Lines {
    title: String,
    y_label: String,
    curves: Vec<(String, Vec<(f64, f64)>)>,
    failure_hour: f64,
}

impl Lines {
    fn new(title: &str, y_label: &str, failure_hour: f64) -> Self {
        Self {
            title: title.into(),
            y_label: y_label.into(),
            curves: Vec::new(),
            failure_hour,
        }
    }

    fn curve(mut self, name: &str, history: &[Record], y: impl Fn(&Record) -> f64) -> Self {
        let points = history
            .iter()
            .map(|r| (r.hour, y(r)))
            .filter(|p| p.1.is_finite())
            .collect();
        self.curves.push((name.into(), points));
        self
    }

    fn ranges(&self) -> ((f64, f64), (f64, f64)) {
        let all = self.curves.iter().flat_map(|c| c.1.iter());
        let (mut x, mut y) = ((0.0f64, 1.0f64), (f64::INFINITY, f64::NEG_INFINITY));
        for &(px, py) in all {
            x.1 = x.1.max(px);
            y = (y.0.min(py), y.1.max(py));
        }
        // no points, or a flat line: a unit span
        if y.0 >= y.1 || y.0.is_nan() {
            y = if y.0.is_finite() {
                (y.0 - 1.0, y.0 + 1.0)
            } else {
                (-1.0, 1.0)
            };
        }
        let pad = 0.05 * (y.1 - y.0);
        (x, (y.0 - pad, y.1 + pad))
    }
}

impl Figure for Lines {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<()> {
        root.fill(&WHITE).map_err(plot_error)?;
        let ((x0, x1), (y0, y1)) = self.ranges();
        let mut chart = ChartBuilder::on(root)
            .caption(&self.title, (FONT, 20))
            .margin(14)
            .x_label_area_size(44)
            .y_label_area_size(90)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(plot_error)?;
        chart
            .configure_mesh()
            .x_desc("time (h)")
            .y_desc(self.y_label.as_str())
            .label_style((FONT, 14))
            .draw()
            .map_err(plot_error)?;
        let grey = RGBColor(120, 120, 120);
        chart
            .draw_series(LineSeries::new(
                [(self.failure_hour, y0), (self.failure_hour, y1)],
                grey.stroke_width(1),
            ))
            .map_err(plot_error)?
            .label("master fails")
            .legend(legend_line(grey.stroke_width(1)));
        for (i, (name, points)) in self.curves.iter().enumerate() {
            let colour = COLOURS[i % COLOURS.len()];
            chart
                .draw_series(LineSeries::new(
                    points.iter().copied(),
                    colour.stroke_width(2),
                ))
                .map_err(plot_error)?
                .label(name.as_str())
                .legend(legend_line(colour.stroke_width(2)));
        }
        chart
            .configure_series_labels()
            .label_font((FONT, 14))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .draw()
            .map_err(plot_error)?;
        Ok(())
    }
}

/// Writes fig3 (drift estimate error and 3-sigma bounds), fig4-latitude and
/// fig4-longitude (error predictions), fig5 (radial errors with and without
/// compensation, and the master's) and fig6 (reduced against full filter)
/// into `dir`, SVG and PNG each; returns the files.
pub fn write_figures(dir: &Path, r: &Results, failure_hour: f64) -> Result<Vec<PathBuf>> {
    let h = &r.history;
    // Fig. 4, one per axis: the backup's error along it, the part due to
    // the azimuth drift and its prediction
    let fig4 = |axis: &str, y_label: &str, [error, drift, predicted]: [fn(&Record) -> f64; 3]| {
        Lines::new(
            &format!("Fig. 4: backup {axis} error and its prediction"),
            y_label,
            failure_hour,
        )
        .curve("backup error", h, error)
        .curve("part due to the azimuth drift", h, drift)
        .curve("prediction (eq. 31)", h, predicted)
    };
    let figures = [
        (
            "fig3-drift-estimate",
            Lines::new(
                "Fig. 3: backup azimuth drift estimate error (reduced filter)",
                "deg/h",
                failure_hour,
            )
            .curve("estimate error", h, |r| r.drift_error_reduced)
            .curve("+3 sigma", h, |r| 3.0 * r.drift_sigma_reduced)
            .curve("-3 sigma", h, |r| -3.0 * r.drift_sigma_reduced),
        ),
        (
            "fig4-latitude",
            fig4(
                "latitude",
                "north error (m)",
                [|r| r.backup_north, |r| r.drift_north, |r| r.predicted_north],
            ),
        ),
        (
            "fig4-longitude",
            fig4(
                "longitude",
                "east error (m)",
                [|r| r.backup_east, |r| r.drift_east, |r| r.predicted_east],
            ),
        ),
        (
            "fig5-radial",
            Lines::new("Fig. 5: radial position error", "m", failure_hour)
                .curve("backup, uncompensated", h, |r| r.radial_backup)
                .curve("backup, compensated (eq. 33)", h, |r| {
                    r.radial_compensated_reduced
                })
                .curve("master (dual-axis)", h, |r| r.radial_master),
        ),
        (
            "fig6-reduced-vs-full",
            Lines::new(
                "Fig. 6: compensated backup, reduced vs full filter",
                "radial error (m)",
                failure_hour,
            )
            .curve("reduced-order filter (8 states)", h, |r| {
                r.radial_compensated_reduced
            })
            .curve("full augmented filter (17 states)", h, |r| {
                r.radial_compensated_full
            }),
        ),
    ];
    let mut files = Vec::new();
    for (stem, figure) in &figures {
        files.extend(write_svg_png(dir, stem, SIZE, figure)?);
    }
    Ok(files)
}
