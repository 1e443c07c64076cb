//! A raw sample (the counts of both SCC1300 parts, as on the wire) to the
//! calibrated body-frame rates and specific force the navigation uses.

use crate::calibration::ProbeCalibration;
use crate::protocol::frame::raw_flags;
use crate::protocol::RawSample;
use crate::sensor_units::{accel_count_to_m_s2, gyro_count_to_rad_s, PART_MOUNTINGS};
use nalgebra::Vector3;

/// Body-frame rates (x and z gyros) and specific force of one raw sample,
/// corrected by `calibration`, or `None` when a part's reading is not
/// valid.
pub fn body_sample(
    raw: &RawSample,
    calibration: &ProbeCalibration,
) -> Option<(f64, f64, Vector3<f64>)> {
    let valid = raw_flags::GYRO_VALID | raw_flags::ACCEL_VALID;
    if raw.parts.iter().any(|p| p.flags & valid != valid) {
        return None;
    }
    let mut rate = [0.0f64; 3];
    let mut force = Vector3::zeros();
    for (((part, mounting), triad), gyro_cal) in raw
        .parts
        .iter()
        .zip(PART_MOUNTINGS)
        .zip(&calibration.accel)
        .zip(&calibration.gyro)
    {
        let gyro = mounting.gyro_axis();
        let value = f64::from(gyro_count_to_rad_s(part.gyro_rate));
        let value = if gyro.negative { -value } else { value };
        rate[gyro.axis as usize] = gyro_cal.apply(value);
        // Each part's triad is corrected in body axes (the frame the host's
        // calibration is fitted in); both then see the same body force, so
        // they are averaged.
        let body = mounting
            .sensor_to_body(part.accel.map(accel_count_to_m_s2))
            .map(f64::from);
        force += 0.5 * Vector3::from(triad.apply(body));
    }
    Some((rate[0], rate[2], force))
}
