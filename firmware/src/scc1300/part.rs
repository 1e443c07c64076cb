//! One SCC1300 part (gyro + accelerometer): start-up, one 20 Hz sample
//! that never blocks and never fails as a whole (each slave's error is
//! kept and flagged), and the recovery that follows a flagged sample.
//!
//! The readings are the driver's own (counts and what the part reported);
//! how they go on the wire is the application's business
//! (`crate::app::sensor_wire`).

use embedded_hal::delay::DelayNs;
use embedded_hal::spi::SpiDevice;
use mwd_core::sensor_units::{self, gyro_count_is_saturated};

use super::accel::{Accel, AccelCounts};
use super::datasheet::{gyro_reg, POWER_UP_WAIT_MS};
use super::error::{Error, Slave};
use super::gyro::{Gyro, GyroCounts, GyroRecovery};

/// One sample of a part: the counts of both slaves, what the part told
/// besides, and the error of each slave, if any. Counts of a slave with an
/// error are 0 unless the error left them meaningful (saturation keeps the
/// clipped gyro count; a failed temperature read keeps the gyro rate).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct PartReading {
    pub gyro: GyroCounts,
    pub accel: AccelCounts,
    /// S_OK of the gyro's rate answer: its output was valid then, even if
    /// the sample failed after (saturation, the temperature read).
    pub gyro_s_ok: bool,
    /// This sample reports the gyro's soft reset by the recovery before it
    /// (a loop failure, TN92 step 4), also when `gyro_error` names a newer
    /// error that asks for recovery again.
    pub gyro_was_reset: bool,
    /// A frame of this sample showed the accelerometer's SAT (acknowledged
    /// since), also when `accel_error` names another flag that came with it.
    pub accel_saturation_seen: bool,
    pub gyro_error: Option<Error>,
    pub accel_error: Option<Error>,
}

impl PartReading {
    /// Rate about the part's X axis in rad/s, if valid.
    pub fn rate_rad_s(&self) -> Option<f32> {
        (self.gyro_error.is_none()).then(|| sensor_units::gyro_count_to_rad_s(self.gyro.rate))
    }

    /// Specific force along the part's X, Y, Z in m/s^2, if valid.
    pub fn accel_m_s2(&self) -> Option<[f32; 3]> {
        (self.accel_error.is_none()).then(|| self.accel.xyz.map(sensor_units::accel_count_to_m_s2))
    }

    /// True when [`Part::recover`] has something to do.
    pub fn needs_recovery(&self) -> bool {
        self.gyro_error.is_some_and(|e| e.needs_recovery())
            || self.accel_error.is_some_and(|e| e.needs_recovery())
    }
}

/// What a recovery did.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct RecoveryReport {
    pub gyro: Option<GyroRecovery>,
    pub accel_restarted: bool,
}

/// A part: its two slaves, each on its own chip select.
pub struct Part<G, A> {
    pub gyro: Gyro<G>,
    pub accel: Accel<A>,
}

impl<G: SpiDevice, A: SpiDevice> Part<G, A> {
    pub fn new(gyro_spi: G, accel_spi: A) -> Self {
        Self {
            gyro: Gyro::new(gyro_spi),
            accel: Accel::new(accel_spi),
        }
    }

    /// Power-up sequence [TN92 steps 1-3]: wait 800 ms, start the gyro,
    /// start the accelerometer. With two parts powered together, call this
    /// for the first and [`Part::start_powered`] for the second.
    pub fn start(&mut self, delay: &mut impl DelayNs) -> Result<(), Error> {
        delay.delay_ms(POWER_UP_WAIT_MS);
        self.start_powered(delay)
    }

    /// Steps 2-3 only: the 800 ms have already passed.
    pub fn start_powered(&mut self, delay: &mut impl DelayNs) -> Result<(), Error> {
        self.gyro.start()?;
        self.accel.start(delay)
    }

    /// Reads both slaves once: gyro rate and temperature, accelerometer
    /// axes and temperature. Never blocks on a delay. A gyro rate beyond
    /// the specified range is [`Error::Saturated`] (count kept); the first
    /// sample after a recovery that soft-reset the gyro reports
    /// [`Error::LoopFailure`].
    pub fn sample(&mut self) -> PartReading {
        let mut reading = PartReading::default();
        let mut gyro = self.read_gyro(&mut reading);
        if self.gyro.take_loop_failure() {
            // The recovery after the previous sample found a loop failure
            // and soft-reset the gyro [TN92 step 4]: this sample reports it,
            // unless its own error asks for recovery again.
            reading.gyro_was_reset = true;
            if !gyro.is_err_and(|e| e.needs_recovery()) {
                gyro = Err(Error::LoopFailure);
            }
        }
        reading.gyro_error = gyro.err();
        let accel = self.accel.read_counts();
        // SAT may have come with another flag whose error is reported instead.
        reading.accel_saturation_seen = self.accel.saturation_seen();
        match accel {
            Ok(counts) => reading.accel = counts,
            Err(e) => reading.accel_error = Some(e),
        }
        reading
    }

    fn read_gyro(&mut self, reading: &mut PartReading) -> Result<(), Error> {
        let rate = self.gyro.read_register(gyro_reg::RATE_X)?;
        if !rate.s_ok {
            return Err(Error::NotReady);
        }
        reading.gyro_s_ok = true;
        reading.gyro.rate = sensor_units::word_to_count(rate.data);
        reading.gyro.temp = self.gyro.read_temperature_count()?;
        if gyro_count_is_saturated(reading.gyro.rate) {
            return Err(Error::Saturated(Slave::Gyro));
        }
        Ok(())
    }

    /// After a sample that [`PartReading::needs_recovery`]: gyro S_OK lost
    /// -> TN92 supervision (60 ms, or a soft reset and 800 ms; a soft reset
    /// is reported as [`Error::LoopFailure`] by the next sample, unless the
    /// same reading showed the accelerometer's PORST, i.e. the whole part
    /// power-cycled); accelerometer PORST -> its start-up again (10 ms). Blocking: run it outside the
    /// acquisition interrupt, and mark the samples it costs as skipped.
    pub fn recover(
        &mut self,
        delay: &mut impl DelayNs,
        reading: &PartReading,
    ) -> Result<RecoveryReport, Error> {
        let mut report = RecoveryReport::default();
        if reading.gyro_error.is_some_and(|e| e.needs_recovery()) {
            let gyro = self.gyro.supervise(delay);
            if reading.accel_error == Some(Error::PowerOnReset) {
                // The whole part power-cycled (PORST, already flagged as
                // RESET_SEEN): that, not a loop failure, is why LOOPF_OK
                // was clear during the gyro's own start-up.
                self.gyro.take_loop_failure();
            }
            report.gyro = Some(gyro?);
        }
        if reading.accel_error.is_some_and(|e| e.needs_recovery()) {
            self.accel.start(delay)?;
            report.accel_restarted = true;
        }
        #[cfg(feature = "defmt")]
        defmt::warn!(
            "SCC1300 recovered: gyro soft reset {=bool}, accelerometer restarted {=bool}",
            report.gyro == Some(super::gyro::GyroRecovery::SoftReset),
            report.accel_restarted
        );
        Ok(report)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use embedded_hal::spi::{self, ErrorKind, ErrorType, Operation};

    /// A bus whose peripheral always fails.
    struct BrokenBus;

    #[derive(Debug)]
    struct Fault;

    impl spi::Error for Fault {
        fn kind(&self) -> ErrorKind {
            ErrorKind::ModeFault
        }
    }

    impl ErrorType for BrokenBus {
        type Error = Fault;
    }

    impl SpiDevice for BrokenBus {
        fn transaction(&mut self, _: &mut [Operation<'_, u8>]) -> Result<(), Fault> {
            Err(Fault)
        }
    }

    #[test]
    fn bus_errors_are_flagged_per_slave() {
        let mut part = Part::new(BrokenBus, BrokenBus);
        let r = part.sample();
        assert_eq!(
            r.gyro_error,
            Some(Error::Bus(Slave::Gyro, ErrorKind::ModeFault))
        );
        assert_eq!(
            r.accel_error,
            Some(Error::Bus(Slave::Accel, ErrorKind::ModeFault))
        );
        assert!(!r.gyro_s_ok && !r.accel_saturation_seen);
        assert_eq!(r.rate_rad_s(), None);
        assert!(!r.needs_recovery());
    }
}
