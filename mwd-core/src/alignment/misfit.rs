//! The heading's misfit to the gyro means of all segments, with the gyro
//! biases solved for ([`Misfit`]), and the search for its (at most two)
//! minima: a grid, golden-section and Newton refinement, and a mirror
//! minimum the grid merged.

use super::segments::{AlignmentConfig, MeanSigmas, StaticSegment, MAX_SEGMENTS};
use crate::attitude::level;
use crate::conventions::{dcm_from_euler, wrap_pi, Euler};
use crate::earth::earth_rate_n;
use crate::probe_sample::GYRO_AXES;
use core::f64::consts::TAU;
use nalgebra::{Matrix3, Vector3};

pub(super) const GRID_POINTS: usize = 72;
/// Cells of the fine scan for a mirror minimum the grid merged (over four
/// grid steps: 0.05 deg each), and bisections that bring the root to
/// 0.05 deg / 2^40.
const MIRROR_SCAN_CELLS: usize = 400;
const MIRROR_BISECTIONS: usize = 40;
/// Golden-section steps that bring the bracket (one grid step either side)
/// to about 1e-4 rad, and Newton steps that take it from there to rounding
/// (the misfit is smooth, and quadratic near its minimum).
const GOLDEN_ITERATIONS: usize = 16;
const NEWTON_ITERATIONS: usize = 4;
/// Finite-difference step of the Newton iterations (rad).
const NEWTON_STEP: f64 = 1e-5;

/// The weighted misfit of a heading to the gyro means of all segments, with
/// the gyro biases (common to all segments, prior N(0, residual_bias^2))
/// solved for in closed form. As a function of heading it is a quadratic
/// form in (cos, sin), so it has at most two local minima.
pub(super) struct Misfit<'a> {
    pub(super) segments: &'a [StaticSegment],
    pub(super) config: &'a AlignmentConfig,
    /// C_b^n of each segment at heading 0 (levelled by its accelerometers).
    pub(super) levelled: [Matrix3<f64>; MAX_SEGMENTS],
    /// Weight (1/variance) of each segment's gyro means, per axis.
    pub(super) weights: [[f64; 3]; MAX_SEGMENTS],
}

impl<'a> Misfit<'a> {
    pub(super) fn new(
        segments: &'a [StaticSegment],
        config: &'a AlignmentConfig,
        sigmas: &MeanSigmas,
    ) -> Self {
        let mut levelled = [Matrix3::identity(); MAX_SEGMENTS];
        let mut weights = [[0.0; 3]; MAX_SEGMENTS];
        for (i, seg) in segments.iter().take(MAX_SEGMENTS).enumerate() {
            let lev = level(&seg.mean.specific_force);
            levelled[i] = dcm_from_euler(&Euler::new(lev.roll, lev.pitch, 0.0));
            let levelling = sigmas.levelling[i];
            for (weight, s) in weights[i].iter_mut().zip(sigmas.gyro[i]) {
                // A noise-free axis still gets a finite weight so the
                // misfit stays well defined.
                *weight = 1.0 / (s * s + levelling).max(1e-30);
            }
        }
        Self {
            segments,
            config,
            levelled,
            weights,
        }
    }

    pub(super) fn count(&self) -> usize {
        self.segments.len().min(MAX_SEGMENTS)
    }

    /// Predicted gyro means of segment i at a heading.
    fn predicted(&self, i: usize, heading: f64) -> Vector3<f64> {
        let (s, c) = (libm::sin(heading), libm::cos(heading));
        let rz = Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0);
        (rz * self.levelled[i]).transpose() * earth_rate_n(self.config.latitude)
    }

    /// Bias estimate of gyro `k` (about body axis `GYRO_AXES[k]`) at a
    /// heading, and the misfit it leaves.
    fn axis_fit(&self, k: usize, heading: f64) -> (f64, f64) {
        self.axis_fit_with(k, &self.all_predicted(heading))
    }

    /// Predicted gyro means of every segment at a heading (computed once
    /// per heading: the misfit of each axis reads them twice).
    fn all_predicted(&self, heading: f64) -> [Vector3<f64>; MAX_SEGMENTS] {
        let mut predicted = [Vector3::zeros(); MAX_SEGMENTS];
        for (i, p) in predicted.iter_mut().enumerate().take(self.count()) {
            *p = self.predicted(i, heading);
        }
        predicted
    }

    fn axis_fit_with(&self, k: usize, predicted: &[Vector3<f64>; MAX_SEGMENTS]) -> (f64, f64) {
        let axis = GYRO_AXES[k];
        let prior = self.config.noise.gyro[axis].residual_bias;
        let prior_weight = if prior > 0.0 {
            1.0 / (prior * prior)
        } else {
            f64::INFINITY
        };
        let residual = |i: usize| self.segments[i].mean.gyro[k] - predicted[i][axis];
        let (mut num, mut den) = (0.0, prior_weight);
        for i in 0..self.count() {
            num += self.weights[i][axis] * residual(i);
            den += self.weights[i][axis];
        }
        let bias = if den.is_finite() { num / den } else { 0.0 };
        let mut cost = if prior > 0.0 {
            bias * bias * prior_weight
        } else {
            0.0
        };
        for i in 0..self.count() {
            let r = residual(i) - bias;
            cost += self.weights[i][axis] * r * r;
        }
        (bias, cost)
    }

    pub(super) fn cost(&self, heading: f64) -> f64 {
        let predicted = self.all_predicted(heading);
        (0..GYRO_AXES.len())
            .map(|k| self.axis_fit_with(k, &predicted).1)
            .sum()
    }

    pub(super) fn biases(&self, heading: f64) -> Vector3<f64> {
        let mut b = Vector3::zeros();
        for (k, axis) in GYRO_AXES.into_iter().enumerate() {
            b[axis] = self.axis_fit(k, heading).0;
        }
        b
    }

    /// The misfit at the grid headings j 2 pi / [`GRID_POINTS`].
    pub(super) fn grid(&self) -> [f64; GRID_POINTS] {
        let step = TAU / GRID_POINTS as f64;
        let mut grid = [0.0; GRID_POINTS];
        for (j, g) in grid.iter_mut().enumerate() {
            *g = self.cost(j as f64 * step);
        }
        grid
    }

    /// The (at most two) local minima as (heading, misfit), best first.
    pub(super) fn local_minima(&self, grid: &[f64; GRID_POINTS]) -> [Option<(f64, f64)>; 2] {
        let step = TAU / GRID_POINTS as f64;
        let mut found: [Option<(f64, f64)>; 2] = [None, None];
        for j in 0..GRID_POINTS {
            let here = grid[j];
            let before = grid[(j + GRID_POINTS - 1) % GRID_POINTS];
            let after = grid[(j + 1) % GRID_POINTS];
            if !(here.is_finite() && here <= before && here < after) {
                continue;
            }
            let Some(h) = self.refine(j as f64 * step) else {
                continue;
            };
            let candidate = (h, self.cost(h));
            let duplicate = found
                .iter()
                .flatten()
                .any(|f| wrap_pi(f.0 - h).abs() < step);
            if duplicate {
                continue;
            }
            match found {
                [None, _] => found[0] = Some(candidate),
                [Some(a), None] if candidate.1 < a.1 => found = [Some(candidate), Some(a)],
                [Some(_), None] => found[1] = Some(candidate),
                [Some(a), Some(b)] => {
                    // More than two would contradict the quadratic form; keep
                    // the best two.
                    if candidate.1 < a.1 {
                        found = [Some(candidate), Some(a)];
                    } else if candidate.1 < b.1 {
                        found[1] = Some(candidate);
                    }
                }
            }
        }
        // Two minima closer than about a grid step share one grid minimum
        // (a level tool heading 89 deg: its mirror is at 91): look for the
        // other one next to the first.
        if let [Some(a), None] = found {
            if let Some(h) = self.merged_mirror(grid, a.0) {
                let candidate = (h, self.cost(h));
                found = if candidate.1 < a.1 {
                    [Some(candidate), Some(a)]
                } else {
                    [Some(a), Some(candidate)]
                };
            }
        }
        found
    }

    /// A second local minimum within two grid steps of the minimum at
    /// `found`, which the grid cannot tell apart from it. The misfit is a
    /// trigonometric polynomial of degree two in heading (a quadratic form
    /// in cos and sin), so the grid gives its five coefficients exactly
    /// (a discrete Fourier transform), and its slope is scanned finely
    /// ([`MIRROR_SCAN_CELLS`] cells, about 0.05 deg each) for a change from
    /// falling to rising away from `found`; that root is then bisected.
    /// Mirrors within about two cells of each other (0.1 deg) are not told
    /// apart. Costs no misfit evaluation: a few thousand flops.
    fn merged_mirror(&self, grid: &[f64; GRID_POINTS], found: f64) -> Option<f64> {
        if !grid.iter().all(|g| g.is_finite()) {
            return None;
        }
        let step = TAU / GRID_POINTS as f64;
        // cost(h) = c0 + c1 cos h + s1 sin h + c2 cos 2h + s2 sin 2h.
        let (mut c1, mut s1, mut c2, mut s2) = (0.0, 0.0, 0.0, 0.0);
        for (j, g) in grid.iter().enumerate() {
            let (sn, cs) = (libm::sin(j as f64 * step), libm::cos(j as f64 * step));
            c1 += g * cs;
            s1 += g * sn;
            c2 += g * (cs * cs - sn * sn);
            s2 += g * 2.0 * sn * cs;
        }
        let scale = 2.0 / GRID_POINTS as f64;
        let (c1, s1, c2, s2) = (c1 * scale, s1 * scale, c2 * scale, s2 * scale);
        let slope_at = |sn: f64, cs: f64| {
            -c1 * sn + s1 * cs - 2.0 * c2 * 2.0 * sn * cs + 2.0 * s2 * (cs * cs - sn * sn)
        };
        let slope = |h: f64| slope_at(libm::sin(h), libm::cos(h));
        let start = found - 2.0 * step;
        let cell = 4.0 * step / MIRROR_SCAN_CELLS as f64;
        // sin/cos of the scanned headings by rotation (no libm call per
        // cell: the probe computes in soft-float f64).
        let (rot_s, rot_c) = (libm::sin(cell), libm::cos(cell));
        let (mut sn, mut cs) = (libm::sin(start), libm::cos(start));
        let mut previous = slope_at(sn, cs);
        let mut best: Option<f64> = None;
        for k in 1..=MIRROR_SCAN_CELLS {
            (sn, cs) = (sn * rot_c + cs * rot_s, cs * rot_c - sn * rot_s);
            let here = slope_at(sn, cs);
            let h = start + k as f64 * cell;
            let far = wrap_pi(h - found).abs() > 2.0 * cell
                && wrap_pi(h - cell - found).abs() > 2.0 * cell;
            if previous < 0.0 && here >= 0.0 && far {
                let (mut lo, mut hi) = (h - cell, h);
                for _ in 0..MIRROR_BISECTIONS {
                    let mid = 0.5 * (lo + hi);
                    if slope(mid) < 0.0 {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                let root = 0.5 * (lo + hi);
                // The nearer of two would be the one the grid merged; at
                // most one more exists (two minima in all).
                if best.is_none_or(|b| wrap_pi(root - found).abs() < wrap_pi(b - found).abs()) {
                    best = Some(root);
                }
            }
            previous = here;
        }
        best
    }

    /// The minimum within one grid step of `start`: golden-section search,
    /// then Newton steps on finite differences, kept inside the bracket.
    pub(super) fn refine(&self, start: f64) -> Option<f64> {
        let span = TAU / GRID_POINTS as f64;
        let ratio = 0.618_033_988_749_894_8;
        let (mut a, mut b) = (start - span, start + span);
        let mut x1 = b - ratio * (b - a);
        let mut x2 = a + ratio * (b - a);
        let (mut f1, mut f2) = (self.cost(x1), self.cost(x2));
        for _ in 0..GOLDEN_ITERATIONS {
            if f1 < f2 {
                b = x2;
                x2 = x1;
                f2 = f1;
                x1 = b - ratio * (b - a);
                f1 = self.cost(x1);
            } else {
                a = x1;
                x1 = x2;
                f1 = f2;
                x2 = a + ratio * (b - a);
                f2 = self.cost(x2);
            }
        }
        let mut h = 0.5 * (a + b);
        for _ in 0..NEWTON_ITERATIONS {
            let (minus, here, plus) = (
                self.cost(h - NEWTON_STEP),
                self.cost(h),
                self.cost(h + NEWTON_STEP),
            );
            let slope = (plus - minus) / (2.0 * NEWTON_STEP);
            let curvature = (plus - 2.0 * here + minus) / (NEWTON_STEP * NEWTON_STEP);
            // Only a step towards a minimum, and never out of the bracket.
            let valid = curvature > 0.0; // false for NaN too
            if !valid {
                break;
            }
            // max/min rather than clamp: clamp's panic path formats floats,
            // which costs the probe 15 KiB of flash.
            let next = (h - slope / curvature).max(start - span).min(start + span);
            if next == h {
                break;
            }
            h = next;
        }
        h.is_finite().then_some(h)
    }
}
