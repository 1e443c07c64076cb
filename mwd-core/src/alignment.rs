//! Coarse alignment of a tool at rest (paper section 3.2.3): levelling from
//! averaged accelerometers, then heading from the earth rate the gyros see,
//! adapted to the probe's gyros (body x and z only).
//!
//! Physics the results respect, by design: with gyros across
//! the tool axis, the heading signal is mainly the cross-axis earth rate
//! Omega cos(lat) sin(heading), plus a pitch-dependent share of the
//! along-axis component. Heading is well determined for a tool heading north
//! or south (where the two candidates psi and 180 deg - psi explain the data
//! alike unless the tool is pitched: the north/south ambiguity, resolved from
//! a prior) and badly determined heading east or west. Gyro bias is
//! comparable with the earth rate, so a single position's heading is
//! bias-limited; toolface indexing (segments at different roll) reverses
//! the cross-axis gyros and lets the estimator separate bias from earth rate.
//!
//! Two methods:
//! * [`gyrocompass`]: eq. 27-29 generalised. Levelling per segment
//!   (eq. 27-28), then the heading that best explains the gyro means of all
//!   segments (eq. 29's tan psi = -omega_x / omega_y is its closed form for a
//!   level tool with a forward gyro), with gyro biases common to all segments
//!   estimated under their prior. The product's default.
//! * [`analytical`]: eq. 30, the TRIAD of gravity, earth rate and their cross
//!   product, with the unmeasured tool-axis rate reconstructed from the
//!   earth-rate magnitude (two signs: the north/south ambiguity).
//!
//! Every heading carries its 1-sigma uncertainty from the sensor error
//! budget ([`ImuNoise`]), propagated through the estimator by central
//! differences, and flags for ill-conditioning and ambiguity. The local
//! (linearised) sigma is only a floor: near east/west the misfit is far
//! from quadratic in heading, so the printed bound also covers every
//! heading the data allow (the profile-likelihood interval: misfit within
//! [`COVERAGE_FACTOR`]^2 of the estimate's), and the ill-conditioning flag
//! is raised when the geometry is weak anywhere in that interval, not only
//! at the estimate, which noise can pull away from east/west.
use crate::attitude::level;
use crate::conventions::{dcm_from_euler, euler_from_dcm, wrap_pi, Euler, DEG};
use crate::earth::{earth_rate_n, EARTH_RATE};
use crate::probe_sample::{ProbeSample, GYRO_AXES};
use crate::sensor_noise::ImuNoise;
use core::f64::consts::{PI, TAU};
use nalgebra::{Matrix3, Vector3};

/// Most segments one alignment takes (toolface positions).
pub const MAX_SEGMENTS: usize = 8;
/// Heading is ill-conditioned when the earth-rate signal changes with
/// heading by less than this fraction of the horizontal earth rate
/// Omega cos(lat): gyro errors are then magnified more than about three
/// times (for a horizontal tool: within about 17 deg of east or west).
pub const ILL_CONDITIONED_SENSITIVITY: f64 = 0.3;
/// Beyond this 1-sigma (rad) the heading is reported as undetermined: the
/// headings the data allow span more than 2 x 40 deg, or the linearised
/// uncertainty no longer describes the error.
pub const MAX_DETERMINED_SIGMA: f64 = 20.0 * DEG;
/// A second heading candidate whose misfit exceeds the best one's by less
/// than this (chi-square, 1 degree of freedom, 99 %) explains the data as
/// well: the heading is ambiguous.
pub const AMBIGUITY_CHI2: f64 = 6.63;
/// Coverage factor of the printed bounds: 2 sigma, about 95 %.
pub const COVERAGE_FACTOR: f64 = 2.0;

/// The headings the data allow: the connected set around an estimate
/// whose misfit exceeds the estimate's by at most this (chi-square, 1
/// degree of freedom: the profile-likelihood interval at the printed
/// coverage, [`COVERAGE_FACTOR`] sigma).
const ALLOWED_CHI2: f64 = COVERAGE_FACTOR * COVERAGE_FACTOR;
/// Bisection steps that place an edge of the allowed interval within a
/// grid step / 2^10 (0.005 deg).
const EDGE_ITERATIONS: usize = 10;

/// The headings the data allow at 3 sigma (chi-square, 1 degree of
/// freedom, 99.7 %): where the expected sigma is checked.
const WIDE_ALLOWED_CHI2: f64 = 9.0;

const GRID_POINTS: usize = 72;
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

/// Means of one static segment (one toolface position).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StaticSegment {
    /// Mean gyro rates and specific force.
    pub mean: ProbeSample,
    /// Number of samples averaged.
    pub samples: usize,
}

/// Running sums of still samples, for their [`StaticSegment`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SegmentSums {
    gyro: [f64; 2],
    specific_force: Vector3<f64>,
    samples: usize,
}

impl SegmentSums {
    pub fn add(&mut self, sample: &ProbeSample) {
        self.gyro[0] += sample.gyro[0];
        self.gyro[1] += sample.gyro[1];
        self.specific_force += sample.specific_force;
        self.samples += 1;
    }

    pub fn samples(&self) -> usize {
        self.samples
    }

    /// The means (a segment of no samples, which the alignment rejects,
    /// when nothing was added).
    pub fn segment(&self) -> StaticSegment {
        let n = self.samples.max(1) as f64;
        StaticSegment {
            mean: ProbeSample {
                gyro: self.gyro.map(|sum| sum / n),
                specific_force: self.specific_force / n,
            },
            samples: self.samples,
        }
    }
}

/// What the alignment needs to know besides the data.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AlignmentConfig {
    /// Latitude of the site (rad).
    pub latitude: f64,
    /// Sample interval (s).
    pub sample_interval: f64,
    /// The sensors' error budget.
    pub noise: ImuNoise,
    /// A heading known roughly (e.g. the parent well's survey), used only to
    /// choose between ambiguous candidates.
    pub heading_prior: Option<f64>,
}

impl AlignmentConfig {
    /// The probe's coarse alignment at `latitude` (rad): 20 Hz samples,
    /// the SCC1300's error budget, no heading prior. The probe and the host's tools all start from this.
    pub fn probe(latitude: f64) -> Self {
        Self {
            latitude,
            sample_interval: crate::timing::SAMPLE_INTERVAL_S,
            noise: ImuNoise::scc1300(),
            heading_prior: None,
        }
    }

    /// The same with a rough heading (rad) to choose between ambiguous
    /// candidates.
    pub fn with_heading_prior(self, heading_prior: Option<f64>) -> Self {
        Self {
            heading_prior,
            ..self
        }
    }
}

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
    /// False when sigma exceeds [`MAX_DETERMINED_SIGMA`]: the value is then
    /// no better than a guess.
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

/// Why an alignment could not be computed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AlignmentError {
    /// No segment, or more than [`MAX_SEGMENTS`].
    SegmentCount,
    /// A mean is NaN or infinite, or a segment has no samples.
    InvalidData,
    /// The specific force is far from gravity: the tool is not at rest.
    NotStatic,
    /// The misfit does not change with heading: the gyros see no horizontal
    /// earth rate (at a pole, or with a single gyro along the vertical).
    NoHeadingInformation,
}

impl core::fmt::Display for AlignmentError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::SegmentCount => write!(
                f,
                "an alignment takes 1 to {MAX_SEGMENTS} static segments (toolface positions)"
            ),
            Self::InvalidData => {
                f.write_str("a static segment has no samples, or its mean is not a finite number")
            }
            Self::NotStatic => f.write_str(
                "the measured specific force is far from gravity: the tool is not at rest",
            ),
            Self::NoHeadingInformation => f.write_str(
                "the gyros see no horizontal earth rate (at a pole, or with a single \
                 vertical gyro), so the heading cannot be determined",
            ),
        }
    }
}

impl core::error::Error for AlignmentError {}

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

/// The headings the data allow around an estimate: the distances (rad) to
/// the lower and upper edge of the interval, None when it is the whole
/// circle.
type Allowed = Option<(f64, f64)>;

/// The larger distance from the estimate to an edge of its allowed
/// interval (pi for the whole circle).
fn half_width(allowed: Allowed) -> f64 {
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
fn ill_conditioned(
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
fn determined(sigma: f64) -> bool {
    sigma.is_finite() && sigma <= MAX_DETERMINED_SIGMA
}

fn check_segment(segment: &StaticSegment) -> Result<(), AlignmentError> {
    if !segment.mean.is_finite() || segment.samples == 0 {
        return Err(AlignmentError::InvalidData);
    }
    // At rest the specific force is gravity (about 9.8 m/s^2 anywhere on
    // earth); 20 % off means the tool moved or a sensor failed.
    let f = segment.mean.specific_force.norm();
    if !(7.8..=11.8).contains(&f) {
        return Err(AlignmentError::NotStatic);
    }
    Ok(())
}

fn check_all(segments: &[StaticSegment]) -> Result<(), AlignmentError> {
    if segments.is_empty() || segments.len() > MAX_SEGMENTS {
        return Err(AlignmentError::SegmentCount);
    }
    segments.iter().try_for_each(check_segment)
}

/// Finite-difference step for an input of standard deviations `a` and `b`.
fn step_size(a: f64, b: f64, floor: f64) -> f64 {
    let s = libm::sqrt(a * a + b * b);
    if s.is_finite() && s > 0.0 {
        (1e-3 * s).max(floor * 1e-6)
    } else {
        floor
    }
}

/// Standard deviations of each segment's means (white, coloured and
/// Gauss-Markov parts; see `AxisNoise::mean_sigma`), per axis. Computed
/// once per alignment: the coloured part solves a Lyapunov equation, far
/// too costly to repeat for every perturbed estimate on the probe.
#[derive(Clone, Copy, Debug)]
struct MeanSigmas {
    accel: [[f64; 3]; MAX_SEGMENTS],
    gyro: [[f64; 3]; MAX_SEGMENTS],
}

impl MeanSigmas {
    fn new(segments: &[StaticSegment], config: &AlignmentConfig) -> Self {
        let mut table = Self {
            accel: [[0.0; 3]; MAX_SEGMENTS],
            gyro: [[0.0; 3]; MAX_SEGMENTS],
        };
        let dt = config.sample_interval;
        for (i, seg) in segments.iter().take(MAX_SEGMENTS).enumerate() {
            for axis in 0..3 {
                table.accel[i][axis] = config.noise.accel[axis].mean_sigma(seg.samples, dt);
                table.gyro[i][axis] = config.noise.gyro[axis].mean_sigma(seg.samples, dt);
            }
        }
        table
    }
}

/// 1-sigma of a heading function of the segments' means, by central
/// differences: independent noise of each segment's means plus the residual
/// biases, which are common to all segments.
fn heading_sigma<F>(
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

/// The weighted misfit of a heading to the gyro means of all segments, with
/// the gyro biases (common to all segments, prior N(0, residual_bias^2))
/// solved for in closed form. As a function of heading it is a quadratic
/// form in (cos, sin), so it has at most two local minima.
struct Misfit<'a> {
    segments: &'a [StaticSegment],
    config: &'a AlignmentConfig,
    /// C_b^n of each segment at heading 0 (levelled by its accelerometers).
    levelled: [Matrix3<f64>; MAX_SEGMENTS],
    /// Weight (1/variance) of each segment's gyro means, per axis.
    weights: [[f64; 3]; MAX_SEGMENTS],
}

impl<'a> Misfit<'a> {
    fn new(
        segments: &'a [StaticSegment],
        config: &'a AlignmentConfig,
        sigmas: &MeanSigmas,
    ) -> Self {
        let mut levelled = [Matrix3::identity(); MAX_SEGMENTS];
        let mut weights = [[0.0; 3]; MAX_SEGMENTS];
        for (i, seg) in segments.iter().take(MAX_SEGMENTS).enumerate() {
            let lev = level(&seg.mean.specific_force);
            levelled[i] = dcm_from_euler(&Euler::new(lev.roll, lev.pitch, 0.0));
            for (weight, s) in weights[i].iter_mut().zip(sigmas.gyro[i]) {
                // A noise-free axis still gets a finite weight so the
                // misfit stays well defined.
                *weight = 1.0 / (s * s).max(1e-30);
            }
        }
        Self {
            segments,
            config,
            levelled,
            weights,
        }
    }

    fn count(&self) -> usize {
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

    fn cost(&self, heading: f64) -> f64 {
        let predicted = self.all_predicted(heading);
        (0..GYRO_AXES.len())
            .map(|k| self.axis_fit_with(k, &predicted).1)
            .sum()
    }

    fn biases(&self, heading: f64) -> Vector3<f64> {
        let mut b = Vector3::zeros();
        for (k, axis) in GYRO_AXES.into_iter().enumerate() {
            b[axis] = self.axis_fit(k, heading).0;
        }
        b
    }

    /// The misfit at the grid headings j 2 pi / [`GRID_POINTS`].
    fn grid(&self) -> [f64; GRID_POINTS] {
        let step = TAU / GRID_POINTS as f64;
        let mut grid = [0.0; GRID_POINTS];
        for (j, g) in grid.iter_mut().enumerate() {
            *g = self.cost(j as f64 * step);
        }
        grid
    }

    /// The (at most two) local minima as (heading, misfit), best first.
    fn local_minima(&self, grid: &[f64; GRID_POINTS]) -> [Option<(f64, f64)>; 2] {
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
    fn refine(&self, start: f64) -> Option<f64> {
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

    /// The connected interval around `centre` where the misfit stays within
    /// `threshold`: walked along the grid in both directions to the first
    /// grid heading beyond it, and the crossing then bisected (the outer end
    /// kept, so the interval errs on the wide side). The misfit is a
    /// trigonometric polynomial of degree two in heading, so it cannot dip
    /// below the threshold and out again between grid headings 5 deg apart
    /// by more than rounding.
    fn allowed_interval(&self, grid: &[f64; GRID_POINTS], centre: f64, threshold: f64) -> Allowed {
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
    fn expected_sigma_allowed(&self, grid: &[f64; GRID_POINTS], centre: f64, misfit: f64) -> f64 {
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
    fn cramer_rao_sigma(&self, heading: f64) -> f64 {
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
    fn sensitivity(&self, heading: f64) -> f64 {
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

#[cfg(test)]
mod tests;
