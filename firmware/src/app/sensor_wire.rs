//! The driver's readings and errors in the wire protocol's terms: the raw
//! part of a raw-sample frame with its flags, the stable code of each driver
//! error, and the sensor events. The driver (`crate::scc1300`) knows nothing
//! of the protocol; every mapping from its types to frames is here, once.

use mwd_core::protocol::frame::{raw_flags, RawPart};
use mwd_core::protocol::{Event, EventKind, Payload};
use mwd_core::sensor_units::{
    TemperatureScale, ACCEL_TEMPERATURE, COUNT_MAX, COUNT_MIN, GYRO_TEMPERATURE,
    OPERATING_TEMPERATURE_DEGC,
};

use crate::scc1300::{Error, GyroRecovery, PartReading, RecoveryReport, Slave, Word};

/// A part's reading as the raw-sample frame carries it: counts, and flags
/// for what the part told and what went wrong.
pub fn raw_part(reading: &PartReading) -> RawPart {
    let mut flags = 0;
    if reading.gyro_s_ok {
        flags |= raw_flags::GYRO_S_OK;
    }
    if reading.gyro_was_reset {
        flags |= raw_flags::RESET_SEEN;
    }
    flags |= reading
        .gyro_error
        .map_or(raw_flags::GYRO_VALID, |e| error_flag(&e));
    if reading.accel_saturation_seen {
        flags |= raw_flags::ACCEL_SATURATED;
    }
    flags |= reading
        .accel_error
        .map_or(raw_flags::ACCEL_VALID, |e| error_flag(&e));
    if part_temperature(reading).is_some_and(|(range, _)| range != TemperatureRange::Inside) {
        flags |= raw_flags::TEMPERATURE_OUT_OF_RANGE;
    }
    RawPart {
        gyro_rate: reading.gyro.rate,
        gyro_temp: reading.gyro.temp,
        accel: reading.accel.xyz,
        accel_temp: reading.accel.temp,
        flags,
    }
}

/// Where a part's temperature lies against its operating range.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum TemperatureRange {
    Below,
    #[default]
    Inside,
    Above,
}

/// A temperature count against the part's operating range
/// (`sensor_units::OPERATING_TEMPERATURE_DEGC`, the limits inside). A count
/// at a limit of the 14-bit range is outside whatever the (unverified)
/// formula says: the temperature clipped there (200 degC reads 8191).
pub fn temperature_range(count: i16, scale: &TemperatureScale) -> TemperatureRange {
    let degc = scale.count_to_degc(count);
    let (lowest, highest) = OPERATING_TEMPERATURE_DEGC;
    if count == COUNT_MIN || degc < lowest {
        TemperatureRange::Below
    } else if count == COUNT_MAX || degc > highest {
        TemperatureRange::Above
    } else {
        TemperatureRange::Inside
    }
}

/// The part's temperature judged from the temperatures it measured in this
/// sample (the gyro's when its values are valid or only saturated, the
/// accelerometer's when its values are valid; other counts are not
/// measurements): above when either is above, else below when either is
/// below, else inside; with the count that decided. None when neither
/// temperature was measured.
pub fn part_temperature(reading: &PartReading) -> Option<(TemperatureRange, i16)> {
    let gyro_measured = matches!(
        reading.gyro_error,
        None | Some(Error::Saturated(Slave::Gyro))
    );
    let measured = [
        gyro_measured.then(|| {
            (
                temperature_range(reading.gyro.temp, &GYRO_TEMPERATURE),
                reading.gyro.temp,
            )
        }),
        reading.accel_error.is_none().then(|| {
            (
                temperature_range(reading.accel.temp, &ACCEL_TEMPERATURE),
                reading.accel.temp,
            )
        }),
    ];
    let find = |wanted: TemperatureRange| measured.iter().flatten().find(|(r, _)| *r == wanted);
    find(TemperatureRange::Above)
        .or_else(|| find(TemperatureRange::Below))
        .or_else(|| measured.iter().flatten().next())
        .copied()
}

/// The Temperature event of part `part` entering `range`: code 0 below the
/// operating range, 1 above it, 2 back inside; value the count that showed
/// it, sign-extended.
pub fn temperature_event(time_us: u64, part: u8, range: TemperatureRange, count: i16) -> Payload {
    Payload::Event(Event {
        time_us,
        kind: EventKind::Temperature,
        part,
        code: match range {
            TemperatureRange::Below => 0,
            TemperatureRange::Above => 1,
            TemperatureRange::Inside => 2,
        },
        value: i32::from(count) as u32,
    })
}

/// The raw-sample flag bit a slave's error sets (none for a gyro that is
/// not ready: its missing valid flag tells).
fn error_flag(error: &Error) -> u16 {
    match error {
        Error::Bus(..) | Error::NoResponse(_) | Error::BadStatus => raw_flags::NO_RESPONSE,
        Error::Parity(..) => raw_flags::PARITY_ERROR,
        Error::NotReady => 0,
        Error::LoopFailure | Error::PowerOnReset => raw_flags::RESET_SEEN,
        Error::Saturated(Slave::Gyro) => raw_flags::GYRO_SATURATED,
        Error::Saturated(Slave::Accel) => raw_flags::ACCEL_SATURATED,
        Error::SelfTest => raw_flags::SELF_TEST_FAILED,
        Error::FrameError => raw_flags::ACCEL_FRAME_ERROR,
    }
}

/// The stable number of a driver error in event frames (`Event::code`):
/// the error's own number, plus 0x100 for the accelerometer.
pub fn fault_code(error: &Error) -> u16 {
    let slave = |s: &Slave| match s {
        Slave::Gyro => 0,
        Slave::Accel => 0x100,
    };
    match error {
        Error::Bus(s, _) => 1 | slave(s),
        Error::NoResponse(s) => 2 | slave(s),
        Error::BadStatus => 3 | 0x100,
        Error::Parity(s, Word::Status) => 4 | slave(s),
        Error::Parity(s, Word::Data) => 5 | slave(s),
        Error::NotReady => 6,
        Error::LoopFailure => 7,
        Error::Saturated(s) => 8 | slave(s),
        Error::SelfTest => 9 | 0x100,
        Error::FrameError => 10 | 0x100,
        Error::PowerOnReset => 11 | 0x100,
    }
}

/// The event frame of one sensor fault of part `part` (0 or 1): the
/// error's code and `count` (the part's running fault count, or the
/// start-up attempt that failed).
pub fn sensor_fault_event(time_us: u64, part: u8, error: &Error, count: u32) -> Payload {
    Payload::Event(Event {
        time_us,
        kind: EventKind::SensorFault,
        part,
        code: fault_code(error),
        value: count,
    })
}

/// The `code` of the SensorReset event that reports a recovery: 0 when the
/// part came back by itself (a transient S_OK drop) or only its
/// accelerometer was restarted, the loop-failure code when the gyro had to
/// be soft-reset (its loop was off: a loop failure, or the start-up after a
/// power cycle), and the error's own code when the recovery failed.
pub fn reset_event_code(outcome: &Result<RecoveryReport, Error>) -> u16 {
    match outcome {
        Ok(report) if report.gyro == Some(GyroRecovery::SoftReset) => {
            fault_code(&Error::LoopFailure)
        }
        Ok(_) => 0,
        Err(error) => fault_code(error),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scc1300::{AccelCounts, GyroCounts};
    use embedded_hal::spi::ErrorKind;

    #[test]
    fn codes_are_distinct() {
        let all = [
            Error::Bus(Slave::Gyro, ErrorKind::Other),
            Error::Bus(Slave::Accel, ErrorKind::Other),
            Error::NoResponse(Slave::Gyro),
            Error::NoResponse(Slave::Accel),
            Error::BadStatus,
            Error::Parity(Slave::Gyro, Word::Status),
            Error::Parity(Slave::Gyro, Word::Data),
            Error::Parity(Slave::Accel, Word::Data),
            Error::NotReady,
            Error::LoopFailure,
            Error::Saturated(Slave::Gyro),
            Error::Saturated(Slave::Accel),
            Error::SelfTest,
            Error::FrameError,
            Error::PowerOnReset,
        ];
        for (i, a) in all.iter().enumerate() {
            for b in &all[i + 1..] {
                assert_ne!(fault_code(a), fault_code(b), "{a:?} vs {b:?}");
            }
        }
        let Payload::Event(e) = sensor_fault_event(42, 1, &Error::SelfTest, 3) else {
            panic!("an event frame")
        };
        assert_eq!(
            (e.time_us, e.kind, e.part, e.code, e.value),
            (42, EventKind::SensorFault, 1, 0x109, 3)
        );
    }

    #[test]
    fn raw_parts_carry_the_counts_and_what_the_part_told() {
        let good = PartReading {
            gyro: GyroCounts {
                rate: -100,
                temp: 7,
            },
            accel: AccelCounts {
                xyz: [650, -1, 0],
                temp: -1625,
            },
            gyro_s_ok: true,
            ..PartReading::default()
        };
        assert_eq!(
            raw_part(&good),
            RawPart {
                gyro_rate: -100,
                gyro_temp: 7,
                accel: [650, -1, 0],
                accel_temp: -1625,
                flags: raw_flags::GYRO_VALID | raw_flags::ACCEL_VALID | raw_flags::GYRO_S_OK,
            }
        );
        // A loop failure reported beside a newer S_OK drop, and SAT beside
        // the self-test failure reported for it.
        let faulty = PartReading {
            gyro_was_reset: true,
            accel_saturation_seen: true,
            gyro_error: Some(Error::NotReady),
            accel_error: Some(Error::SelfTest),
            ..PartReading::default()
        };
        assert_eq!(
            raw_part(&faulty).flags,
            raw_flags::RESET_SEEN | raw_flags::ACCEL_SATURATED | raw_flags::SELF_TEST_FAILED
        );
        assert_eq!(error_flag(&Error::LoopFailure), raw_flags::RESET_SEEN);
    }

    #[test]
    fn temperatures_outside_the_range_or_clipped_are_flagged_when_measured() {
        use TemperatureRange::{Above, Below, Inside};
        // -40 degC is count -5850, +125 degC is 4875 (limits inside).
        for (count, range) in [
            (-5850, Inside),
            (-5851, Below),
            (4875, Inside),
            (4876, Above),
            (COUNT_MAX, Above),
            (COUNT_MIN, Below),
            (-1625, Inside),
        ] {
            assert_eq!(
                temperature_range(count, &GYRO_TEMPERATURE),
                range,
                "{count}"
            );
        }
        let mut hot = PartReading::default();
        hot.gyro.temp = COUNT_MAX;
        hot.accel.temp = 0;
        assert_eq!(part_temperature(&hot), Some((Above, COUNT_MAX)));
        assert_ne!(
            raw_part(&hot).flags & raw_flags::TEMPERATURE_OUT_OF_RANGE,
            0
        );
        // The valid flags stay: the values are measurements, out of spec.
        assert_ne!(raw_part(&hot).flags & raw_flags::GYRO_VALID, 0);
        // A cold accelerometer beside a good gyro.
        let mut cold = PartReading::default();
        cold.accel.temp = -7150;
        assert_eq!(part_temperature(&cold), Some((Below, -7150)));
        // Counts that are not measurements are not judged.
        hot.gyro_error = Some(Error::NotReady);
        assert_eq!(part_temperature(&hot), Some((Inside, 0)));
        assert_eq!(
            raw_part(&hot).flags & raw_flags::TEMPERATURE_OUT_OF_RANGE,
            0
        );
        hot.accel_error = Some(Error::FrameError);
        assert_eq!(part_temperature(&hot), None);
        hot.gyro_error = Some(Error::Saturated(Slave::Gyro));
        assert_eq!(part_temperature(&hot), Some((Above, COUNT_MAX)));

        let Payload::Event(e) = temperature_event(5, 1, Below, -7150) else {
            panic!("an event frame")
        };
        assert_eq!(
            (e.kind, e.part, e.code, e.value),
            (EventKind::Temperature, 1, 0, (-7150i32) as u32)
        );
        assert_eq!(e.value, 0xFFFF_E412);
    }

    #[test]
    fn reset_event_codes_tell_transient_soft_reset_and_failure_apart() {
        let transient = RecoveryReport {
            gyro: Some(GyroRecovery::Transient),
            accel_restarted: true,
        };
        let soft_reset = RecoveryReport {
            gyro: Some(GyroRecovery::SoftReset),
            accel_restarted: false,
        };
        let loop_failure = fault_code(&Error::LoopFailure);
        assert_eq!(reset_event_code(&Ok(transient)), 0);
        assert_eq!(reset_event_code(&Ok(soft_reset)), loop_failure);
        assert_eq!(
            reset_event_code(&Err(Error::NotReady)),
            fault_code(&Error::NotReady)
        );
        assert_ne!(loop_failure, 0);
    }
}
