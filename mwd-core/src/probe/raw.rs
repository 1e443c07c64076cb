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

/// What one raw sample offers the navigation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Reading {
    /// Both parts valid: the full sample ([`body_sample`]).
    Both(ProbeSample),
    /// One part valid (gyro and accelerometer), the other out: the healthy
    /// part's gyro and accelerometer triad; the missing gyro's rate is NaN
    /// (its index in [`crate::probe_sample::GYRO_AXES`] is `missing_gyro`).
    Single {
        sample: ProbeSample,
        missing_gyro: usize,
    },
    /// Neither part valid.
    Neither,
}

/// The calibrated reading of one raw sample, whatever is still valid in it
/// (the probe's degraded modes, docs/protocol.md Kind 2).
pub fn reading(raw: &RawSample, calibration: &ProbeCalibration) -> Reading {
    if let Some(sample) = body_sample(raw, calibration) {
        return Reading::Both(sample);
    }
    let valid = raw_flags::GYRO_VALID | raw_flags::ACCEL_VALID;
    let healthy: [bool; 2] = core::array::from_fn(|p| raw.parts[p].flags & valid == valid);
    let Some(part) = healthy.iter().position(|&h| h) else {
        return Reading::Neither;
    };
    let (raw_part, mounting) = (&raw.parts[part], PART_MOUNTINGS[part]);
    let gyro = mounting.gyro_axis();
    let value = f64::from(gyro_count_to_rad_s(raw_part.gyro_rate));
    let rate = calibration.gyro[part].apply(if gyro.negative { -value } else { value });
    let triad = mounting
        .sensor_to_body(raw_part.accel.map(accel_count_to_m_s2))
        .map(f64::from);
    let force = calibration.accel[part].apply(triad);
    let mut gyros = [f64::NAN; 2];
    gyros[part] = rate;
    Reading::Single {
        sample: ProbeSample::new(gyros[0], gyros[1], force.into()),
        missing_gyro: 1 - part,
    }
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
    fn one_valid_part_gives_its_own_gyro_and_triad() {
        let count = rad_s_to_gyro_count(0.1);
        let mut raw = sample([count, count]);
        raw.parts[0].flags = raw_flags::NO_RESPONSE;
        let Reading::Single {
            sample,
            missing_gyro,
        } = reading(&raw, &ProbeCalibration::default())
        else {
            panic!("one part is valid");
        };
        assert_eq!(missing_gyro, 0);
        assert!(sample.rate_x().is_nan());
        let both = body_sample(&sample_of(count), &ProbeCalibration::default()).unwrap();
        assert_eq!(sample.rate_z(), both.rate_z());
        // Part 2's triad alone: its Z count (650, 1 g) is body -x.
        assert!(
            (sample.specific_force.x + 9.80665).abs() < 0.02,
            "{sample:?}"
        );
        raw.parts[1].flags = 0;
        assert_eq!(
            reading(&raw, &ProbeCalibration::default()),
            Reading::Neither
        );
    }

    fn sample_of(count: i16) -> RawSample {
        sample([count, count])
    }

    #[test]
    fn an_invalid_part_gives_no_sample() {
        let mut raw = sample([0, 0]);
        raw.parts[1].flags &= !raw_flags::ACCEL_VALID;
        assert_eq!(body_sample(&raw, &ProbeCalibration::default()), None);
    }
}
