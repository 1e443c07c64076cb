//! The gyro slave (CSB_G): 32-bit transactions, rate and temperature reads,
//! STATUS, soft reset, and TN92's start-up and S_OK supervision.

use embedded_hal::delay::DelayNs;
use embedded_hal::spi::{Error as _, SpiDevice};
use mwd_core::sensor_units;

use super::datasheet::{
    gyro_reg, GYRO_LOOPF_OK, GYRO_RECHECK_WAIT_MS, GYRO_SOFT_RESET_DATA, GYRO_S_OK,
    POWER_UP_WAIT_MS,
};
use super::error::{Error, Slave, Word};
use super::frame::{gyro_command, gyro_write_word, is_dead_word, is_odd_parity, GYRO_READ_WORD};

/// What one gyro transaction returned, both words parity-checked.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GyroAnswer {
    /// S_OK of MISO word 1.
    pub s_ok: bool,
    /// MISO word 2, parity bit included.
    pub data: u16,
}

/// The STATUS register (0x08), plus the live S_OK of the same frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GyroStatus {
    /// S_OK as latched in STATUS: clear if it dropped since the last read.
    pub s_ok: bool,
    pub loop_ok: bool,
    /// S_OK of MISO word 1: the state now.
    pub s_ok_now: bool,
}

/// The gyro's half of a part's sample, in counts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct GyroCounts {
    /// Rate about the part's X axis (18 LSB per deg/s).
    pub rate: i16,
    pub temp: i16,
}

/// How a supervision run ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GyroRecovery {
    /// S_OK was back at the recheck: a transient.
    Transient,
    /// LOOPF_OK was clear: soft reset and a full start-up, now S_OK again.
    SoftReset,
}

/// One gyro, owning its chip select's `SpiDevice`.
pub struct Gyro<SPI> {
    spi: SPI,
    /// [`Gyro::supervise`] found a loop failure and soft-reset the gyro;
    /// not yet reported in a sample ([`Gyro::take_loop_failure`]).
    loop_failure_pending: bool,
}

impl<SPI: SpiDevice> Gyro<SPI> {
    pub fn new(spi: SPI) -> Self {
        Self {
            spi,
            loop_failure_pending: false,
        }
    }

    /// True once after [`Gyro::supervise`] found LOOPF_OK clear and
    /// soft-reset the gyro: the next sample reports [`Error::LoopFailure`]
    /// (raw flag RESET_SEEN), as the accelerometer's PORST is reported.
    pub fn take_loop_failure(&mut self) -> bool {
        core::mem::take(&mut self.loop_failure_pending)
    }

    /// Gives the `SpiDevice` back.
    pub fn release(self) -> SPI {
        self.spi
    }

    /// One 32-bit transaction: sends `cmd` and `word2` MSB first and checks
    /// both answer words (dead line first, then odd parity) [TN92].
    pub fn transfer(&mut self, cmd: u16, word2: u16) -> Result<GyroAnswer, Error> {
        let [c1, c0] = cmd.to_be_bytes();
        let [d1, d0] = word2.to_be_bytes();
        let mut buf = [c1, c0, d1, d0];
        self.spi
            .transfer_in_place(&mut buf)
            .map_err(|e| Error::Bus(Slave::Gyro, e.kind()))?;
        let status = u16::from_be_bytes([buf[0], buf[1]]);
        let data = u16::from_be_bytes([buf[2], buf[3]]);
        if is_dead_word(status) && is_dead_word(data) {
            return Err(Error::NoResponse(Slave::Gyro));
        }
        if !is_odd_parity(status) {
            return Err(Error::Parity(Slave::Gyro, Word::Status));
        }
        if !is_odd_parity(data) {
            return Err(Error::Parity(Slave::Gyro, Word::Data));
        }
        Ok(GyroAnswer {
            s_ok: status & GYRO_S_OK != 0,
            data,
        })
    }

    /// Reads a register; the S_OK judgement is left to the caller.
    pub fn read_register(&mut self, reg: u8) -> Result<GyroAnswer, Error> {
        self.transfer(gyro_command(reg, false), GYRO_READ_WORD)
    }

    /// Writes 15 data bits to a register.
    pub fn write_register(&mut self, reg: u8, data: u16) -> Result<(), Error> {
        self.transfer(gyro_command(reg, true), gyro_write_word(data))
            .map(|_| ())
    }

    /// Reads a 14-bit output register, requiring S_OK.
    fn read_count(&mut self, reg: u8) -> Result<i16, Error> {
        let answer = self.read_register(reg)?;
        if !answer.s_ok {
            return Err(Error::NotReady);
        }
        Ok(sensor_units::word_to_count(answer.data))
    }

    /// Rate about the part's X axis in counts (18 LSB per deg/s). A count
    /// beyond the specified +-300 deg/s ([`sensor_units::GYRO_RANGE_COUNTS`]) is reported
    /// as saturation.
    pub fn read_rate_count(&mut self) -> Result<i16, Error> {
        let count = self.read_count(gyro_reg::RATE_X)?;
        if sensor_units::gyro_count_is_saturated(count) {
            return Err(Error::Saturated(Slave::Gyro));
        }
        Ok(count)
    }

    pub fn read_temperature_count(&mut self) -> Result<i16, Error> {
        self.read_count(gyro_reg::TEMP)
    }

    /// Reads STATUS (0x08); reading clears its latched flags [TN92].
    pub fn read_status(&mut self) -> Result<GyroStatus, Error> {
        let answer = self.read_register(gyro_reg::STATUS)?;
        Ok(GyroStatus {
            s_ok: answer.data & GYRO_S_OK != 0,
            loop_ok: answer.data & GYRO_LOOPF_OK != 0,
            s_ok_now: answer.s_ok,
        })
    }

    /// Reads IC_ID (value UNVERIFIED, see `datasheet::GYRO_IC_ID_EXPECTED`).
    pub fn read_ic_id(&mut self) -> Result<u16, Error> {
        self.read_register(gyro_reg::IC_ID).map(|a| a.data >> 1)
    }

    /// Soft reset: write bit 1 of IC_ID (MOSI 0x003D 0x0004) [TN92].
    pub fn soft_reset(&mut self) -> Result<(), Error> {
        self.write_register(gyro_reg::IC_ID, GYRO_SOFT_RESET_DATA)
    }

    /// TN92 step 2, after the 800 ms power-up wait: read STATUS twice (the
    /// first read clears flags latched during power-up), then require S_OK.
    pub fn start(&mut self) -> Result<(), Error> {
        self.read_status()?;
        let status = self.read_status()?;
        if status.s_ok {
            Ok(())
        } else {
            Err(Error::NotReady)
        }
    }

    /// TN92 step 4, after S_OK dropped: read STATUS, wait 60 ms, read it
    /// again; if LOOPF_OK is clear, soft-reset and repeat the 800 ms
    /// start-up. Blocks for 60 ms (860+ ms with a reset): run it outside
    /// the 20 Hz acquisition interrupt. A loop failure is remembered for
    /// the next sample ([`Gyro::take_loop_failure`]).
    pub fn supervise(&mut self, delay: &mut impl DelayNs) -> Result<GyroRecovery, Error> {
        self.read_status()?;
        delay.delay_ms(GYRO_RECHECK_WAIT_MS);
        let status = self.read_status()?;
        if !status.loop_ok {
            self.soft_reset()?;
            // Reported in the next sample even if the restart below fails.
            self.loop_failure_pending = true;
            delay.delay_ms(POWER_UP_WAIT_MS);
            self.start()?;
            return Ok(GyroRecovery::SoftReset);
        }
        // The latched bit may still remember the drop; judge by the live one.
        if status.s_ok_now {
            Ok(GyroRecovery::Transient)
        } else {
            Err(Error::NotReady)
        }
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use embedded_hal_mock::eh1::spi::{Mock, Transaction};
    use std::vec;

    fn read(cmd: [u8; 2], answer: [u8; 4]) -> [Transaction<u8>; 3] {
        [
            Transaction::transaction_start(),
            Transaction::transfer_in_place(vec![cmd[0], cmd[1], 0x00, 0x01], answer.to_vec()),
            Transaction::transaction_end(),
        ]
    }

    #[test]
    fn rate_read_sends_0001_0001_and_decodes_the_count() {
        // Status: S_OK (0x0002) has one bit set, so P = 0. Data: count -100
        // left-aligned is 0xFE70, 10 ones, so P = 1: 0xFE71.
        let expect = read([0x00, 0x01], [0x00, 0x02, 0xFE, 0x71]);
        let mut spi = Mock::new(&expect);
        let mut gyro = Gyro::new(spi.clone());
        assert_eq!(gyro.read_rate_count(), Ok(-100));
        spi.done();
    }

    #[test]
    fn status_temp_and_reset_bytes() {
        let mut expect = vec![];
        // STATUS: S_OK and LOOPF_OK set -> data 0x0006 + P 1 = 0x0007.
        expect.extend(read([0x00, 0x40], [0x00, 0x02, 0x00, 0x07]));
        expect.extend(read([0x00, 0x51], [0x00, 0x02, 0x00, 0x01]));
        // IC_ID 0x0130 (a made-up value: the real one is unknown) << 1, P = 0.
        expect.extend(read([0x00, 0x38], [0x00, 0x02, 0x02, 0x60]));
        expect.extend([
            Transaction::transaction_start(),
            Transaction::transfer_in_place(vec![0x00, 0x3D, 0x00, 0x04], vec![0, 2, 0, 1]),
            Transaction::transaction_end(),
        ]);
        let mut spi = Mock::new(&expect);
        let mut gyro = Gyro::new(spi.clone());
        assert_eq!(
            gyro.read_status(),
            Ok(GyroStatus {
                s_ok: true,
                loop_ok: true,
                s_ok_now: true,
            })
        );
        assert_eq!(gyro.read_temperature_count(), Ok(0));
        assert_eq!(gyro.read_ic_id(), Ok(0x0130));
        assert_eq!(gyro.soft_reset(), Ok(()));
        spi.done();
    }

    #[test]
    fn parity_dead_line_and_not_ok_are_told_apart() {
        let mut expect = vec![];
        expect.extend(read([0x00, 0x01], [0x00, 0x03, 0x00, 0x01])); // status even
        expect.extend(read([0x00, 0x01], [0x00, 0x02, 0x00, 0x03])); // data even
        expect.extend(read([0x00, 0x01], [0xFF, 0xFF, 0xFF, 0xFF])); // dead CS
        expect.extend(read([0x00, 0x01], [0x00, 0x01, 0x00, 0x01])); // S_OK clear
        expect.extend(read([0x00, 0x01], [0x00, 0x02, 0x7F, 0xFC])); // +8191
        let mut spi = Mock::new(&expect);
        let mut gyro = Gyro::new(spi.clone());
        assert_eq!(
            gyro.read_rate_count(),
            Err(Error::Parity(Slave::Gyro, Word::Status))
        );
        assert_eq!(
            gyro.read_rate_count(),
            Err(Error::Parity(Slave::Gyro, Word::Data))
        );
        assert_eq!(gyro.read_rate_count(), Err(Error::NoResponse(Slave::Gyro)));
        assert_eq!(gyro.read_rate_count(), Err(Error::NotReady));
        assert_eq!(gyro.read_rate_count(), Err(Error::Saturated(Slave::Gyro)));
        spi.done();
    }

    #[test]
    fn rates_beyond_300_deg_s_are_out_of_range() {
        // Spec: 18 LSB per deg/s, range +-300 deg/s -> +-5400 counts.
        assert_eq!(sensor_units::GYRO_RANGE_COUNTS, 5400);
        for (count, saturated) in [
            (0, false),
            (5400, false),
            (-5400, false),
            (5401, true),
            (-5401, true),
            (8191, true),
            (-8192, true),
        ] {
            assert_eq!(
                sensor_units::gyro_count_is_saturated(count),
                saturated,
                "{count}"
            );
        }
        // Over the bus: +5400 (0x5460 left-aligned, P = 0 with 5 ones) is
        // good, +5401 (0x5464, 6 ones, P = 1) is flagged.
        let mut expect = vec![];
        expect.extend(read([0x00, 0x01], [0x00, 0x02, 0x54, 0x60]));
        expect.extend(read([0x00, 0x01], [0x00, 0x02, 0x54, 0x65]));
        let mut spi = Mock::new(&expect);
        let mut gyro = Gyro::new(spi.clone());
        assert_eq!(gyro.read_rate_count(), Ok(5400));
        assert_eq!(gyro.read_rate_count(), Err(Error::Saturated(Slave::Gyro)));
        spi.done();
    }
}
