//! Helpers for the probe's unit tests (compiled for tests only).

use crate::protocol::frame::raw_flags;
use crate::protocol::{RawPart, RawSample};
use crate::sensor_units::{m_s2_to_accel_count, rad_s_to_gyro_count, PART_MOUNTINGS};

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
