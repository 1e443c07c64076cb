//! The driver's readings and errors in the wire protocol's terms: the raw
//! part of a raw-sample frame with its flags, the stable code of each driver
//! error, and the sensor events. The driver (`crate::scc1300`) knows nothing
//! of the protocol; every mapping from its types to frames is here, once.

use mwd_core::protocol::frame::{raw_flags, RawPart};
use mwd_core::protocol::{Event, EventKind, Payload};

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
    RawPart {
        gyro_rate: reading.gyro.rate,
        gyro_temp: reading.gyro.temp,
        accel: reading.accel.xyz,
        accel_temp: reading.accel.temp,
        flags,
    }
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
