//! Helpers for the probe's unit tests (compiled for tests only).

use super::Navigator;
use crate::earth::Position;
use crate::protocol::frame::raw_flags;
use crate::protocol::{RawPart, RawSample};
use crate::sensor_noise::ImuNoise;
use crate::sensor_units::{
    m_s2_to_accel_count, rad_s_to_gyro_count, PART_MOUNTINGS, STANDARD_GRAVITY_M_S2,
};
use crate::timing::{ALIGNMENT_SAMPLES, FINE_ALIGNMENT_SAMPLES};

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
