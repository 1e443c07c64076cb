//! What can go wrong on the sensor bus, told apart so the firmware can
//! count, flag and recover (design rule: no panics on data), and told in
//! a sentence for logs.

use core::fmt;

use embedded_hal::spi::ErrorKind;

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
}

impl fmt::Display for Slave {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Slave::Gyro => "gyro",
            Slave::Accel => "accelerometer",
        })
    }
}

impl fmt::Display for Word {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Word::Status => "status word",
            Word::Data => "data",
        })
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Bus(slave, kind) => {
                write!(f, "the SPI peripheral failed on the {slave}'s chip select: {kind}")
            }
            Error::NoResponse(slave) => write!(
                f,
                "the {slave} did not answer (MISO all zeros or all ones: dead chip select or no part)"
            ),
            Error::BadStatus => f.write_str(
                "the accelerometer's status byte lacks its fixed 0 1 bits (stuck MISO bit or another device)",
            ),
            Error::Parity(slave, word) => {
                write!(f, "the {slave}'s MISO {word} failed its odd-parity check")
            }
            Error::NotReady => f.write_str(
                "the gyro's S_OK is clear: its output is not valid (start-up or a transient)",
            ),
            Error::LoopFailure => f.write_str(
                "the gyro's LOOPF_OK was clear (STATUS register): it was soft-reset and restarted",
            ),
            Error::Saturated(Slave::Gyro) => {
                f.write_str("the gyro's rate (RATE_X register) is beyond the specified +-300 deg/s")
            }
            Error::Saturated(Slave::Accel) => f.write_str(
                "the accelerometer's output saturated (SAT, acknowledged through INT_STATUS)",
            ),
            Error::SelfTest => {
                f.write_str("the accelerometer reported a self-test or memory checksum failure (ST)")
            }
            Error::FrameError => {
                f.write_str("the accelerometer received a bad frame from the driver (FRME)")
            }
            Error::PowerOnReset => {
                f.write_str("the accelerometer went through a power-on reset (PORST)")
            }
        }
    }
}

impl core::error::Error for Error {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recovery_is_asked_for_by_not_ready_and_power_on_reset_only() {
        assert!(Error::PowerOnReset.needs_recovery());
        assert!(Error::NotReady.needs_recovery());
        assert!(!Error::LoopFailure.needs_recovery());
        assert!(!Error::Parity(Slave::Gyro, Word::Data).needs_recovery());
    }

    #[test]
    fn errors_read_as_sentences_naming_the_slave_and_word() {
        extern crate std;
        use std::string::ToString;
        let text = Error::Parity(Slave::Gyro, Word::Status).to_string();
        assert_eq!(
            text,
            "the gyro's MISO status word failed its odd-parity check"
        );
        let text = Error::Bus(Slave::Accel, ErrorKind::ModeFault).to_string();
        assert!(text.contains("accelerometer's chip select"), "{text}");
        let as_error: &dyn core::error::Error = &Error::PowerOnReset;
        assert!(as_error.to_string().contains("PORST"));
    }
}
