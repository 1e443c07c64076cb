//! The accelerometer slave (CSB_A): command byte + data bytes per
//! transaction, the burst read of the three axes from Z_MSB, temperature,
//! and the status byte's supervision [TN92].
//!
//! Every MISO status byte is checked: fixed bits, dPAR against the parity
//! of the data it covers (the previous frame's or this frame's, as
//! `datasheet::ACCEL_DPAR_SCOPE` says: the spec leaves it open), FRME (the
//! part rejected our previous frame), PORST, ST and SAT. Because FRME (and
//! dPAR in the `PreviousFrame` reading) speak about the previous frame, a
//! sample is three frames: the axes, the temperature (whose status vouches
//! for the axes) and STATUS (whose status vouches for the temperature).
//!
//! SAT means output saturated, invalid until INT_STATUS is read [spec,
//! from the SCA3100 family]: whichever frame shows it, and whatever other
//! flag comes with it, the sample is invalid and INT_STATUS is read before
//! the driver returns.

use embedded_hal::delay::DelayNs;
use embedded_hal::spi::{Error as _, SpiDevice};
use mwd_core::sensor_units;

use super::datasheet::{accel_reg, accel_status, DparScope, ACCEL_DPAR_SCOPE, ACCEL_SETTLE_MS};
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
    /// What dPAR covers ([`ACCEL_DPAR_SCOPE`] unless set otherwise).
    dpar_scope: DparScope,
    /// With [`DparScope::PreviousFrame`]: the dPAR the next status byte
    /// must carry; `None` when unknown (after construction or a failed
    /// transfer).
    expected_dpar: Option<bool>,
    /// A status byte that passed the fixed-bit check showed SAT since this
    /// was last cleared (by the operation that acknowledges it).
    sat_seen: bool,
}

impl<SPI: SpiDevice> Accel<SPI> {
    /// An accelerometer whose dPAR follows [`ACCEL_DPAR_SCOPE`].
    pub fn new(spi: SPI) -> Self {
        Self::with_dpar_scope(spi, ACCEL_DPAR_SCOPE)
    }

    /// An accelerometer whose dPAR covers `dpar_scope` (for tests of the
    /// other reading of the spec; the firmware uses [`Accel::new`]).
    pub fn with_dpar_scope(spi: SPI, dpar_scope: DparScope) -> Self {
        Self {
            spi,
            dpar_scope,
            expected_dpar: None,
            sat_seen: false,
        }
    }

    pub fn dpar_scope(&self) -> DparScope {
        self.dpar_scope
    }

    pub fn release(self) -> SPI {
        self.spi
    }

    /// True when the last [`Accel::read_counts`] (or [`Accel::start`]) saw
    /// SAT in any frame, even if another error was reported for it; the
    /// saturation has been acknowledged through INT_STATUS since.
    pub fn saturation_seen(&self) -> bool {
        self.sat_seen
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
        let previous = self.expected_dpar.take();
        let frame = buf.get_mut(..len).ok_or(Error::BadStatus)?;
        self.spi
            .transfer_in_place(frame)
            .map_err(|e| Error::Bus(Slave::Accel, e.kind()))?;
        let (status, data) = frame.split_first().ok_or(Error::BadStatus)?;
        let this_frame = odd_parity_of(data);
        let expected = match self.dpar_scope {
            DparScope::PreviousFrame => {
                self.expected_dpar = Some(this_frame);
                previous
            }
            DparScope::SameFrame => Some(this_frame),
        };
        if shows_saturation(*status) {
            self.sat_seen = true;
        }
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

    /// Reads one register (single frame; with
    /// [`DparScope::PreviousFrame`] its dPAR is checked by the next). A SAT
    /// in its status is returned, not acknowledged: that is up to the
    /// caller ([`Accel::acknowledge_saturation`]).
    pub fn read_register(&mut self, reg: u8) -> Result<u8, Error> {
        self.read(reg, 1).map(|d| d[0])
    }

    /// Writes one register (SAT in its status: as [`Accel::read_register`]).
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
    /// CTRL = 0x00 (clears PORST), wait [`ACCEL_SETTLE_MS`] (10 ms). Flags
    /// left over from power-up (PORST, SAT, FRME, dPAR of the unknown frame
    /// before) are expected on the first frames and not errors here; ST is.
    /// A SAT shown after the first INT_STATUS read is acknowledged again
    /// before returning.
    pub fn start(&mut self, delay: &mut impl DelayNs) -> Result<(), Error> {
        self.expected_dpar = None;
        tolerate_start_flags(self.read_register(accel_reg::INT_STATUS))?;
        // That read acknowledged any SAT shown so far.
        self.sat_seen = false;
        let result =
            tolerate_start_flags(self.write_register(accel_reg::CTRL, 0x00)).and_then(|()| {
                delay.delay_ms(ACCEL_SETTLE_MS);
                // This frame's status shows the state after CTRL = 0: PORST
                // must be gone now. SAT here is acknowledged below.
                match self.read_register(accel_reg::STATUS) {
                    Err(Error::Saturated(_)) => Ok(()),
                    other => other.map(|_| ()),
                }
            });
        self.acknowledge_if_seen(result)
    }

    /// If a frame since `sat_seen` was cleared showed SAT: reads INT_STATUS
    /// to acknowledge it, and returns the error that matters most: one
    /// that needs recovery, else the operation's own.
    fn acknowledge_if_seen<T>(&mut self, result: Result<T, Error>) -> Result<T, Error> {
        if !self.sat_seen {
            return result;
        }
        let ack = self.acknowledge_saturation();
        match (result, ack) {
            (Err(e), _) if e.needs_recovery() => Err(e),
            (_, Err(a)) if a.needs_recovery() => Err(a),
            (result, _) => result,
        }
    }

    /// Axes X, Y, Z and temperature in counts: burst read from Z_MSB
    /// (command 0x25: Z_MSB, Z_LSB, Y_MSB, Y_LSB, X_MSB, X_LSB), then the
    /// temperature pair from TEMP_MSB, then STATUS, each frame's status
    /// vouching for the previous frame. SAT in any of the three frames,
    /// alone or with other flags, makes the sample invalid and is
    /// acknowledged through INT_STATUS before returning; the error is
    /// [`Error::Saturated`] unless another flag came with it (then that
    /// flag's error; [`Accel::saturation_seen`] still tells).
    pub fn read_counts(&mut self) -> Result<AccelCounts, Error> {
        self.sat_seen = false;
        let result = self.read_sample_frames();
        self.acknowledge_if_seen(result)
    }

    fn read_sample_frames(&mut self) -> Result<AccelCounts, Error> {
        let axes = self.read(accel_reg::Z_MSB, 6)?;
        let temp = self.read(accel_reg::TEMP_MSB, 2)?;
        self.read_register(accel_reg::STATUS)?;
        let pair =
            |i: usize| sensor_units::word_to_count(u16::from_be_bytes([axes[i], axes[i + 1]]));
        Ok(AccelCounts {
            xyz: [pair(4), pair(2), pair(0)],
            temp: sensor_units::word_to_count(u16::from_be_bytes([temp[0], temp[1]])),
        })
    }
}

/// True when a status byte that looks like one (fixed bits right, so not a
/// dead line either) carries SAT.
fn shows_saturation(status: u8) -> bool {
    accel_status_fixed_bits_ok(status) && status & accel_status::SAT != 0
}

/// Checks one MISO status byte; `expected_dpar` is the parity of the data
/// its dPAR covers (see [`DparScope`]), if known. Flags are reported in the
/// order PORST, dPAR, FRME, ST, SAT; SAT is the least of them.
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
    use std::vec::Vec;

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

    /// A SAT status byte (fixed bits, SAT) plus `extra` flags and dPAR.
    fn sat(extra: u8, dpar: bool) -> u8 {
        0b0000_1010 | extra | u8::from(dpar)
    }

    const AXES_CMD: [u8; 7] = [0x25, 0, 0, 0, 0, 0, 0];
    const AXES: [u8; 6] = [0x00, 0x00, 0xFF, 0xFC, 0x0A, 0x28];
    const TEMP_CMD: [u8; 3] = [0x4C, 0, 0];
    const STATUS_CMD: [u8; 2] = [0x08, 0];
    const INT_STATUS_CMD: [u8; 2] = [0x58, 0];

    fn axes_miso(status: u8) -> Vec<u8> {
        let mut v = vec![status];
        v.extend(AXES);
        v
    }

    #[test]
    fn sat_in_the_temperature_or_status_frame_is_acknowledged() {
        // SAT first shows in the temperature frame's status.
        let mut expect = vec![];
        expect.extend(frame(&AXES_CMD, &axes_miso(0x03)));
        expect.extend(frame(&TEMP_CMD, &[sat(0, odd_parity_of(&AXES)), 0, 0]));
        expect.extend(frame(&INT_STATUS_CMD, &[sat(0, true), 1]));
        // Then in the STATUS frame's status.
        expect.extend(frame(&AXES_CMD, &axes_miso(ok_status(&[1]))));
        expect.extend(frame(&TEMP_CMD, &[ok_status(&AXES), 0, 0]));
        expect.extend(frame(&STATUS_CMD, &[sat(0, true), 0]));
        expect.extend(frame(&INT_STATUS_CMD, &[sat(0, true), 1]));
        let mut spi = Mock::new(&expect);
        let mut accel = Accel::with_dpar_scope(spi.clone(), DparScope::PreviousFrame);
        for _ in 0..2 {
            assert_eq!(accel.read_counts(), Err(Error::Saturated(Slave::Accel)));
            assert!(accel.saturation_seen());
        }
        spi.done();
    }

    #[test]
    fn sat_with_frme_st_or_bad_dpar_is_acknowledged_and_the_other_flag_reported() {
        let mut expect = vec![];
        // SAT + ST in the axes frame.
        expect.extend(frame(&AXES_CMD, &axes_miso(sat(0x10, true))));
        expect.extend(frame(
            &INT_STATUS_CMD,
            &[sat(0x10, odd_parity_of(&AXES)), 1],
        ));
        // SAT + FRME in the temperature frame.
        expect.extend(frame(&AXES_CMD, &axes_miso(ok_status(&[1]))));
        expect.extend(frame(&TEMP_CMD, &[sat(0x40, odd_parity_of(&AXES)), 0, 0]));
        expect.extend(frame(&INT_STATUS_CMD, &[sat(0, true), 1]));
        // SAT + wrong dPAR in the temperature frame.
        expect.extend(frame(&AXES_CMD, &axes_miso(ok_status(&[1]))));
        expect.extend(frame(&TEMP_CMD, &[sat(0, !odd_parity_of(&AXES)), 0, 0]));
        expect.extend(frame(&INT_STATUS_CMD, &[sat(0, true), 1]));
        // SAT + PORST: PORST wins (it asks for recovery), SAT acknowledged.
        expect.extend(frame(&AXES_CMD, &axes_miso(sat(0x20, true))));
        expect.extend(frame(&INT_STATUS_CMD, &[sat(0x20, true), 1]));
        let mut spi = Mock::new(&expect);
        let mut accel = Accel::with_dpar_scope(spi.clone(), DparScope::PreviousFrame);
        assert_eq!(accel.read_counts(), Err(Error::SelfTest));
        assert!(accel.saturation_seen());
        assert_eq!(accel.read_counts(), Err(Error::FrameError));
        assert_eq!(
            accel.read_counts(),
            Err(Error::Parity(Slave::Accel, Word::Data))
        );
        assert_eq!(accel.read_counts(), Err(Error::PowerOnReset));
        spi.done();
    }

    #[test]
    fn sat_after_int_status_in_start_up_is_acknowledged_again() {
        let mut expect = vec![];
        expect.extend(frame(&[0x58, 0x00], &[0b0010_0011, 0x00]));
        expect.extend(frame(&[0x07, 0x00], &[0b0010_0011, 0x00]));
        // SAT + FRME after CTRL = 0: FRME reported, SAT acknowledged.
        expect.extend(frame(&STATUS_CMD, &[sat(0x40, true), 0x00]));
        expect.extend(frame(&INT_STATUS_CMD, &[sat(0, true), 1]));
        let mut spi = Mock::new(&expect);
        let mut accel = Accel::new(spi.clone());
        assert_eq!(accel.start(&mut NoopDelay::new()), Err(Error::FrameError));
        spi.done();
    }

    #[test]
    fn same_frame_dpar_is_checked_in_its_own_frame() {
        let mut expect = vec![];
        // Good: every status vouches for its own frame's data.
        expect.extend(frame(&AXES_CMD, &axes_miso(ok_status(&AXES))));
        expect.extend(frame(&TEMP_CMD, &[ok_status(&[0, 0]), 0, 0]));
        expect.extend(frame(&STATUS_CMD, &[ok_status(&[0x00]), 0x00]));
        // The axes frame's dPAR is wrong: caught at once, no more frames.
        expect.extend(frame(&AXES_CMD, &axes_miso(ok_status(&AXES) ^ 1)));
        let mut spi = Mock::new(&expect);
        let mut accel = Accel::with_dpar_scope(spi.clone(), DparScope::SameFrame);
        assert_eq!(accel.dpar_scope(), DparScope::SameFrame);
        assert_eq!(
            accel.read_counts(),
            Ok(AccelCounts {
                xyz: [650, -1, 0],
                temp: 0
            })
        );
        assert_eq!(
            accel.read_counts(),
            Err(Error::Parity(Slave::Accel, Word::Data))
        );
        spi.done();
    }

    #[test]
    fn the_default_scope_is_the_datasheet_switch() {
        let mut spi = Mock::new(&[]);
        let accel = Accel::new(spi.clone());
        assert_eq!(accel.dpar_scope(), ACCEL_DPAR_SCOPE);
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
