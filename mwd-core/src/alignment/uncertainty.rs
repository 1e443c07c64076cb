//! How far to trust a heading: its sigma propagated through the estimator
//! ([`heading_sigma`]), its Cramer-Rao bound, the headings the data allow
//! (the profile-likelihood interval of the misfit), and the flags for
//! ill-conditioning and for a heading that is determined.

use super::misfit::{Misfit, GRID_POINTS};
use super::segments::{AlignmentConfig, MeanSigmas, StaticSegment, MAX_SEGMENTS};
use crate::conventions::{wrap_pi, DEG};
use crate::earth::{earth_rate_n, EARTH_RATE};
use crate::probe_sample::{ProbeSample, GYRO_AXES};
use core::f64::consts::{PI, TAU};
use nalgebra::{Matrix3, Vector3};

/// Heading is ill-conditioned when the earth-rate signal changes with
/// heading by less than this fraction of the horizontal earth rate
/// Omega cos(lat): gyro errors are then magnified more than about three
/// times (for a horizontal tool: within about 17 deg of east or west).
pub const ILL_CONDITIONED_SENSITIVITY: f64 = 0.3;
/// Beyond this 1-sigma (rad) the heading is reported as undetermined: the
/// headings the data allow span more than 2 x 40 deg, or the linearised
/// uncertainty no longer describes the error.
pub const MAX_DETERMINED_SIGMA: f64 = 20.0 * DEG;
/// Coverage factor of the printed bounds: 2 sigma, about 95 %.
pub const COVERAGE_FACTOR: f64 = 2.0;

/// The headings the data allow: the connected set around an estimate
/// whose misfit exceeds the estimate's by at most this (chi-square, 1
/// degree of freedom: the profile-likelihood interval at the printed
/// coverage, [`COVERAGE_FACTOR`] sigma).
pub(super) const ALLOWED_CHI2: f64 = COVERAGE_FACTOR * COVERAGE_FACTOR;
/// Bisection steps that place an edge of the allowed interval within a
/// grid step / 2^10 (0.005 deg).
const EDGE_ITERATIONS: usize = 10;

/// The headings the data allow at 3 sigma (chi-square, 1 degree of
/// freedom, 99.7 %): where the expected sigma is checked.
const WIDE_ALLOWED_CHI2: f64 = 9.0;

/// The headings the data allow around an estimate: the distances (rad) to
/// the lower and upper edge of the interval, None when it is the whole
/// circle.
pub(super) type Allowed = Option<(f64, f64)>;

/// The larger distance from the estimate to an edge of its allowed
/// interval (pi for the whole circle).
pub(super) fn half_width(allowed: Allowed) -> f64 {
    allowed.map_or(PI, |(below, above)| below.max(above).min(PI))
}

/// Ill-conditioned when the geometry is weak anywhere in the headings the
/// data allow: with noise the estimate of a tool heading east may land well
/// away from east, but east is still among the headings the data allow
/// and the geometry is still the weak one. Checked over the estimate's
/// allowed interval and, when ambiguous, the other candidate's (the north/
/// south pair), and at the prior (the well plan's azimuth, say). When the
/// data allow every heading (the heading is undetermined, its bound pi),
/// the interval says nothing about the geometry: the candidates themselves
/// are checked.
pub(super) fn ill_conditioned(
    model: &Misfit,
    estimate: (f64, Allowed),
    other: Option<(f64, Allowed)>,
    config: &AlignmentConfig,
) -> bool {
    let weak = |h: f64| model.sensitivity(h) < ILL_CONDITIONED_SENSITIVITY;
    let weak_around = |(centre, allowed): (f64, Allowed)| match allowed {
        Some((below, above)) => model.weak_between(centre - below, centre + above),
        None => weak(centre),
    };
    weak_around(estimate)
        || other.is_some_and(weak_around)
        || config.heading_prior.is_some_and(weak)
}

/// Determined when the sigma (which covers the expected sigma of every
/// heading the data allow, see `Misfit::expected_sigma_allowed`) is
/// within [`MAX_DETERMINED_SIGMA`].
pub(super) fn determined(sigma: f64) -> bool {
    sigma.is_finite() && sigma <= MAX_DETERMINED_SIGMA
}

/// Finite-difference step for an input of standard deviations `a` and `b`.
pub(super) fn step_size(a: f64, b: f64, floor: f64) -> f64 {
    let s = libm::sqrt(a * a + b * b);
    if s.is_finite() && s > 0.0 {
        (1e-3 * s).max(floor * 1e-6)
    } else {
        floor
    }
}

/// 1-sigma of a heading function of the segments' means, by central
/// differences: independent noise of each segment's means plus the residual
/// biases, which are common to all segments.
pub(super) fn heading_sigma<F>(
    segments: &[StaticSegment],
    config: &AlignmentConfig,
    sigmas: &MeanSigmas,
    estimate: F,
) -> f64
where
    F: Fn(&[StaticSegment]) -> Option<f64>,
{
    let mut work = [StaticSegment {
        mean: ProbeSample::default(),
        samples: 1,
    }; MAX_SEGMENTS];
    let n = segments.len().min(MAX_SEGMENTS);
    work[..n].copy_from_slice(&segments[..n]);
    let mut variance = 0.0;
    // Inputs: 0..3 accelerometer axes, 3..6 rate axes.
    for input in 0..6 {
        let (axis, is_gyro) = (input % 3, input >= 3);
        let gyro = GYRO_AXES.iter().position(|&a| a == axis);
        if is_gyro && gyro.is_none() {
            continue;
        }
        let noise = if is_gyro {
            &config.noise.gyro[axis]
        } else {
            &config.noise.accel[axis]
        };
        let floor = if is_gyro { 1e-9 } else { 1e-6 };
        let mut common_derivative = 0.0;
        for i in 0..n {
            let sigma = if is_gyro {
                sigmas.gyro[i][axis]
            } else {
                sigmas.accel[i][axis]
            };
            if !sigma.is_finite() {
                return f64::INFINITY;
            }
            let h = step_size(sigma, noise.residual_bias, floor);
            let original = work[i];
            let mut shifted = |delta: f64| {
                let mean = &mut work[i].mean;
                match gyro {
                    Some(k) if is_gyro => mean.gyro[k] += delta,
                    _ => mean.specific_force[axis] += delta,
                }
                let value = estimate(&work[..n]);
                work[i] = original;
                value
            };
            let (Some(up), Some(down)) = (shifted(h), shifted(-h)) else {
                return f64::INFINITY;
            };
            let derivative = wrap_pi(up - down) / (2.0 * h);
            variance += derivative * derivative * sigma * sigma;
            common_derivative += derivative;
        }
        variance +=
            common_derivative * common_derivative * noise.residual_bias * noise.residual_bias;
    }
    libm::sqrt(variance)
}

impl Misfit<'_> {
    /// The connected interval around `centre` where the misfit stays within
    /// `threshold`: walked along the grid in both directions to the first
    /// grid heading beyond it, and the crossing then bisected (the outer end
    /// kept, so the interval errs on the wide side). The misfit is a
    /// trigonometric polynomial of degree two in heading, so it cannot dip
    /// below the threshold and out again between grid headings 5 deg apart
    /// by more than rounding.
    pub(super) fn allowed_interval(
        &self,
        grid: &[f64; GRID_POINTS],
        centre: f64,
        threshold: f64,
    ) -> Allowed {
        let step = TAU / GRID_POINTS as f64;
        let mut c = wrap_pi(centre);
        if c < 0.0 {
            c += TAU;
        }
        // The grid heading at or below the centre.
        let j0 = ((c / step) as usize).min(GRID_POINTS - 1);
        let inside = |h: f64| self.cost(h) <= threshold; // false for NaN
        let edge = |up: bool| -> Option<f64> {
            let mut last_inside = 0.0;
            for m in 0..GRID_POINTS {
                let (index, offset) = if up {
                    let j = j0 + 1 + m;
                    (j % GRID_POINTS, j as f64 * step - c)
                } else {
                    let j = j0 as f64 - m as f64;
                    ((j0 + GRID_POINTS - m) % GRID_POINTS, c - j * step)
                };
                if grid[index] <= threshold {
                    last_inside = offset;
                    continue;
                }
                let sign = if up { 1.0 } else { -1.0 };
                let (mut lo, mut hi) = (last_inside, offset);
                for _ in 0..EDGE_ITERATIONS {
                    let mid = 0.5 * (lo + hi);
                    if inside(centre + sign * mid) {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                return Some(hi);
            }
            None
        };
        let above = edge(true)?;
        let below = edge(false)?;
        (below + above < TAU).then_some((below, above))
    }

    /// True when the geometry is weak (sensitivity below
    /// [`ILL_CONDITIONED_SENSITIVITY`]) anywhere from `lo` to `hi` (rad,
    /// lo <= hi, less than a turn apart), checked at both ends and at most
    /// a grid step apart between: the weak zones are about 35 deg wide
    /// (seven grid steps) for a horizontal tool; only a zone whose least
    /// sensitivity is barely below the threshold is narrower than a step,
    /// and may be missed.
    fn weak_between(&self, lo: f64, hi: f64) -> bool {
        let step = TAU / GRID_POINTS as f64;
        let span = (hi - lo).max(0.0);
        let n = (libm::ceil(span / step) as usize).min(GRID_POINTS);
        (0..=n).any(|t| {
            let h = if n == 0 {
                lo
            } else {
                lo + span * t as f64 / n as f64
            };
            self.sensitivity(h) < ILL_CONDITIONED_SENSITIVITY
        })
    }

    /// The largest Cramer-Rao sigma from `lo` to `hi` (rad, lo <= hi, less
    /// than a turn apart), sampled as [`Self::weak_between`] samples the
    /// sensitivity (both ends and at most a grid step apart).
    fn largest_cramer_rao_sigma(&self, lo: f64, hi: f64) -> f64 {
        let step = TAU / GRID_POINTS as f64;
        let span = (hi - lo).max(0.0);
        let n = (libm::ceil(span / step) as usize).min(GRID_POINTS);
        (0..=n)
            .map(|t| {
                if n == 0 {
                    lo
                } else {
                    lo + span * t as f64 / n as f64
                }
            })
            .map(|h| self.cramer_rao_sigma(h))
            // NaN counts as the worst.
            .fold(0.0, |worst: f64, s| {
                if s.is_nan() {
                    f64::INFINITY
                } else {
                    worst.max(s)
                }
            })
    }

    /// The largest expected (Cramer-Rao) sigma among the headings the
    /// data allow at [`WIDE_ALLOWED_CHI2`] around `centre` (whose misfit
    /// is `misfit`): pi / 3 when they are the whole circle. The truth is
    /// among them in all but 0.3 % of runs, so a sigma at least this large
    /// is at least the truth's own. Without it, where the geometry weakens
    /// towards east/west, a noise draw that lands the estimate in better
    /// geometry and makes the misfit look sharp gave a sigma just under the
    /// limit of a determined heading, and among those runs, selected for
    /// looking sharp, the 2-sigma bound covered only 74 % of the errors
    ///.
    pub(super) fn expected_sigma_allowed(
        &self,
        grid: &[f64; GRID_POINTS],
        centre: f64,
        misfit: f64,
    ) -> f64 {
        match self.allowed_interval(grid, centre, misfit + WIDE_ALLOWED_CHI2) {
            Some((below, above)) => self.largest_cramer_rao_sigma(centre - below, centre + above),
            // Every heading allowed at 3 sigma: at least a third of a
            // half turn, so undetermined (finite: the data still exist).
            None => PI / 3.0,
        }
    }

    /// Rate of change with heading of the predicted gyro means of segment
    /// i (exact: the derivative of the heading rotation).
    fn predicted_slope(&self, i: usize, heading: f64) -> Vector3<f64> {
        let (s, c) = (libm::sin(heading), libm::cos(heading));
        let drz = Matrix3::new(-s, -c, 0.0, c, -s, 0.0, 0.0, 0.0, 0.0);
        (drz * self.levelled[i]).transpose() * earth_rate_n(self.config.latitude)
    }

    /// The Cramer-Rao bound of the heading: 1/sqrt of the expected
    /// information of the gyro means with the biases profiled out (per
    /// axis: sum w d^2 - (sum w d)^2 / (sum w + w_bias), d the derivative
    /// of the predicted rate with heading).
    pub(super) fn cramer_rao_sigma(&self, heading: f64) -> f64 {
        let mut information = 0.0;
        for axis in GYRO_AXES {
            let prior = self.config.noise.gyro[axis].residual_bias;
            let prior_weight = if prior > 0.0 {
                1.0 / (prior * prior)
            } else {
                f64::INFINITY
            };
            let (mut wdd, mut wd, mut w) = (0.0, 0.0, 0.0);
            for i in 0..self.count() {
                let d = self.predicted_slope(i, heading)[axis];
                let wi = self.weights[i][axis];
                wdd += wi * d * d;
                wd += wi * d;
                w += wi;
            }
            let profiled = if prior_weight.is_finite() {
                wd * wd / (w + prior_weight)
            } else {
                0.0
            };
            information += (wdd - profiled).max(0.0);
        }
        if information > 0.0 {
            1.0 / libm::sqrt(information)
        } else {
            f64::INFINITY
        }
    }

    /// How strongly the gyro signal changes with heading, as a fraction of
    /// the horizontal earth rate (per segment, root-mean-square over
    /// segments).
    pub(super) fn sensitivity(&self, heading: f64) -> f64 {
        let horizontal = EARTH_RATE * libm::cos(self.config.latitude);
        // Within 0.06 deg of a pole there is no horizontal earth rate to
        // speak of (and the ratio below would divide rounding noise).
        if self.count() == 0 || horizontal <= 1e-3 * EARTH_RATE {
            return 0.0;
        }
        let mut sum = 0.0;
        for i in 0..self.count() {
            let d = self.predicted_slope(i, heading);
            for axis in GYRO_AXES {
                sum += d[axis] * d[axis];
            }
        }
        libm::sqrt(sum / self.count() as f64) / horizontal
    }
}
