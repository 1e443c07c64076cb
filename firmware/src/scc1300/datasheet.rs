//! Register map, bit positions, timings and the datasheet values that are
//! not verified, in one place. Source: `docs/scc1300.md` ("the spec"), which
//! condenses Murata TN92 "SPI communication with SCC1300" (Rev. 1.1), the
//! SCC1300-D04 datasheet front pages (doc 82 1131 00) and third-party
//! drivers. Sensitivities and count conversions live in
//! `mwd_core::sensor_units`, shared with the mock and the host.

/// Gyro registers [TN92].
pub mod gyro_reg {
    pub const RATE_X: u8 = 0x00;
    /// Reads the IC identification; writing [`super::GYRO_SOFT_RESET_DATA`]
    /// soft-resets the gyro.
    pub const IC_ID: u8 = 0x07;
    pub const STATUS: u8 = 0x08;
    pub const TEMP: u8 = 0x0A;
}

/// Accelerometer registers [TN92].
pub mod accel_reg {
    pub const REVID: u8 = 0x00;
    pub const CTRL: u8 = 0x01;
    pub const STATUS: u8 = 0x02;
    pub const RESET: u8 = 0x03;
    pub const X_LSB: u8 = 0x04;
    pub const X_MSB: u8 = 0x05;
    pub const Y_LSB: u8 = 0x06;
    pub const Y_MSB: u8 = 0x07;
    pub const Z_LSB: u8 = 0x08;
    pub const Z_MSB: u8 = 0x09;
    pub const TEMP_LSB: u8 = 0x12;
    pub const TEMP_MSB: u8 = 0x13;
    pub const INT_STATUS: u8 = 0x16;
    pub const ID: u8 = 0x27;
}

/// Gyro MISO status word (word 1) and STATUS register bits [TN92].
pub const GYRO_S_OK: u16 = 1 << 1;
/// LOOPF_OK, in the STATUS register (0x08) only [TN92].
pub const GYRO_LOOPF_OK: u16 = 1 << 2;
/// Data written to IC_ID for a soft reset ("bit 1"), before the shift and
/// parity of the write word: gives MOSI word 2 = 0x0004 [TN92].
pub const GYRO_SOFT_RESET_DATA: u16 = 1 << 1;

/// Accelerometer MISO status byte `[-, FRME, PORST, ST, SAT, 0, 1, dPAR]`
/// [TN92; meanings from the SCA3100 family, per the spec].
pub mod accel_status {
    pub const FRME: u8 = 1 << 6;
    pub const PORST: u8 = 1 << 5;
    pub const ST: u8 = 1 << 4;
    pub const SAT: u8 = 1 << 3;
    /// Bits 2..1 always read `0 1`: a cheap check that the slave answers.
    pub const FIXED_MASK: u8 = 0b0000_0110;
    pub const FIXED_VALUE: u8 = 0b0000_0010;
    pub const DPAR: u8 = 1 << 0;
}

/// Wait after power-up (and after a gyro soft reset) before the first
/// access [TN92 step 1].
pub const POWER_UP_WAIT_MS: u32 = 800;
/// Accelerometer settling after CTRL = 0x00 [TN92 step 3].
pub const ACCEL_SETTLE_MS: u32 = 10;
/// Gyro supervision: wait between the two STATUS reads after S_OK dropped
/// [TN92 step 4].
pub const GYRO_RECHECK_WAIT_MS: u32 = 60;

/// UNVERIFIED: maximum SPI clock. The datasheet's figure was not available;
/// TN92's example runs at 500 kHz; the spec says keep <= 1 MHz.
pub const SPI_MAX_CLOCK_HZ: u32 = 1_000_000;
/// The clock TN92 itself uses; the board code should configure this.
pub const SPI_CLOCK_HZ: u32 = 500_000;

/// UNVERIFIED: gyro IC_ID, accelerometer ID and REVID values are unknown
/// (spec). `None` means "read and log, do not check".
pub const GYRO_IC_ID_EXPECTED: Option<u16> = None;
pub const ACCEL_ID_EXPECTED: Option<u8> = None;

/// Which accelerometer frame the dPAR bit of a MISO status byte protects.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DparScope {
    /// dPAR is the odd-parity bit over the MISO data bytes of the
    /// *previous* accelerometer frame ("delayed parity"): checked one
    /// transaction late.
    PreviousFrame,
    /// dPAR is the odd-parity bit over the MISO data bytes of the *same*
    /// frame: checked as soon as the frame is in.
    SameFrame,
}

/// UNVERIFIED, the single switch for the meaning of the accelerometer's
/// dPAR bit; the driver ([`super::accel::Accel::new`]) follows it, and the
/// driver-against-mock tests configure hil-mock's `Scc1300::dpar_scope`
/// from it (they also check that the mock's default agrees).
///
/// What the spec says (`docs/scc1300.md`, "Accelerometer part"): only the
/// status byte `[-, FRME, PORST, ST, SAT, 0, 1, dPAR]` ahead of the data,
/// and odd parity as the bus's only check, no CRC (section "Bus"). Its
/// meanings from the SCA3100 family cover SAT, ST, FRME (an error in the
/// previous frame) and PORST, not dPAR. So neither the frame nor the
/// bytes dPAR covers is documented; the full datasheet (Murata doc
/// 82 1131 00) was not available.
///
/// An earlier note argued that dPAR "cannot protect this frame's data"
/// because it is clocked out before the command is decoded. That does not
/// hold: dPAR is the last status bit, shifted out on the falling edge after
/// the 7th SCK rising edge, by which time A5..A0 and RW are in (only the
/// command's P bit is still to come), so the part could compute the parity
/// of the addressed data in time. Both readings are therefore possible;
/// `PreviousFrame` stays the default because it is what the driver, the
/// mock and the recorded QEMU captures have used so far. Both settings are
/// tested against the mock. In both, dPAR is taken over *all* data bytes of
/// the frame (six for the axis burst), which is unverified too. Correct
/// this constant (and hil-mock's `DEFAULT_DPAR_SCOPE`) once the datasheet
/// is found.
pub const ACCEL_DPAR_SCOPE: DparScope = DparScope::PreviousFrame;
