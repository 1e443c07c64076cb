//! Helpers for the probe's unit tests (compiled for tests only).

use super::Navigator;
use crate::conventions::{dcm_from_euler, Euler};
use crate::earth::{earth_rate_n, Position};
use crate::probe_sample::ProbeSample;
use crate::protocol::frame::raw_flags;
use crate::protocol::{RawPart, RawSample};
use crate::sensor_noise::ImuNoise;
use crate::sensor_units::{
    m_s2_to_accel_count, rad_s_to_gyro_count, PART_MOUNTINGS, STANDARD_GRAVITY,
    STANDARD_GRAVITY_M_S2,
};
use crate::timing::{sample_time_us, ALIGNMENT_SAMPLES, FINE_ALIGNMENT_SAMPLES};
use nalgebra::Vector3;

/// Samples from power-on to the end of the fine alignment.
pub(crate) const ALL_ALIGNMENT: u32 = ALIGNMENT_SAMPLES + FINE_ALIGNMENT_SAMPLES;

/// Raw sample `n` of a still probe feeling `force` (body axes, m/s^2) on
/// both parts, no rotation (the hil-mock generator's static probe, which
/// has no earth rate).
pub(crate) fn still_sample(n: u32, force: [f32; 3]) -> RawSample {
    turning_sample(n, force, [0.0; 3])
}

/// Raw sample `n` of a probe feeling `force` and turning at `rate` (both
/// in body axes: m/s^2, rad/s) on both parts.
pub(crate) fn turning_sample(n: u32, force: [f32; 3], rate: [f32; 3]) -> RawSample {
    let parts = PART_MOUNTINGS.map(|mounting| RawPart {
        accel: mounting.body_to_sensor(force).map(m_s2_to_accel_count),
        gyro_rate: rad_s_to_gyro_count(mounting.gyro_rate_from_body(rate)),
        flags: raw_flags::GYRO_VALID | raw_flags::ACCEL_VALID,
        ..RawPart::default()
    });
    RawSample {
        time_us: u64::from(n) * 50_000,
        sample_counter: n,
        parts,
    }
}

/// Level: gravity's reaction on body +z.
pub(crate) fn level_sample(n: u32) -> RawSample {
    still_sample(n, [0.0, 0.0, STANDARD_GRAVITY_M_S2])
}

/// A level probe turning about body z (up) at `deg_s`, sample `n`.
pub(crate) fn level_turning_sample(n: u32, deg_s: f32) -> RawSample {
    turning_sample(
        n,
        [0.0, 0.0, STANDARD_GRAVITY_M_S2],
        [0.0, 0.0, deg_s.to_radians()],
    )
}

/// Sample `n` (time, counter, calibrated sample) of an error-free tool at
/// `attitude` at the paper's site, at full resolution: the earth's rate
/// plus `turn_n` (NED, rad/s) and gravity's reaction, in body axes (over
/// the minutes of a test a turn's heading change is left out of the
/// earth rate's projection).
pub(crate) fn earth_rate_sample(
    n: u32,
    attitude: &Euler,
    turn_n: Vector3<f64>,
) -> (u64, u32, ProbeSample) {
    let c_nb = dcm_from_euler(attitude).transpose();
    let rate = c_nb * (earth_rate_n(Position::paper_site().lat) + turn_n);
    let force = c_nb * Vector3::new(0.0, 0.0, -STANDARD_GRAVITY);
    (
        sample_time_us(n),
        n,
        ProbeSample::new(rate.x, rate.z, force),
    )
}

/// The SCC1300's budget with its gyros' (body x and z) white noise, bias
/// instability and residual bias `factor` times smaller and no coloured
/// part: a quieter gyro grade.
pub(crate) const fn quieter_gyros(factor: f64) -> ImuNoise {
    let mut noise = ImuNoise::scc1300();
    let mut axis = 0;
    while axis < 3 {
        noise.gyro[axis].white_density /= factor;
        noise.gyro[axis].bias_instability /= factor;
        noise.gyro[axis].residual_bias /= factor;
        noise.gyro[axis].coloured = None;
        axis += 2;
    }
    noise
}

/// A navigator at the paper's site that has aligned on level still
/// samples and navigates.
pub(crate) fn aligned_navigator() -> Navigator {
    let mut navigator = Navigator::new(Position::paper_site());
    for n in 0..=ALL_ALIGNMENT {
        navigator.step(&level_sample(n));
    }
    assert!(navigator.is_navigating());
    navigator
}
