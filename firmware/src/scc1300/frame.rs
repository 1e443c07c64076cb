//! SPI words of the two slaves: command words with odd parity, and the
//! checks of the words the part answers [TN92].
//!
//! Gyro: one 32-bit transaction per access, CSB_G low throughout: MOSI
//! `cmd, data`, MISO `status, data`, each a 16-bit word whose bit 0 makes
//! the word's parity odd. The answer is in-frame: word 2 carries the
//! register named by word 1 of the same transaction.
//! Accelerometer: MOSI byte 1 = `A5..A0, RW, P` with odd parity over the
//! byte, then data bytes; MISO byte 1 = status, then in-frame data.

use super::datasheet::accel_status;

/// Bit that gives `value` (whose bit 0 is clear) odd parity.
const fn parity_bit(ones: u32) -> u16 {
    if ones % 2 == 0 {
        1
    } else {
        0
    }
}

/// True when the word holds an odd number of ones (parity bit included).
pub const fn is_odd_parity(word: u16) -> bool {
    word.count_ones() % 2 == 1
}

/// Gyro MOSI word 1: `addr << 3 | RW << 2 | 0 << 1 | P`.
pub const fn gyro_command(addr: u8, write: bool) -> u16 {
    let word = ((addr as u16) << 3) | ((write as u16) << 2);
    word | parity_bit(word.count_ones())
}

/// Gyro MOSI word 2 of a write: `data << 1 | P` (15 data bits).
pub const fn gyro_write_word(data: u16) -> u16 {
    let word = data << 1;
    word | parity_bit(word.count_ones())
}

/// Gyro MOSI word 2 of a read.
pub const GYRO_READ_WORD: u16 = 0x0001;

/// Accelerometer MOSI byte 1: `A5..A0, RW, P`.
pub const fn accel_command(addr: u8, write: bool) -> u8 {
    let byte = ((addr & 0x3F) << 2) | ((write as u8) << 1);
    byte | parity_bit(byte.count_ones()) as u8
}

/// Odd-parity bit over a run of bytes (the accelerometer's dPAR rule).
pub fn odd_parity_of(bytes: &[u8]) -> bool {
    let ones: u32 = bytes.iter().map(|b| b.count_ones()).sum();
    ones % 2 == 0
}

/// Words that a slave with a dead chip select or a floating/stuck MISO
/// line returns: all zeros or all ones.
pub const fn is_dead_word(word: u16) -> bool {
    word == 0x0000 || word == 0xFFFF
}

/// The accelerometer status byte's fixed bits `0 1` in bits 2..1.
pub const fn accel_status_fixed_bits_ok(status: u8) -> bool {
    status & accel_status::FIXED_MASK == accel_status::FIXED_VALUE
}

#[cfg(test)]
mod tests {
    use super::super::datasheet::{accel_reg, gyro_reg, GYRO_SOFT_RESET_DATA};
    use super::*;

    #[test]
    fn gyro_words_match_the_spec() {
        // The spec's computed command words [TN92].
        assert_eq!(gyro_command(gyro_reg::RATE_X, false), 0x0001);
        assert_eq!(gyro_command(gyro_reg::IC_ID, false), 0x0038);
        assert_eq!(gyro_command(gyro_reg::STATUS, false), 0x0040);
        assert_eq!(gyro_command(gyro_reg::TEMP, false), 0x0051);
        assert_eq!(gyro_command(gyro_reg::IC_ID, true), 0x003D);
        assert_eq!(gyro_write_word(GYRO_SOFT_RESET_DATA), 0x0004);
    }

    #[test]
    fn accel_bytes_match_the_spec() {
        assert_eq!(accel_command(accel_reg::Z_MSB, false), 0x25);
        assert_eq!(accel_command(accel_reg::INT_STATUS, false), 0x58);
        assert_eq!(accel_command(accel_reg::CTRL, true), 0x07);
        assert_eq!(accel_command(accel_reg::TEMP_MSB, false), 0x4C);
        assert_eq!(accel_command(accel_reg::STATUS, false), 0x08);
    }

    #[test]
    fn every_command_word_has_odd_parity() {
        for addr in 0..32u8 {
            for write in [false, true] {
                assert!(is_odd_parity(gyro_command(addr, write)));
            }
        }
        for addr in 0..64u8 {
            for write in [false, true] {
                assert!(is_odd_parity(u16::from(accel_command(addr, write))));
            }
        }
        for data in 0..0x8000u16 {
            assert!(is_odd_parity(gyro_write_word(data)));
        }
    }

    #[test]
    fn parity_checks_and_dead_words() {
        assert!(is_odd_parity(0x0001));
        assert!(!is_odd_parity(0x0003));
        assert!(odd_parity_of(&[]));
        assert!(!odd_parity_of(&[0x01]));
        assert!(odd_parity_of(&[0x03]));
        assert!(is_dead_word(0xFFFF) && is_dead_word(0));
        assert!(accel_status_fixed_bits_ok(0b0000_0010));
        assert!(!accel_status_fixed_bits_ok(0xFF));
        assert!(!accel_status_fixed_bits_ok(0x00));
    }
}
