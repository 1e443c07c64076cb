//! Figures of a survey (`host-sim survey --plot DIR`): a plan view and a
//! vertical section of the well path with the stations' 2-sigma error
//! ellipses, each written as SVG and PNG.
//!
//! Rendered through [`crate::formats::figure`] (SVG and PNG of one drawing).
//!
//! Ellipses: the 2-sigma ellipse of a 2x2 covariance (k = 2 times the
//! 1-sigma semi-axes; it holds 1 - e^-2 = 86.5 % of a 2-D normal). In the
//! plan view the block is the NE block of the NEV covariance; in the
//! vertical section it is the covariance of (vertical-section distance,
//! vertical), i.e. the NEV covariance projected on the section plane with
//! the unit vectors (cos A, sin A, 0) and (0, 0, 1), A the section azimuth.

use super::{LengthUnit, Row};
use crate::formats::figure::{legend_line, plot_error, prepare_dir, write_svg_png, Figure, FONT};
use crate::survey::iscwsa::Cov6;
use anyhow::Result;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

/// Pixel size of every survey figure (SVG and PNG alike).
pub const SIZE: (u32, u32) = (1000, 800);
/// Ellipse scale: semi-axes are this many 1-sigma.
pub const SIGMA: f64 = 2.0;
/// Stroke colour of the error ellipses (and of nothing else drawn as a
/// line), so a reader (or a test) can tell them apart in the SVG.
pub const ELLIPSE_COLOUR: RGBColor = RGBColor(214, 39, 40);
const PATH_COLOUR: RGBColor = RGBColor(31, 119, 180);
const OTHER_COLOUR: RGBColor = RGBColor(44, 160, 44);
/// Points per ellipse outline.
const ELLIPSE_POINTS: usize = 73;

/// The `k`-sigma ellipse of the covariance `[[sxx, sxy], [sxy, syy]]`
/// of (x, y): semi-major and semi-minor axes, and the angle of the major
/// axis from +x towards +y (rad).
pub fn ellipse_axes(sxx: f64, syy: f64, sxy: f64, k: f64) -> (f64, f64, f64) {
    let mean = 0.5 * (sxx + syy);
    let half = (0.5 * (sxx - syy)).hypot(sxy);
    let a = k * (mean + half).max(0.0).sqrt();
    let b = k * (mean - half).max(0.0).sqrt();
    let theta = 0.5 * (2.0 * sxy).atan2(sxx - syy);
    (a, b, theta)
}

/// Outline of the `k`-sigma ellipse of the covariance
/// `[[sxx, sxy], [sxy, syy]]` of (x, y) around `centre`: the eigenvectors
/// of the block are the axes, `k` times the square roots of the eigenvalues
/// the semi-axes. Closed (last point = first).
pub fn ellipse_outline(
    centre: (f64, f64),
    sxx: f64,
    syy: f64,
    sxy: f64,
    k: f64,
) -> Vec<(f64, f64)> {
    let (a, b, theta) = ellipse_axes(sxx, syy, sxy, k);
    let (st, ct) = theta.sin_cos();
    (0..ELLIPSE_POINTS)
        .map(|i| {
            let t = std::f64::consts::TAU * i as f64 / (ELLIPSE_POINTS - 1) as f64;
            let (u, v) = (a * t.cos(), b * t.sin());
            (centre.0 + u * ct - v * st, centre.1 + u * st + v * ct)
        })
        .collect()
}

/// The plan-view block of a NEV covariance as (x = east, y = north):
/// (ee, nn, ne).
pub fn plan_block(c: &Cov6) -> (f64, f64, f64) {
    (c[1], c[0], c[3])
}

/// The section block (x = vertical-section distance along azimuth `a` rad,
/// y = vertical down): (var vs, var v, cov(vs, v)), with
/// vs = n cos a + e sin a.
pub fn section_block(c: &Cov6, a: f64) -> (f64, f64, f64) {
    let (s, co) = a.sin_cos();
    let [nn, ee, vv, ne, nv, ev] = *c;
    let var_vs = co * co * nn + s * s * ee + 2.0 * co * s * ne;
    (var_vs, vv, co * nv + s * ev)
}

/// One panel: a path, ellipses, markers for stations without covariance,
/// in data coordinates; equal scale on both axes.
pub struct Panel {
    pub title: String,
    pub x_desc: String,
    pub y_desc: String,
    pub path: Vec<(f64, f64)>,
    pub ellipses: Vec<Vec<(f64, f64)>>,
    pub ellipse_label: String,
    /// Stations without a covariance, and the legend note for them.
    pub no_cov: Vec<(f64, f64)>,
    pub no_cov_note: String,
    /// The y axis grows downwards (TVD): y is drawn negated and labelled
    /// with its true value.
    pub y_down: bool,
    /// Other wells' paths (legend label, points), drawn without ellipses.
    pub others: Vec<(String, Vec<(f64, f64)>)>,
}

const MARGIN: u32 = 15;
const X_LABEL_AREA: u32 = 50;
const Y_LABEL_AREA: u32 = 80;

/// Data ranges with the same length per pixel on both axes, holding every
/// point with a 5 % border.
fn equal_ranges(
    points: impl Iterator<Item = (f64, f64)>,
    px: (u32, u32),
) -> ((f64, f64), (f64, f64)) {
    let (mut x0, mut x1, mut y0, mut y1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for (x, y) in points.filter(|p| p.0.is_finite() && p.1.is_finite()) {
        (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
    }
    if x0 > x1 {
        (x0, x1, y0, y1) = (-1.0, 1.0, -1.0, 1.0);
    }
    let (w, h) = (f64::from(px.0.max(1)), f64::from(px.1.max(1)));
    let per_px = ((x1 - x0) / w).max((y1 - y0) / h).max(1e-6) * 1.1;
    let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
    (
        (cx - 0.5 * per_px * w, cx + 0.5 * per_px * w),
        (cy - 0.5 * per_px * h, cy + 0.5 * per_px * h),
    )
}

impl Figure for Panel {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<()> {
        let flip = |p: &(f64, f64)| if self.y_down { (p.0, -p.1) } else { *p };
        root.fill(&WHITE).map_err(plot_error)?;
        let area = root.titled(&self.title, (FONT, 20)).map_err(plot_error)?;
        let (w, h) = area.dim_in_pixel();
        let px = (
            w.saturating_sub(2 * MARGIN + Y_LABEL_AREA),
            h.saturating_sub(2 * MARGIN + X_LABEL_AREA),
        );
        let all = self
            .path
            .iter()
            .chain(self.ellipses.iter().flatten())
            .chain(&self.no_cov)
            .chain(self.others.iter().flat_map(|o| &o.1))
            .map(flip);
        let ((x0, x1), (y0, y1)) = equal_ranges(all, px);
        let mut chart = ChartBuilder::on(&area)
            .margin(MARGIN)
            .x_label_area_size(X_LABEL_AREA)
            .y_label_area_size(Y_LABEL_AREA)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(plot_error)?;
        let sign = if self.y_down { -1.0 } else { 1.0 };
        let y_fmt = move |v: &f64| format!("{:.0}", sign * v + 0.0);
        chart
            .configure_mesh()
            .x_desc(self.x_desc.as_str())
            .y_desc(self.y_desc.as_str())
            .x_label_formatter(&|v| format!("{v:.0}"))
            .y_label_formatter(&y_fmt)
            .label_style((FONT, 14))
            // major grid lines only: the light ones add nothing at equal
            // scale and double the PNG's size
            .light_line_style(TRANSPARENT)
            .axis_desc_style((FONT, 16))
            .draw()
            .map_err(plot_error)?;
        if !self.ellipses.is_empty() {
            chart
                .draw_series(self.ellipses.iter().map(|e| {
                    PathElement::new(
                        e.iter().map(flip).collect::<Vec<_>>(),
                        ELLIPSE_COLOUR.stroke_width(1),
                    )
                }))
                .map_err(plot_error)?
                .label(self.ellipse_label.as_str())
                // a filled box, not a line: the ellipse colour's lines in
                // the SVG are the ellipses alone
                .legend(|(x, y)| {
                    Rectangle::new(
                        [(x, y - 4), (x + 20, y + 4)],
                        ELLIPSE_COLOUR.mix(0.5).filled(),
                    )
                });
        }
        // the path over the ellipses, so it stays visible
        chart
            .draw_series(LineSeries::new(
                self.path.iter().map(flip),
                PATH_COLOUR.stroke_width(2),
            ))
            .map_err(plot_error)?
            .label("well path (minimum curvature)")
            .legend(legend_line(PATH_COLOUR.stroke_width(2)));
        for (label, points) in &self.others {
            chart
                .draw_series(LineSeries::new(
                    points.iter().map(flip),
                    OTHER_COLOUR.stroke_width(2),
                ))
                .map_err(plot_error)?
                .label(label.as_str())
                .legend(legend_line(OTHER_COLOUR.stroke_width(2)));
        }
        if !self.no_cov.is_empty() {
            chart
                .draw_series(
                    self.no_cov
                        .iter()
                        .map(|p| Cross::new(flip(p), 4, BLACK.stroke_width(1))),
                )
                .map_err(plot_error)?
                .label(self.no_cov_note.as_str())
                .legend(|(x, y)| Cross::new((x + 10, y), 4, BLACK.stroke_width(1)));
        }
        chart
            .configure_series_labels()
            .label_font((FONT, 14))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(plot_error)?;
        Ok(())
    }
}

/// What the survey figures need.
pub struct SurveyPlot<'a> {
    pub rows: &'a [Row],
    /// Unit of the figures (the station file's).
    pub unit: LengthUnit,
    /// Vertical-section azimuth, rad (true north).
    pub vsec_azimuth: f64,
    /// Well name for the titles (the station file's name).
    pub well: &'a str,
    /// Error model name, if one was run.
    pub model: Option<&'a str>,
    /// An offset well (name, rows) drawn as a path without ellipses.
    pub offset: Option<(&'a str, &'a [Row])>,
}

impl SurveyPlot<'_> {
    fn panels(&self) -> (Panel, Panel) {
        let (unit, k) = match self.unit {
            LengthUnit::Metre => ("m", 1.0),
            LengthUnit::Foot => ("ft", 1.0 / super::FOOT_M),
        };
        let k2 = k * k;
        let a = self.vsec_azimuth;
        let what = match self.model {
            Some(m) => format!(
                "{m}, {SIGMA:.0}-sigma ellipses ({:.1} % in 2-D)",
                100.0 * (1.0 - (-0.5 * SIGMA * SIGMA).exp())
            ),
            None => "no error model".to_string(),
        };
        let mut plan = Panel {
            title: format!("{}: plan view, {what}", self.well),
            x_desc: format!("east ({unit}, true north)"),
            y_desc: format!("north ({unit}, true north)"),
            path: Vec::new(),
            ellipses: Vec::new(),
            ellipse_label: format!("{SIGMA:.0}-sigma horizontal ellipse (NE block)"),
            no_cov: Vec::new(),
            no_cov_note: String::new(),
            y_down: false,
            others: Vec::new(),
        };
        let mut section = Panel {
            title: format!("{}: vertical section, {what}", self.well),
            x_desc: format!("vertical section along {:.2} deg ({unit})", a.to_degrees()),
            y_desc: format!("TVD ({unit}, down)"),
            path: Vec::new(),
            ellipses: Vec::new(),
            ellipse_label: format!("{SIGMA:.0}-sigma ellipse in the section plane"),
            no_cov: Vec::new(),
            no_cov_note: String::new(),
            y_down: true,
            others: Vec::new(),
        };
        for r in self.rows {
            let p = (k * r.east_m, k * r.north_m);
            let s = (k * r.vsec_m, k * r.tvd_m);
            plan.path.push(p);
            section.path.push(s);
            if self.model.is_none() {
                continue;
            }
            match &r.cov {
                Some(c) => {
                    let (xx, yy, xy) = plan_block(c);
                    plan.ellipses
                        .push(ellipse_outline(p, k2 * xx, k2 * yy, k2 * xy, SIGMA));
                    let (xx, yy, xy) = section_block(c, a);
                    section
                        .ellipses
                        .push(ellipse_outline(s, k2 * xx, k2 * yy, k2 * xy, SIGMA));
                }
                None => {
                    plan.no_cov.push(p);
                    section.no_cov.push(s);
                }
            }
        }
        let first = self.rows.iter().find(|r| r.cov.is_none());
        let note = match (self.model, first) {
            (Some(m), Some(r)) => format!(
                "no ellipse from MD {:.1} {unit} on: outside {m}'s stated validity, not extrapolated",
                k * r.md_m
            ),
            _ => String::new(),
        };
        plan.no_cov_note = note.clone();
        section.no_cov_note = note;
        if let Some((name, rows)) = self.offset {
            let label = format!("offset well {name} (no ellipses drawn)");
            let (sa, ca) = a.sin_cos();
            plan.others.push((
                label.clone(),
                rows.iter().map(|r| (k * r.east_m, k * r.north_m)).collect(),
            ));
            // projected on the reference well's section plane
            section.others.push((
                label,
                rows.iter()
                    .map(|r| (k * (r.north_m * ca + r.east_m * sa), k * r.tvd_m))
                    .collect(),
            ));
        }
        (plan, section)
    }

    /// Writes plan.svg, plan.png, section.svg, section.png into `dir`
    /// (created if missing; refused if it is not a directory).
    pub fn write(&self, dir: &Path) -> Result<Vec<PathBuf>> {
        prepare_dir(dir)?;
        let (plan, section) = self.panels();
        let mut out = write_svg_png(dir, "plan", SIZE, &plan)?.to_vec();
        out.extend(write_svg_png(dir, "section", SIZE, &section)?);
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::survey::listing::ellipse::{three_by_one_cov, Ellipse};

    fn close(a: f64, b: f64, tol: f64) {
        assert!((a - b).abs() <= tol, "{a} vs {b}");
    }

    /// Largest and smallest distance from the centre and the direction of
    /// the largest, over the outline.
    fn axes(points: &[(f64, f64)], c: (f64, f64)) -> (f64, f64, f64) {
        let d = |p: &(f64, f64)| (p.0 - c.0).hypot(p.1 - c.1);
        let far = points.iter().max_by(|a, b| d(a).total_cmp(&d(b))).unwrap();
        let near = points.iter().map(d).fold(f64::INFINITY, f64::min);
        (d(far), near, (far.1 - c.1).atan2(far.0 - c.0))
    }

    #[test]
    fn ellipse_of_a_known_covariance() {
        // semi-axes 3 and 1 (1-sigma), major axis 30 deg from +x:
        // cov = R diag(9, 1) R^T
        let t = 30f64.to_radians();
        let (s, c) = t.sin_cos();
        let (sxx, syy, sxy) = (9.0 * c * c + s * s, 9.0 * s * s + c * c, 8.0 * c * s);
        let centre = (100.0, -50.0);
        let pts = ellipse_outline(centre, sxx, syy, sxy, 2.0);
        assert_eq!(pts.first(), pts.last());
        let (a, b, dir) = axes(&pts, centre);
        // 72 segments: the sampled extremes are within 1 - cos(2.5 deg)
        close(a, 6.0, 1e-9); // t = 0 is sampled exactly
        close(b, 2.0, 2.0 * 0.01);
        let dir = dir.rem_euclid(std::f64::consts::PI);
        close(dir, t, 1e-9);
        // every point satisfies the quadratic form: d^T C^-1 d = k^2
        let det = sxx * syy - sxy * sxy;
        for p in &pts {
            let (x, y) = (p.0 - centre.0, p.1 - centre.1);
            let q = (syy * x * x - 2.0 * sxy * x * y + sxx * y * y) / det;
            close(q, 4.0, 1e-9);
        }
    }

    #[test]
    fn plan_ellipse_agrees_with_the_listing_ellipse() {
        // major axis at azimuth 60 deg (clockwise from north) in NEV
        let cov = three_by_one_cov(60.0, 4.0);
        let e = Ellipse::from_cov(&cov);
        let (xx, yy, xy) = plan_block(&cov);
        let pts = ellipse_outline((0.0, 0.0), xx, yy, xy, SIGMA);
        let (a, _, dir) = axes(&pts, (0.0, 0.0));
        close(a, SIGMA * e.semi_major, 1e-9);
        // azimuth from north clockwise = 90 deg - angle from east
        let azimuth = (90.0 - dir.to_degrees()).rem_euclid(180.0);
        close(azimuth, e.azimuth_deg, 1e-9);
    }

    #[test]
    fn section_block_projects_on_the_plane() {
        let cov = [4.0, 9.0, 16.0, 1.0, 2.0, 3.0];
        // along north: (nn, vv, nv)
        let (a, b, c) = section_block(&cov, 0.0);
        close(a, 4.0, 1e-12);
        close(b, 16.0, 1e-12);
        close(c, 2.0, 1e-12);
        // along east: (ee, vv, ev)
        let (a, _, c) = section_block(&cov, 90f64.to_radians());
        close(a, 9.0, 1e-12);
        close(c, 3.0, 1e-12);
        // at 45 deg: (nn + ee + 2 ne) / 2 and (nv + ev) / sqrt 2
        let (a, _, c) = section_block(&cov, 45f64.to_radians());
        close(a, 0.5 * (4.0 + 9.0 + 2.0), 1e-12);
        close(c, 5.0 / 2f64.sqrt(), 1e-12);
    }

    #[test]
    fn equal_scale() {
        let ((x0, x1), (y0, y1)) =
            equal_ranges([(0.0, 0.0), (100.0, 10.0)].into_iter(), (800, 400));
        close((x1 - x0) / 800.0, (y1 - y0) / 400.0, 1e-12);
        assert!(x0 < 0.0 && x1 > 100.0 && y0 < 0.0 && y1 > 10.0);
    }
}
