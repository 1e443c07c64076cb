//! What can go wrong on the sensor bus, told apart so the firmware can
//! count, flag and recover (design rule: no panics on data).

use embedded_hal::spi::ErrorKind;
use mwd_core::protocol::frame::{raw_flags, Event, EventKind};

/// Which slave of a part an error concerns.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Slave {
    Gyro,
    Accel,
}

/// Which word of a transaction failed its parity check.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Word {
    /// Gyro MISO word 1.
    Status,
    /// Gyro MISO word 2, or the accelerometer's data bytes (dPAR).
    Data,
}

/// A driver error. Every variant leaves the driver usable: the caller
/// flags the sample and, where [`Error::needs_recovery`] says so, runs the
/// part's recovery.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Error {
    /// The SPI peripheral reported an error.
    Bus(Slave, ErrorKind),
    /// MISO read all zeros or all ones: dead chip select or no part.
    NoResponse(Slave),
    /// Accelerometer status byte without its fixed `0 1` bits (stuck MISO
    /// bit or a different device).
    BadStatus,
    /// A word the part sent failed its odd-parity check.
    Parity(Slave, Word),
    /// Gyro S_OK is clear: output invalid (start-up, or a transient).
    NotReady,
    /// Gyro LOOPF_OK was clear at the 60 ms recheck after S_OK dropped, so
    /// the recovery soft-reset the gyro and repeated its start-up (TN92
    /// step 4). Reported as the gyro error of the first sample after that
    /// recovery (raw flag RESET_SEEN); the recovery is already done.
    LoopFailure,
    /// Output beyond range: accelerometer SAT (acknowledged through
    /// INT_STATUS), or a gyro count beyond the specified +-300 deg/s
    /// (`mwd_core::sensor_units::GYRO_RANGE_COUNTS`).
    Saturated(Slave),
    /// Accelerometer ST: self-test or memory checksum failure.
    SelfTest,
    /// Accelerometer FRME: it received a bad frame from us (MOSI parity or
    /// length), so the answer to it is void.
    FrameError,
    /// Accelerometer PORST: the part went through a power-on reset.
    PowerOnReset,
}

impl Error {
    /// True when the part needs its recovery sequence (not just a retry).
    /// Not [`Error::LoopFailure`]: it reports a recovery that has been run.
    pub fn needs_recovery(&self) -> bool {
        matches!(self, Error::NotReady | Error::PowerOnReset)
    }

    /// The raw-sample flag bit this error sets.
    pub fn raw_flag(&self) -> u16 {
        match self {
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

    /// A stable number for event frames (`Event::code` of a sensor fault).
    pub fn code(&self) -> u16 {
        let slave = |s: &Slave| match s {
            Slave::Gyro => 0,
            Slave::Accel => 0x100,
        };
        match self {
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
}

impl Error {
    /// The sensor-fault event frame that reports this error for part
    /// `part` (0 or 1), with `count` occurrences since the last report.
    pub fn to_event(&self, part: u8, time_us: u64, count: u32) -> Event {
        Event {
            time_us,
            kind: EventKind::SensorFault,
            part,
            code: self.code(),
            value: count,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
                assert_ne!(a.code(), b.code(), "{a:?} vs {b:?}");
            }
        }
        let e = Error::SelfTest.to_event(1, 42, 3);
        assert_eq!(
            (e.kind, e.part, e.code, e.value),
            (EventKind::SensorFault, 1, 0x109, 3)
        );
        assert!(Error::PowerOnReset.needs_recovery());
        assert!(Error::NotReady.needs_recovery());
        assert!(!Error::LoopFailure.needs_recovery());
        assert_eq!(Error::LoopFailure.raw_flag(), raw_flags::RESET_SEEN);
        assert!(!Error::Parity(Slave::Gyro, Word::Data).needs_recovery());
    }
}
