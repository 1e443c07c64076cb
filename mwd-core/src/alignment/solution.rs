//! The coarse solution: levelling of a segment ([`level_segment`]), and
//! its heading by generalised gyrocompassing ([`gyrocompass`], the
//! product's default) or by the TRIAD ([`analytical`]), each with its
//! uncertainty.

use super::misfit::{Misfit, GRID_POINTS};
use super::segments::{
    check_all, check_segment, AlignmentConfig, AlignmentError, MeanSigmas, StaticSegment,
};
use super::uncertainty::{
    determined, half_width, heading_sigma, ill_conditioned, step_size, ALLOWED_CHI2,
    COVERAGE_FACTOR,
};
use crate::attitude::level;
use crate::conventions::{euler_from_dcm, wrap_pi};
use crate::earth::{earth_rate_n, EARTH_RATE};
use core::f64::consts::{PI, TAU};
use nalgebra::{Matrix3, Vector3};

/// A second heading candidate whose misfit exceeds the best one's by less
/// than this (chi-square, 1 degree of freedom, 99 %) explains the data as
/// well: the heading is ambiguous.
pub const AMBIGUITY_CHI2: f64 = 6.63;

/// A value with its 1-sigma uncertainty.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Uncertain {
    pub value: f64,
    pub sigma: f64,
}

/// Roll and pitch of one segment.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LevelEstimate {
    pub roll: Uncertain,
    pub pitch: Uncertain,
    /// False when the tool axis is near vertical and roll is undefined.
    pub roll_valid: bool,
}

/// A heading estimate and how far to trust it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HeadingEstimate {
    /// Heading (rad, in [-pi, pi)) and its 1-sigma.
    pub heading: Uncertain,
    /// The other candidate when the data cannot tell them apart.
    pub alternative: Option<f64>,
    /// True when `alternative` explains the data as well (and no prior, or a
    /// prior, chose between them).
    pub ambiguous: bool,
    /// True when the geometry makes heading insensitive to the earth rate
    /// anywhere among the headings the data allow (or at the prior).
    pub ill_conditioned: bool,
    /// False when sigma exceeds
    /// [`MAX_DETERMINED_SIGMA`](super::MAX_DETERMINED_SIGMA): the value is
    /// then no better than a guess.
    pub determined: bool,
    /// Estimated gyro biases (rad/s, body x y z; 0 for absent gyros).
    pub gyro_bias: Vector3<f64>,
}

impl HeadingEstimate {
    /// The half-width of the printed bound (rad): [`COVERAGE_FACTOR`] sigma,
    /// or pi when the heading is undetermined.
    pub fn bound(&self) -> f64 {
        if self.determined {
            (COVERAGE_FACTOR * self.heading.sigma).min(PI)
        } else {
            PI
        }
    }
}

/// Levelling (eq. 27-28) of one segment with its uncertainty.
pub fn level_segment(
    segment: &StaticSegment,
    config: &AlignmentConfig,
) -> Result<LevelEstimate, AlignmentError> {
    check_segment(segment)?;
    let lev = level(&segment.mean.specific_force);
    let mut var = [0.0; 2];
    for axis in 0..3 {
        let noise = &config.noise.accel[axis];
        let sigma = noise.mean_sigma(segment.samples, config.sample_interval);
        let total = sigma * sigma + noise.residual_bias * noise.residual_bias;
        let h = step_size(sigma, noise.residual_bias, 1e-6);
        let mut plus = segment.mean.specific_force;
        let mut minus = plus;
        plus[axis] += h;
        minus[axis] -= h;
        let (lp, lm) = (level(&plus), level(&minus));
        let d_roll = wrap_pi(lp.roll - lm.roll) / (2.0 * h);
        let d_pitch = (lp.pitch - lm.pitch) / (2.0 * h);
        var[0] += d_roll * d_roll * total;
        var[1] += d_pitch * d_pitch * total;
    }
    Ok(LevelEstimate {
        roll: Uncertain {
            value: lev.roll,
            sigma: libm::sqrt(var[0]),
        },
        pitch: Uncertain {
            value: lev.pitch,
            sigma: libm::sqrt(var[1]),
        },
        roll_valid: lev.roll_valid,
    })
}

/// Heading by generalised gyrocompassing (eq. 27-29) over one or more static
/// segments that share heading and pitch (toolface indexing).
pub fn gyrocompass(
    segments: &[StaticSegment],
    config: &AlignmentConfig,
) -> Result<HeadingEstimate, AlignmentError> {
    check_all(segments)?;
    let sigmas = MeanSigmas::new(segments, config);
    let model = Misfit::new(segments, config, &sigmas);
    let grid = model.grid();
    let [first, second] = model.local_minima(&grid);
    let (best, other) = match (first, second) {
        (Some(a), Some(b)) if b.1 - a.1 < AMBIGUITY_CHI2 => {
            // Ambiguous: a prior chooses, otherwise the lower misfit.
            let choose_b = config
                .heading_prior
                .is_some_and(|p| wrap_pi(b.0 - p).abs() < wrap_pi(a.0 - p).abs());
            if choose_b {
                (b, Some(a))
            } else {
                (a, Some(b))
            }
        }
        (Some(a), _) => (a, None),
        (None, _) => return Err(AlignmentError::NoHeadingInformation),
    };
    let heading = best.0;
    // Propagated through the estimator; near east/west the estimate sticks
    // where the measured rate exceeds what any heading explains and the
    // propagated derivative collapses, so the Cramer-Rao bound from the
    // expected information is the floor.
    let propagated = heading_sigma(segments, config, &sigmas, |perturbed| {
        Misfit::new(perturbed, config, &sigmas).refine(heading)
    });
    // Both are local: near east/west the misfit is far from quadratic in
    // heading, and noise that pulls the estimate away from east/west leaves
    // it where the local curvature is high but the misfit stays low all the
    // way to east/west (the local sigma there once printed 30 deg bounds
    // for errors of 60). The headings the data allow (the profile-likelihood
    // interval) are the honest measure, and their farther edge bounds the
    // printed interval from below. The grid of the search is reused, so
    // this costs some 20 misfit evaluations (of some 450).
    let allowed = model.allowed_interval(&grid, heading, best.1 + ALLOWED_CHI2);
    let sigma = propagated
        .max(model.cramer_rao_sigma(heading))
        .max(half_width(allowed) / COVERAGE_FACTOR);
    let sigma = sigma.max(model.expected_sigma_allowed(&grid, heading, best.1));
    // The other candidate, when ambiguous, is allowed as well.
    let other_allowed =
        other.map(|o| (o.0, model.allowed_interval(&grid, o.0, o.1 + ALLOWED_CHI2)));
    Ok(HeadingEstimate {
        heading: Uncertain {
            value: wrap_pi(heading),
            sigma,
        },
        alternative: other.map(|o| wrap_pi(o.0)),
        ambiguous: other.is_some(),
        ill_conditioned: ill_conditioned(&model, (heading, allowed), other_allowed, config),
        determined: determined(sigma),
        gyro_bias: model.biases(heading),
    })
}

/// Analytical alignment (eq. 30) of one segment: the TRIAD of gravity, earth
/// rate and their cross product. Without a tool-axis gyro the missing rate
/// is +-sqrt(Omega^2 - omega_x^2 - omega_z^2); both signs are candidates,
/// and the one nearer the prior (else the positive one) is returned, with
/// the other as the alternative.
pub fn analytical(
    segment: &StaticSegment,
    config: &AlignmentConfig,
) -> Result<HeadingEstimate, AlignmentError> {
    check_all(core::slice::from_ref(segment))?;
    let solve = |seg: &StaticSegment, sign: f64| triad_heading(seg, config, sign);
    let plus = solve(segment, 1.0);
    let minus = solve(segment, -1.0);
    let prefer_minus = config
        .heading_prior
        .is_some_and(|p| wrap_pi(minus - p).abs() < wrap_pi(plus - p).abs());
    let (chosen_sign, alternative) = if prefer_minus {
        (-1.0, Some(plus))
    } else {
        (1.0, Some(minus))
    };
    let heading = solve(segment, chosen_sign);
    let sigmas = MeanSigmas::new(core::slice::from_ref(segment), config);
    let sigma = if heading.is_finite() {
        heading_sigma(core::slice::from_ref(segment), config, &sigmas, |p| {
            p.first()
                .map(|s| solve(s, chosen_sign))
                .filter(|h| h.is_finite())
        })
    } else {
        f64::INFINITY
    };
    let model = Misfit::new(core::slice::from_ref(segment), config, &sigmas);
    // The headings the misfit allows around the result (those explaining
    // the gyro means about as well), as in [`gyrocompass`]: they bound the
    // locally propagated sigma from below and decide the flag. Without a
    // solution, around the misfit's best grid heading.
    let grid = model.grid();
    let centre = if heading.is_finite() {
        heading
    } else {
        let best = (0..GRID_POINTS).fold(0, |b, j| if grid[j] < grid[b] { j } else { b });
        best as f64 * TAU / GRID_POINTS as f64
    };
    let allowed = model.allowed_interval(&grid, centre, model.cost(centre) + ALLOWED_CHI2);
    // The two signs are distinct candidates when further apart than the
    // propagated sigma (the wider floor describes the data, not the signs).
    let ambiguous = alternative.is_some_and(|a| wrap_pi(a - heading).abs() > sigma);
    let sigma = sigma
        .max(half_width(allowed) / COVERAGE_FACTOR)
        .max(model.expected_sigma_allowed(&grid, centre, model.cost(centre)));
    Ok(HeadingEstimate {
        heading: Uncertain {
            value: if heading.is_finite() { heading } else { 0.0 },
            sigma,
        },
        alternative: alternative.filter(|a| a.is_finite()),
        ambiguous,
        ill_conditioned: ill_conditioned(&model, (centre, allowed), None, config),
        determined: determined(sigma),
        gyro_bias: Vector3::zeros(),
    })
}

fn triad_heading(segment: &StaticSegment, config: &AlignmentConfig, sign: f64) -> f64 {
    let (x, z) = (segment.mean.rate_x(), segment.mean.rate_z());
    let rest = EARTH_RATE * EARTH_RATE - x * x - z * z;
    if rest < 0.0 {
        // The measured cross-axis rates exceed the whole earth rate:
        // noise or bias dominates and the magnitude constraint has no
        // solution. No heading (the caller reports it undetermined).
        return f64::NAN;
    }
    let w_b = segment.mean.rate_with_tool_axis(sign * libm::sqrt(rest));
    let g_b = -segment.mean.specific_force;
    let g_n = Vector3::new(0.0, 0.0, g_b.norm());
    let w_n = earth_rate_n(config.latitude);
    // Orthonormal triads built from (g, g x w) in both frames: eq. 30's
    // rows [g; w; g x w] carry the same information, and orthonormalising
    // them keeps the result a rotation.
    let triad = |g: Vector3<f64>, w: Vector3<f64>| {
        let t1 = g.normalize();
        let t2 = g.cross(&w).normalize();
        Matrix3::from_columns(&[t1, t2, t1.cross(&t2)])
    };
    let c_bn = triad(g_n, w_n) * triad(g_b, w_b).transpose();
    euler_from_dcm(&c_bn).heading
}
