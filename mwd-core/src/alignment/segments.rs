//! What an alignment takes: static segments (the means of still samples
//! at one toolface, [`StaticSegment`], summed by [`SegmentSums`]), the
//! sigmas of those means from the noise budget, what it needs to know
//! besides ([`AlignmentConfig`]), and the checks that refuse them
//! ([`AlignmentError`]).

use crate::earth::EARTH_RATE;
use crate::probe_sample::ProbeSample;
use crate::sensor_noise::ImuNoise;
use crate::sensor_units::STANDARD_GRAVITY;
use nalgebra::Vector3;

/// Most segments one alignment takes (toolface positions).
pub const MAX_SEGMENTS: usize = 8;

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

pub(super) fn check_segment(segment: &StaticSegment) -> Result<(), AlignmentError> {
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

pub(super) fn check_all(segments: &[StaticSegment]) -> Result<(), AlignmentError> {
    if segments.is_empty() || segments.len() > MAX_SEGMENTS {
        return Err(AlignmentError::SegmentCount);
    }
    segments.iter().try_for_each(check_segment)
}

/// Standard deviations of each segment's means (white, coloured and
/// Gauss-Markov parts; see `AxisNoise::mean_sigma`), per axis. Computed
/// once per alignment: the coloured part solves a Lyapunov equation, far
/// too costly to repeat for every perturbed estimate on the probe.
#[derive(Clone, Copy, Debug)]
pub(super) struct MeanSigmas {
    pub(super) accel: [[f64; 3]; MAX_SEGMENTS],
    pub(super) gyro: [[f64; 3]; MAX_SEGMENTS],
    /// What each segment's levelling error adds to the variance of every
    /// predicted gyro mean ([`levelling_rate_variance`]; the misfit's
    /// weights take it).
    pub(super) levelling: [f64; MAX_SEGMENTS],
}

impl MeanSigmas {
    pub(super) fn new(segments: &[StaticSegment], config: &AlignmentConfig) -> Self {
        let mut table = Self {
            accel: [[0.0; 3]; MAX_SEGMENTS],
            gyro: [[0.0; 3]; MAX_SEGMENTS],
            levelling: [0.0; MAX_SEGMENTS],
        };
        let dt = config.sample_interval;
        for (i, seg) in segments.iter().take(MAX_SEGMENTS).enumerate() {
            for axis in 0..3 {
                table.accel[i][axis] = config.noise.accel[axis].mean_sigma(seg.samples, dt);
                table.gyro[i][axis] = config.noise.gyro[axis].mean_sigma(seg.samples, dt);
            }
            table.levelling[i] = levelling_rate_variance(config, &table.accel[i]);
        }
        table
    }
}

/// The variance (rad/s)^2 a segment's levelling error puts on each
/// predicted gyro mean. The prediction resolves the earth rate through
/// the levelled attitude, whose tilt is off by the accelerometers' error
/// over g (the residual bias and the mean's noise, the larger axis's), and
/// a tilt delta moves each predicted rate by at most EARTH_RATE delta per
/// tilt axis. The heading's sigma already carries this through the
/// accelerometer inputs (`heading_sigma`); the misfit's weights did not, so
/// a quiet gyro (a navigation grade's 300 s mean is known to ~0.007 deg/h,
/// while a 1 mg bias's tilt moves it by up to 0.015 deg/h) read a tilt
/// error as heading information: a horizontal tool's two mirror headings,
/// which only the unknown tilt tells apart, were called unambiguous and the
/// wrong one printed with a 0.075 deg sigma (`host-sim study indexing`, the
/// navigation grade, 1 run in 20), and near east or west the allowed
/// interval was too narrow. For the SCC1300 it is 5e-5 of the noise's.
fn levelling_rate_variance(config: &AlignmentConfig, accel_mean_sigma: &[f64; 3]) -> f64 {
    let tilt_variance = config
        .noise
        .accel
        .iter()
        .zip(accel_mean_sigma)
        .map(|(axis, mean)| axis.residual_bias * axis.residual_bias + mean * mean)
        .fold(0.0, f64::max)
        / (STANDARD_GRAVITY * STANDARD_GRAVITY);
    2.0 * EARTH_RATE * EARTH_RATE * tilt_variance
}
