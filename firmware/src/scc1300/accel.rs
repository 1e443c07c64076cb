//! The accelerometer slave (CSB_A): command byte + data bytes per
//! transaction, the burst read of the three axes from Z_MSB, temperature,
//! and the status byte's supervision [TN92].
//!
//! Every MISO status byte is checked: fixed bits, dPAR against the parity
//! of the previous frame's data (see `datasheet::ACCEL_DPAR_COVERS_PREVIOUS_FRAME`),
//! FRME (the part rejected our previous frame), PORST, ST and SAT. Because
//! dPAR and FRME speak about the previous frame, a sample is three frames:
//! the axes, the temperature (whose status vouches for the axes) and STATUS
//! (whose status vouches for the temperature).

use embedded_hal::delay::DelayNs;
use embedded_hal::spi::{Error as _, SpiDevice};
use mwd_core::sensor_units::{self, ACCEL_TEMPERATURE};

use super::datasheet::{accel_reg, accel_status, ACCEL_SETTLE_MS};
use super::error::{Error, Slave, Word};
use super::frame::{accel_command, accel_status_fixed_bits_ok, odd_parity_of};

/// Longest frame: command + six burst bytes.
const MAX_FRAME: usize = 7;

/// One accelerometer sample in counts, part axes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct AccelCounts {
    pub xyz: [i16; 3],
    pub temp: i16,
}

/// One accelerometer, owning its chip select's `SpiDevice`.
pub struct Accel<SPI> {
    spi: SPI,
    /// dPAR the next status byte must carry; `None` when unknown (after
    /// construction or a failed transfer).
    expected_dpar: Option<bool>,
}

impl<SPI: SpiDevice> Accel<SPI> {
    pub fn new(spi: SPI) -> Self {
        Self {
            spi,
            expected_dpar: None,
        }
    }

    pub fn release(self) -> SPI {
        self.spi
    }

    /// One frame: `cmd` then `data_len` bytes (`write` = data to send, or
    /// zeros for a read). Returns the data bytes after checking the status.
    fn frame<'b>(
        &mut self,
        cmd: u8,
        write: &[u8],
        data_len: usize,
        buf: &'b mut [u8; MAX_FRAME],
    ) -> Result<&'b [u8], Error> {
        let len = data_len.saturating_add(1).min(MAX_FRAME);
        buf.fill(0);
        buf[0] = cmd;
        for (slot, byte) in buf.iter_mut().skip(1).zip(write) {
            *slot = *byte;
        }
        let expected = self.expected_dpar.take();
        let frame = buf.get_mut(..len).ok_or(Error::BadStatus)?;
        self.spi
            .transfer_in_place(frame)
            .map_err(|e| Error::Bus(Slave::Accel, e.kind()))?;
        let (status, data) = frame.split_first().ok_or(Error::BadStatus)?;
        self.expected_dpar = Some(odd_parity_of(data));
        check_status(*status, expected)?;
        Ok(data)
    }

    fn read(&mut self, reg: u8, data_len: usize) -> Result<[u8; MAX_FRAME - 1], Error> {
        let mut buf = [0u8; MAX_FRAME];
        let data = self.frame(accel_command(reg, false), &[], data_len, &mut buf)?;
        let mut out = [0u8; MAX_FRAME - 1];
        for (o, d) in out.iter_mut().zip(data) {
            *o = *d;
        }
        Ok(out)
    }

    /// Reads one register (single frame; its dPAR is checked by the next).
    pub fn read_register(&mut self, reg: u8) -> Result<u8, Error> {
        self.read(reg, 1).map(|d| d[0])
    }

    /// Writes one register.
    pub fn write_register(&mut self, reg: u8, value: u8) -> Result<(), Error> {
        let mut buf = [0u8; MAX_FRAME];
        self.frame(accel_command(reg, true), &[value], 1, &mut buf)
            .map(|_| ())
    }

    /// Reads INT_STATUS, which acknowledges SAT [TN92 step 3]. The status
    /// of this very frame may still show SAT: it is clocked out before the
    /// read takes effect, so SAT is not an error here.
    pub fn acknowledge_saturation(&mut self) -> Result<u8, Error> {
        match self.read_register(accel_reg::INT_STATUS) {
            Err(Error::Saturated(Slave::Accel)) => Ok(0),
            other => other,
        }
    }

    /// TN92 step 3, after the 800 ms power-up wait: read INT_STATUS, write
    /// CTRL = 0x00 (clears PORST), wait 10 ms. Flags left over from power-up
    /// (PORST, SAT, FRME, dPAR of the unknown frame before) are expected on
    /// the first frames and not errors here; ST is.
    pub fn start(&mut self, delay: &mut impl DelayNs) -> Result<(), Error> {
        self.expected_dpar = None;
        tolerate_start_flags(self.read_register(accel_reg::INT_STATUS))?;
        tolerate_start_flags(self.write_register(accel_reg::CTRL, 0x00))?;
        delay.delay_ms(ACCEL_SETTLE_MS);
        // This frame's status shows the state after CTRL = 0: PORST must be
        // gone now; its dPAR checks the CTRL frame.
        match self.read_register(accel_reg::STATUS) {
            Err(Error::Saturated(_)) => self.acknowledge_saturation().map(|_| ()),
            other => other.map(|_| ()),
        }
    }

    /// Axes X, Y, Z and temperature in counts: burst read from Z_MSB
    /// (command 0x25: Z_MSB, Z_LSB, Y_MSB, Y_LSB, X_MSB, X_LSB), then the
    /// temperature pair from TEMP_MSB, then STATUS, each frame's status
    /// vouching for the previous frame's data. On SAT the saturation is
    /// acknowledged and [`Error::Saturated`] returned.
    pub fn read_counts(&mut self) -> Result<AccelCounts, Error> {
        let axes = self.read(accel_reg::Z_MSB, 6);
        let axes = match axes {
            Err(Error::Saturated(_)) => {
                self.acknowledge_saturation()?;
                return Err(Error::Saturated(Slave::Accel));
            }
            other => other?,
        };
        let temp = self.read(accel_reg::TEMP_MSB, 2)?;
        self.read_register(accel_reg::STATUS)?;
        let pair =
            |i: usize| sensor_units::word_to_count(u16::from_be_bytes([axes[i], axes[i + 1]]));
        Ok(AccelCounts {
            xyz: [pair(4), pair(2), pair(0)],
            temp: sensor_units::word_to_count(u16::from_be_bytes([temp[0], temp[1]])),
        })
    }

    /// Specific force along the part's X, Y, Z in m/s^2.
    pub fn read_m_s2(&mut self) -> Result<[f32; 3], Error> {
        self.read_counts()
            .map(|c| c.xyz.map(sensor_units::accel_count_to_m_s2))
    }

    /// Temperature in degrees Celsius (formula UNVERIFIED, see
    /// `sensor_units::ACCEL_TEMPERATURE`); costs a full sample read.
    pub fn read_temperature_degc(&mut self) -> Result<f32, Error> {
        self.read_counts()
            .map(|c| ACCEL_TEMPERATURE.count_to_degc(c.temp))
    }
}

/// Checks one MISO status byte; `expected_dpar` is the parity of the
/// previous frame's data, if known.
pub fn check_status(status: u8, expected_dpar: Option<bool>) -> Result<(), Error> {
    if status == 0x00 || status == 0xFF {
        return Err(Error::NoResponse(Slave::Accel));
    }
    if !accel_status_fixed_bits_ok(status) {
        return Err(Error::BadStatus);
    }
    // A reset breaks the dPAR chain, so PORST is checked before dPAR.
    if status & accel_status::PORST != 0 {
        return Err(Error::PowerOnReset);
    }
    let dpar = status & accel_status::DPAR != 0;
    if expected_dpar.is_some_and(|e| e != dpar) {
        return Err(Error::Parity(Slave::Accel, Word::Data));
    }
    if status & accel_status::FRME != 0 {
        return Err(Error::FrameError);
    }
    if status & accel_status::ST != 0 {
        return Err(Error::SelfTest);
    }
    if status & accel_status::SAT != 0 {
        return Err(Error::Saturated(Slave::Accel));
    }
    Ok(())
}

fn tolerate_start_flags<T>(result: Result<T, Error>) -> Result<(), Error> {
    match result {
        Ok(_)
        | Err(Error::PowerOnReset)
        | Err(Error::Saturated(_))
        | Err(Error::FrameError)
        | Err(Error::Parity(Slave::Accel, Word::Data)) => Ok(()),
        Err(e) => Err(e),
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use embedded_hal_mock::eh1::delay::NoopDelay;
    use embedded_hal_mock::eh1::spi::{Mock, Transaction};
    use std::vec;

    /// A good status byte whose dPAR vouches for `previous` data bytes.
    fn ok_status(previous: &[u8]) -> u8 {
        0b0000_0010 | u8::from(odd_parity_of(previous))
    }

    fn frame(mosi: &[u8], miso: &[u8]) -> [Transaction<u8>; 3] {
        [
            Transaction::transaction_start(),
            Transaction::transfer_in_place(mosi.to_vec(), miso.to_vec()),
            Transaction::transaction_end(),
        ]
    }

    #[test]
    fn start_sends_int_status_then_ctrl_then_status() {
        let mut expect = vec![];
        // PORST on the first frames is expected during start-up.
        expect.extend(frame(&[0x58, 0x00], &[0b0010_0011, 0x00]));
        expect.extend(frame(&[0x07, 0x00], &[0b0010_0011, 0x00]));
        expect.extend(frame(&[0x08, 0x00], &[ok_status(&[0x00]), 0x00]));
        let mut spi = Mock::new(&expect);
        let mut accel = Accel::new(spi.clone());
        assert_eq!(accel.start(&mut NoopDelay::new()), Ok(()));
        spi.done();
    }

    #[test]
    fn burst_read_from_z_msb_decodes_axes_and_temperature() {
        // X = 650 (1 g) = 0x0A28, Y = -1 = 0xFFFC, Z = 0; temp count 0.
        let axes = [0x00, 0x00, 0xFF, 0xFC, 0x0A, 0x28];
        let temp = [0x00, 0x00];
        let mut expect = vec![];
        expect.extend(frame(
            &[0x25, 0, 0, 0, 0, 0, 0],
            &[0x03, 0x00, 0x00, 0xFF, 0xFC, 0x0A, 0x28],
        ));
        let mut temp_miso = vec![ok_status(&axes)];
        temp_miso.extend(temp);
        expect.extend(frame(&[0x4C, 0, 0], &temp_miso));
        expect.extend(frame(&[0x08, 0], &[ok_status(&temp), 0x00]));
        let mut spi = Mock::new(&expect);
        let mut accel = Accel::new(spi.clone());
        assert_eq!(
            accel.read_counts(),
            Ok(AccelCounts {
                xyz: [650, -1, 0],
                temp: 0
            })
        );
        spi.done();
    }

    #[test]
    fn saturation_is_acknowledged_through_int_status() {
        let mut expect = vec![];
        let sat = 0b0000_1010 | 1; // SAT, fixed bits, dPAR of nothing known
        expect.extend(frame(&[0x25, 0, 0, 0, 0, 0, 0], &[sat, 0, 0, 0, 0, 0, 0]));
        expect.extend(frame(&[0x58, 0], &[sat, 0]));
        let mut spi = Mock::new(&expect);
        let mut accel = Accel::new(spi.clone());
        assert_eq!(accel.read_counts(), Err(Error::Saturated(Slave::Accel)));
        spi.done();
    }

    #[test]
    fn status_byte_checks() {
        assert_eq!(check_status(0x02, None), Ok(()));
        assert_eq!(
            check_status(0xFF, None),
            Err(Error::NoResponse(Slave::Accel))
        );
        assert_eq!(
            check_status(0x00, None),
            Err(Error::NoResponse(Slave::Accel))
        );
        assert_eq!(check_status(0x06, None), Err(Error::BadStatus));
        assert_eq!(
            check_status(0x02, Some(true)),
            Err(Error::Parity(Slave::Accel, Word::Data))
        );
        assert_eq!(check_status(0x43, Some(true)), Err(Error::FrameError));
        assert_eq!(check_status(0x22, None), Err(Error::PowerOnReset));
        assert_eq!(check_status(0x12, None), Err(Error::SelfTest));
        assert_eq!(
            check_status(0x0A, None),
            Err(Error::Saturated(Slave::Accel))
        );
    }
}
