//! A raw sample (the counts of both SCC1300 parts, as on the wire) to the
//! calibrated body-frame rates and specific force the navigation uses.

use crate::calibration::ProbeCalibration;
use crate::probe_sample::ProbeSample;
use crate::protocol::frame::raw_flags;
use crate::protocol::RawSample;
use crate::sensor_units::{accel_count_to_m_s2, gyro_count_to_rad_s, PART_MOUNTINGS};

/// The calibrated body-frame sample of one raw sample, or `None` when a
/// part's reading is not valid.
pub fn body_sample(raw: &RawSample, calibration: &ProbeCalibration) -> Option<ProbeSample> {
    let valid = raw_flags::GYRO_VALID | raw_flags::ACCEL_VALID;
    if raw.parts.iter().any(|p| p.flags & valid != valid) {
        return None;
    }
    let mut rate = [0.0f64; 3];
    let mut accel = [[0.0f64; 3]; 2];
    for ((part, mounting), triad) in raw.parts.iter().zip(PART_MOUNTINGS).zip(&mut accel) {
        let gyro = mounting.gyro_axis();
        let value = f64::from(gyro_count_to_rad_s(part.gyro_rate));
        rate[gyro.axis as usize] = if gyro.negative { -value } else { value };
        *triad = mounting
            .sensor_to_body(part.accel.map(accel_count_to_m_s2))
            .map(f64::from);
    }
    Some(calibration.correct(rate[0], rate[2], &accel))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::calibration::GyroCalibration;
    use crate::protocol::RawPart;
    use crate::sensor_units::{rad_s_to_gyro_count, GYRO_LSB_PER_DEG_S};

    fn sample(gyro: [i16; 2]) -> RawSample {
        let flags = raw_flags::GYRO_VALID | raw_flags::ACCEL_VALID;
        let part = |gyro_rate| RawPart {
            gyro_rate,
            accel: [0, 0, 650],
            flags,
            ..RawPart::default()
        };
        RawSample {
            time_us: 0,
            sample_counter: 0,
            parts: [part(gyro[0]), part(gyro[1])],
        }
    }

    #[test]
    fn each_gyro_gets_its_own_calibration() {
        // Part 1 senses body x, part 2 body z (their mountings), so the
        // calibration's gyro[0] and gyro[1] are theirs.
        let count = rad_s_to_gyro_count(0.1);
        let raw = sample([count, 0]);
        let plain = body_sample(&raw, &ProbeCalibration::default()).unwrap();
        assert!((plain.rate_x().abs() - 0.1).abs() < 1.0 / f64::from(GYRO_LSB_PER_DEG_S));
        assert_eq!(plain.rate_z(), 0.0);
        let calibration = ProbeCalibration {
            gyro: [
                GyroCalibration::IDENTITY,
                GyroCalibration {
                    bias: 0.5,
                    scale: 1.0,
                },
            ],
            ..ProbeCalibration::default()
        };
        let corrected = body_sample(&raw, &calibration).unwrap();
        assert_eq!(corrected.rate_x(), plain.rate_x());
        assert_eq!(corrected.rate_z(), -0.5);
    }

    #[test]
    fn an_invalid_part_gives_no_sample() {
        let mut raw = sample([0, 0]);
        raw.parts[1].flags &= !raw_flags::ACCEL_VALID;
        assert_eq!(body_sample(&raw, &ProbeCalibration::default()), None);
    }
}
