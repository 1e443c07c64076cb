//! SVG plots (plotters' SVG backend; text laid out with the embedded font): log-log plots of
//! measured points with vertical error bars and model lines, and plain
//! line plots of time series.

use crate::formats::figure::legend_line;
use anyhow::{anyhow, Result};
use plotters::chart::SeriesLabelStyle;
use plotters::coord::{CoordTranslate, Shift};
use plotters::prelude::*;
use std::ops::Range;
use std::path::Path;

/// How a series is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Style {
    /// Markers joined by a thin line (measured data).
    Markers,
    /// A plain line (fitted model or one of its terms).
    Line,
}

/// One named curve of a plot.
#[derive(Clone, Debug)]
pub struct Series {
    /// Legend label.
    pub name: String,
    /// Points (x, y); non-positive values are dropped on a log axis.
    pub points: Vec<(f64, f64)>,
    /// Optional (low, high) error bar per point.
    pub error_bars: Vec<(f64, f64)>,
    /// Drawing style.
    pub style: Style,
    /// Index into the palette: series of one sensor share a colour.
    pub colour: usize,
}

/// Axis labels and title.
pub struct Labels<'a> {
    /// Title above the plot.
    pub title: &'a str,
    /// X-axis description.
    pub x: &'a str,
    /// Y-axis description.
    pub y: &'a str,
}

fn bounds(series: &[Series]) -> Option<((f64, f64), (f64, f64))> {
    let mut xs = (f64::INFINITY, f64::NEG_INFINITY);
    let mut ys = (f64::INFINITY, f64::NEG_INFINITY);
    for s in series {
        let bars = s.error_bars.iter().flat_map(|&(l, h)| [l, h]);
        for (x, y) in s.points.iter().copied().chain(bars.map(|v| (f64::NAN, v))) {
            if x > 0.0 && x.is_finite() {
                xs = (xs.0.min(x), xs.1.max(x));
            }
            if y > 0.0 && y.is_finite() {
                ys = (ys.0.min(y), ys.1.max(y));
            }
        }
    }
    (xs.0 < xs.1 && ys.0 <= ys.1).then(|| ((xs.0 / 1.2, xs.1 * 1.2), (ys.0 / 2.0, ys.1 * 2.0)))
}

/// A chart on `root` with the title and room for the axes' labels
/// (`x_label_area` pixels below).
fn chart_builder<'a, 'b, DB: DrawingBackend>(
    root: &'a DrawingArea<DB, Shift>,
    labels: &Labels,
    x_label_area: u32,
) -> ChartBuilder<'a, 'b, DB> {
    let mut builder = ChartBuilder::on(root);
    builder
        .caption(labels.title, ("sans-serif", 22))
        .margin(12)
        .x_label_area_size(x_label_area)
        .y_label_area_size(80);
    builder
}

/// The legend's box (drawn by the caller, where it wants it).
fn legend<'a, 'b, DB: DrawingBackend + 'a, CT: CoordTranslate>(
    chart: &'b mut ChartContext<'a, DB, CT>,
) -> SeriesLabelStyle<'a, 'b, DB, CT> {
    let mut style = chart.configure_series_labels();
    style.background_style(WHITE.mix(0.8)).border_style(BLACK);
    style
}

/// Writes a log-log plot of `series` to an SVG file.
pub fn loglog_svg(path: &Path, labels: &Labels, series: &[Series]) -> Result<()> {
    crate::formats::figure::register_font()?;
    let ((x0, x1), (y0, y1)) =
        bounds(series).ok_or_else(|| anyhow!("nothing positive to plot in {}", path.display()))?;
    let root = SVGBackend::new(path, (900, 640)).into_drawing_area();
    let err = |e: &dyn std::fmt::Display| anyhow!("plot {}: {e}", path.display());
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let mut chart = chart_builder(&root, labels, 48)
        .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
        .map_err(|e| err(&e))?;
    chart
        .configure_mesh()
        .x_desc(labels.x)
        .y_desc(labels.y)
        .y_label_formatter(&|v| format!("{v:.1e}"))
        .draw()
        .map_err(|e| err(&e))?;
    for s in series {
        let colour = Palette99::pick(s.colour).to_rgba();
        let pts: Vec<(f64, f64)> = s
            .points
            .iter()
            .copied()
            .filter(|&(x, y)| x > 0.0 && y > 0.0)
            .collect();
        match s.style {
            Style::Markers => {
                chart
                    .draw_series(LineSeries::new(pts.clone(), colour.stroke_width(1)))
                    .map_err(|e| err(&e))?
                    .label(s.name.as_str())
                    .legend(move |(x, y)| Circle::new((x + 10, y), 3, colour.filled()));
                chart
                    .draw_series(pts.iter().map(|&p| Circle::new(p, 3, colour.filled())))
                    .map_err(|e| err(&e))?;
                let bars = s
                    .points
                    .iter()
                    .zip(&s.error_bars)
                    .filter(|(p, b)| p.0 > 0.0 && b.0 > 0.0);
                chart
                    .draw_series(bars.map(|(p, b)| {
                        PathElement::new(vec![(p.0, b.0), (p.0, b.1)], colour.stroke_width(1))
                    }))
                    .map_err(|e| err(&e))?;
            }
            Style::Line => {
                chart
                    .draw_series(LineSeries::new(pts, colour.mix(0.6).stroke_width(2)))
                    .map_err(|e| err(&e))?
                    .label(s.name.as_str())
                    .legend(legend_line(colour.stroke_width(2)));
            }
        }
    }
    legend(&mut chart)
        .position(SeriesLabelPosition::LowerLeft)
        .draw()
        .map_err(|e| err(&e))?;
    root.present().map_err(|e| err(&e))?;
    Ok(())
}

/// A named curve of a line plot: legend label and points (x, y).
pub type Curve<'a> = (&'a str, Vec<(f64, f64)>);

/// Writes a line plot of `curves` over `x_range` to an SVG file; the y
/// axis spans the finite values with a 5 % margin.
pub fn line_svg(path: &Path, labels: &Labels, x_range: Range<f64>, curves: &[Curve]) -> Result<()> {
    crate::formats::figure::register_font()?;
    let err = |e: &dyn std::fmt::Display| anyhow!("plot {}: {e}", path.display());
    let (mut y0, mut y1) = (f64::INFINITY, f64::NEG_INFINITY);
    for (_, pts) in curves {
        for &(_, v) in pts.iter().filter(|p| p.1.is_finite()) {
            y0 = y0.min(v);
            y1 = y1.max(v);
        }
    }
    // Nothing finite, or a flat line: give the axis a unit span.
    if y0.is_nan() || y1.is_nan() || y0 >= y1 {
        y0 = if y0.is_finite() { y0 } else { 0.0 };
        y1 = y0 + 1.0;
    }
    let pad = 0.05 * (y1 - y0);
    let root = SVGBackend::new(path, (900, 560)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let mut chart = chart_builder(&root, labels, 44)
        .build_cartesian_2d(x_range, (y0 - pad)..(y1 + pad))
        .map_err(|e| err(&e))?;
    chart
        .configure_mesh()
        .x_desc(labels.x)
        .y_desc(labels.y)
        .draw()
        .map_err(|e| err(&e))?;
    for (i, (name, pts)) in curves.iter().enumerate() {
        let colour = Palette99::pick(i).to_rgba();
        chart
            .draw_series(LineSeries::new(pts.iter().copied(), colour.stroke_width(2)))
            .map_err(|e| err(&e))?
            .label(*name)
            .legend(legend_line(colour.stroke_width(2)));
    }
    legend(&mut chart).draw().map_err(|e| err(&e))?;
    root.present().map_err(|e| err(&e))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_an_svg() {
        let dir = std::env::temp_dir().join(format!("plot-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("p.svg");
        let s = Series {
            name: "a".into(),
            points: vec![(0.1, 1.0), (1.0, 0.3), (10.0, 0.1)],
            error_bars: vec![(0.9, 1.1), (0.25, 0.35), (0.05, 0.2)],
            style: Style::Markers,
            colour: 0,
        };
        let fit = Series {
            style: Style::Line,
            name: "fit".into(),
            error_bars: vec![],
            ..s.clone()
        };
        loglog_svg(
            &path,
            &Labels {
                title: "t",
                x: "tau (s)",
                y: "dev",
            },
            &[s, fit],
        )
        .unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text.starts_with("<svg") && text.contains("<circle"));
        let empty = Series {
            points: vec![(0.0, -1.0)],
            ..Series {
                name: String::new(),
                points: vec![],
                error_bars: vec![],
                style: Style::Line,
                colour: 0,
            }
        };
        assert!(loglog_svg(
            &path,
            &Labels {
                title: "",
                x: "",
                y: ""
            },
            &[empty]
        )
        .is_err());
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn line_plots_survive_flat_and_non_finite_series() {
        let dir = std::env::temp_dir().join(format!("line-plot-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("l.svg");
        let labels = Labels {
            title: "flat",
            x: "time (s)",
            y: "deg",
        };
        let flat = vec![(0.0, 2.0), (1.0, 2.0), (2.0, f64::NAN)];
        let none = vec![(0.0, f64::INFINITY)];
        line_svg(&path, &labels, 0.0..2.0, &[("flat", flat), ("none", none)]).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text.starts_with("<svg") && text.contains("flat"));
        std::fs::remove_dir_all(&dir).ok();
    }
}
