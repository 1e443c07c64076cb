//! The sweep's contour map ([`plot_sweep_contour`]): a colour map
//! of the value on log-log axes (each grid point's cell reaching halfway,
//! in log, to its neighbours), contour lines by marching squares on the
//! log grid (log10 of bias, ARW and value: the TD error is close to a
//! power law of both, so its contours are nearly straight there), the
//! requirement's contour bold, the named grades as markers, and a colour
//! bar.

use super::contour::{contour_segments, Segment};
use super::log_axis::{log_range, tick};
use super::split_stem;
use crate::formats::figure::{plot_error, write_svg_png, Figure, FONT};
use crate::survey::listing::plot::SIZE;
use anyhow::{bail, Result};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

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

/// A sweep axis: at least two values, positive and increasing (a log axis).
fn check_axis(name: &str, v: &[f64]) -> Result<()> {
    if v.len() < 2 {
        bail!("sweep: at least two {name} values are needed for a map");
    }
    if !v.iter().all(|x| x.is_finite() && *x > 0.0) || v.windows(2).any(|w| w[1] <= w[0]) {
        bail!("sweep: the {name} values must be positive and increasing (a log axis)");
    }
    Ok(())
}

/// Contour levels (1-3-10 steps), drawn where the value spans them.
pub const LEVELS: [f64; 13] = [
    0.01, 0.03, 0.1, 0.3, 1.0, 3.0, 10.0, 30.0, 100.0, 300.0, 1000.0, 3000.0, 10_000.0,
];
const REQUIREMENT_COLOUR: RGBColor = RGBColor(214, 39, 40);
/// Width of the colour bar's panel, px.
const BAR_PANEL: u32 = 150;

/// Matplotlib's viridis colour map (perceptually uniform, readable in grey
/// and by colour-blind readers) through five of its published anchor
/// colours (0, 0.25, 0.5, 0.75, 1: #440154, #3b528b, #21918c, #5ec962,
/// #fde725), linear in between.
pub fn viridis(t: f64) -> RGBColor {
    const ANCHORS: [(f64, f64, f64); 5] = [
        (68.0, 1.0, 84.0),
        (59.0, 82.0, 139.0),
        (33.0, 145.0, 140.0),
        (94.0, 201.0, 98.0),
        (253.0, 231.0, 37.0),
    ];
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let s = t * 4.0;
    let k = (s.floor() as usize).min(3);
    let f = s - k as f64;
    let (a, b) = (ANCHORS[k], ANCHORS[k + 1]);
    let mix = |x: f64, y: f64| (x + f * (y - x)).round() as u8;
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

/// Cell edges of a log axis: halfway (in log) between neighbours, the
/// outer ones as far out as the inner ones are.
fn edges(v: &[f64]) -> Vec<f64> {
    let l: Vec<f64> = v.iter().map(|x| x.log10()).collect();
    let n = l.len();
    let mut e = Vec::with_capacity(n + 1);
    e.push(l[0] - 0.5 * (l[1] - l[0]));
    for k in 1..n {
        e.push(0.5 * (l[k - 1] + l[k]));
    }
    e.push(l[n - 1] + 0.5 * (l[n - 1] - l[n - 2]));
    e.into_iter().map(|x| 10f64.powf(x)).collect()
}

/// A log range widened to hold `points` with a factor 2 of room.
fn widen(range: (f64, f64), points: impl Iterator<Item = f64>) -> (f64, f64) {
    points
        .filter(|v| v.is_finite() && *v > 0.0)
        .fold(range, |(a, b), v| (a.min(v / 2.0), b.max(v * 2.0)))
}

pub(super) struct SweepFigure<'a> {
    sweep: &'a Sweep<'a>,
    /// Colour scale of the value (log).
    scale: (f64, f64),
    x: (f64, f64),
    y: (f64, f64),
    cells: Vec<([(f64, f64); 2], RGBColor)>,
    /// (level, bold, segments in data coordinates).
    lines: Vec<(f64, bool, Vec<Segment>)>,
}

impl<'a> SweepFigure<'a> {
    pub(super) fn new(sweep: &'a Sweep<'a>) -> Result<Self> {
        let all = sweep.value.iter().flatten().copied();
        let Some(scale) = log_range(all, 1.0) else {
            bail!("sweep: no value to map (every cell undetermined)");
        };
        let (bx, ax) = (edges(sweep.bias_deg_per_h), edges(sweep.arw_deg_per_sqrt_h));
        let span = (scale.1 / scale.0).log10();
        let mut cells = Vec::new();
        for (b, row) in sweep.value.iter().enumerate() {
            for (a, &v) in row.iter().enumerate() {
                if v.is_finite() && v > 0.0 {
                    let t = (v / scale.0).log10() / span;
                    cells.push(([(bx[b], ax[a]), (bx[b + 1], ax[a + 1])], viridis(t)));
                }
            }
        }
        let lg = |v: &[f64]| v.iter().map(|x| x.log10()).collect::<Vec<_>>();
        let (lb, la) = (lg(sweep.bias_deg_per_h), lg(sweep.arw_deg_per_sqrt_h));
        let lz: Vec<Vec<f64>> = sweep
            .value
            .iter()
            .map(|r| {
                r.iter()
                    .map(|&v| if v > 0.0 { v.log10() } else { f64::NAN })
                    .collect()
            })
            .collect();
        let req = sweep.requirement;
        let same = |l: f64| (l / req - 1.0).abs() < 1e-9;
        let mut levels: Vec<(f64, bool)> = LEVELS
            .iter()
            .filter(|&&l| !same(l))
            .map(|&l| (l, false))
            .collect();
        levels.push((req, true));
        let lines = levels
            .into_iter()
            .filter(|(l, _)| *l > scale.0 && *l < scale.1)
            .map(|(l, bold)| {
                let segs = contour_segments(&lb, &la, &lz, l.log10())
                    .into_iter()
                    .map(|s| s.map(|(p, q)| (10f64.powf(p), 10f64.powf(q))))
                    .collect();
                (l, bold, segs)
            })
            .collect();
        // grades off the log axes (not positive) are not drawn
        let grades = sweep.grades;
        Ok(Self {
            sweep,
            scale,
            x: widen((bx[0], bx[bx.len() - 1]), grades.iter().map(|g| g.1)),
            y: widen((ax[0], ax[ax.len() - 1]), grades.iter().map(|g| g.2)),
            cells,
            lines,
        })
    }

    /// What the requirement's contour says, for the legend ("met": the
    /// value at or below it).
    fn requirement_note(&self) -> String {
        let req = self.sweep.requirement;
        let what = format!("requirement {} ({})", tick(req), self.sweep.label);
        let has = self.lines.iter().any(|(_, bold, s)| *bold && !s.is_empty());
        let values = self.sweep.value.iter().flatten().filter(|v| v.is_finite());
        let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
        if has {
            what
        } else if hi <= req {
            format!("{what}: met everywhere in the sweep")
        } else if lo > req {
            format!("{what}: met nowhere in the sweep")
        } else {
            format!("{what}: no contour between determined values")
        }
    }

    fn colour_bar<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> Result<()> {
        let (lo, hi) = self.scale;
        let mut bar = ChartBuilder::on(area)
            .margin_top(15)
            .margin_bottom(65)
            .margin_right(10)
            .y_label_area_size(90)
            .build_cartesian_2d(0.0..1.0, (lo..hi).log_scale())
            .map_err(plot_error)?;
        bar.configure_mesh()
            .disable_x_mesh()
            .disable_x_axis()
            .disable_y_mesh()
            .y_desc(self.sweep.label)
            .y_label_formatter(&|v| tick(*v))
            .label_style((FONT, 13))
            .axis_desc_style((FONT, 14))
            .draw()
            .map_err(plot_error)?;
        const STEPS: usize = 64;
        let at = |k: usize| lo * (hi / lo).powf(k as f64 / STEPS as f64);
        bar.draw_series((0..STEPS).map(|k| {
            let t = (k as f64 + 0.5) / STEPS as f64;
            Rectangle::new([(0.0, at(k)), (1.0, at(k + 1))], viridis(t).filled())
        }))
        .map_err(plot_error)?;
        let req = self.sweep.requirement;
        if req > lo && req < hi {
            bar.draw_series(std::iter::once(PathElement::new(
                vec![(0.0, req), (1.0, req)],
                REQUIREMENT_COLOUR.stroke_width(3),
            )))
            .map_err(plot_error)?;
        }
        Ok(())
    }
}

impl Figure for SweepFigure<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<()> {
        root.fill(&WHITE).map_err(plot_error)?;
        let area = root
            .titled(self.sweep.title, (FONT, 20))
            .map_err(plot_error)?;
        let w = area.dim_in_pixel().0;
        let (main, bar) = area.split_horizontally(w.saturating_sub(BAR_PANEL));
        let mut chart = ChartBuilder::on(&main)
            .margin(15)
            .x_label_area_size(50)
            .y_label_area_size(80)
            .build_cartesian_2d(
                (self.x.0..self.x.1).log_scale(),
                (self.y.0..self.y.1).log_scale(),
            )
            .map_err(plot_error)?;
        chart
            .draw_series(
                self.cells
                    .iter()
                    .map(|(r, c)| Rectangle::new(*r, c.filled())),
            )
            .map_err(plot_error)?;
        chart
            .configure_mesh()
            .x_desc("gyro bias (deg/h)")
            .y_desc("gyro ARW (deg/sqrt(h))")
            .x_label_formatter(&|v| tick(*v))
            .y_label_formatter(&|v| tick(*v))
            .bold_line_style(WHITE.mix(0.35))
            .light_line_style(TRANSPARENT)
            .label_style((FONT, 14))
            .axis_desc_style((FONT, 16))
            .draw()
            .map_err(plot_error)?;
        let mut thin_labelled = false;
        for (level, bold, segs) in &self.lines {
            let style = if *bold {
                REQUIREMENT_COLOUR.stroke_width(3)
            } else {
                BLACK.mix(0.7).stroke_width(1)
            };
            let ann = chart
                .draw_series(segs.iter().map(|s| PathElement::new(s.to_vec(), style)))
                .map_err(plot_error)?;
            if *bold {
                ann.label(self.requirement_note())
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], style));
            } else if !thin_labelled && !segs.is_empty() {
                thin_labelled = true;
                ann.label("contours at 1-3-10 steps (labelled)")
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], style));
            }
            // the level's number at the middle piece of its line
            if let Some(s) = segs.get(segs.len() / 2) {
                chart
                    .draw_series(std::iter::once(Text::new(
                        tick(*level),
                        s[0],
                        (FONT, 13).into_font().color(&BLACK),
                    )))
                    .map_err(plot_error)?;
            }
        }
        if !self.lines.iter().any(|(_, bold, _)| *bold) {
            // the requirement is outside the map's values: say so
            chart
                .draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())
                .map_err(plot_error)?
                .label(self.requirement_note())
                .legend(|(x, y)| {
                    PathElement::new(
                        vec![(x, y), (x + 24, y)],
                        REQUIREMENT_COLOUR.stroke_width(3),
                    )
                });
        }
        chart
            .draw_series(
                self.sweep
                    .grades
                    .iter()
                    .filter(|g| [g.1, g.2].iter().all(|v| v.is_finite() && *v > 0.0))
                    .map(|(name, b, a)| {
                        EmptyElement::at((*b, *a))
                            + Circle::new((0, 0), 6, WHITE.filled())
                            + Circle::new((0, 0), 6, BLACK.stroke_width(2))
                            + Text::new(name.clone(), (9, -16), (FONT, 14).into_font())
                    }),
            )
            .map_err(plot_error)?;
        chart
            .configure_series_labels()
            .label_font((FONT, 14))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .position(SeriesLabelPosition::LowerRight)
            .draw()
            .map_err(plot_error)?;
        self.colour_bar(&bar)
    }
}
