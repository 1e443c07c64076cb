//! The two slaves of a part as embedded-hal 1.0 `SpiDevice`s, each its own
//! chip select, sharing the part through a `RefCell`. Link faults (dead chip
//! select, stuck and noisy bits, parity flips on either side) are applied
//! here, between the master and the part's logic.

use core::cell::RefCell;
use embedded_hal::spi::{self, ErrorKind, ErrorType, Operation, SpiDevice};

use crate::clock::TimeSource;
use crate::faults::{DeadLevel, LinkFaults, Rng};
use crate::part::Scc1300;
use crate::source::SampleSource;
use crate::{accel, gyro};

/// Longest frame the mock handles in one chip-select period; longer frames
/// are answered with the first bytes only and counted as MOSI errors by the
/// slave's frame logic (wrong length).
pub const MAX_FRAME: usize = 16;

/// The mock's bus error: the part was already borrowed (re-entrant use).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MockBusError;

impl spi::Error for MockBusError {
    fn kind(&self) -> ErrorKind {
        ErrorKind::Other
    }
}

impl core::fmt::Display for MockBusError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str("the simulated SCC1300 part was already in use (re-entrant SPI transaction)")
    }
}

impl core::error::Error for MockBusError {}

#[derive(Clone, Copy)]
enum Which {
    Gyro,
    Accel,
}

fn run<T: TimeSource, S: SampleSource>(
    part: &RefCell<Scc1300<T, S>>,
    which: Which,
    operations: &mut [Operation<'_, u8>],
) -> Result<(), MockBusError> {
    let mut part = part.try_borrow_mut().map_err(|_| MockBusError)?;
    let part = &mut *part;
    // Gather what the master clocks out during this chip-select period.
    let mut mosi = [0u8; MAX_FRAME];
    let mut len = 0usize;
    let mut push = |bytes: &mut dyn Iterator<Item = u8>| {
        for b in bytes {
            if let Some(slot) = mosi.get_mut(len) {
                *slot = b;
            }
            len = len.saturating_add(1);
        }
    };
    for op in operations.iter() {
        match op {
            Operation::Read(buf) => push(&mut buf.iter().map(|_| 0)),
            Operation::Write(buf) => push(&mut buf.iter().copied()),
            Operation::Transfer(read, write) => {
                let n = read.len().max(write.len());
                push(&mut (0..n).map(|i| write.get(i).copied().unwrap_or(0)))
            }
            Operation::TransferInPlace(buf) => push(&mut buf.iter().copied()),
            Operation::DelayNs(_) => {}
        }
    }
    let frame_len = len.min(MAX_FRAME);
    let mut miso = [0u8; MAX_FRAME];
    let (mosi, miso_frame) = match (mosi.get_mut(..frame_len), miso.get_mut(..frame_len)) {
        (Some(a), Some(b)) => (a, b),
        _ => return Err(MockBusError),
    };
    let faults = match which {
        Which::Gyro => part.faults.gyro,
        Which::Accel => part.faults.accel,
    };
    match faults.dead {
        Some(level) => miso_frame.fill(match level {
            DeadLevel::Low => 0x00,
            DeadLevel::High => 0xFF,
        }),
        None => {
            let mut link = faults;
            if link.mosi_bit_flip.fires(&mut part.rng) {
                let protected = match which {
                    Which::Gyro => 4,
                    Which::Accel => 1,
                };
                let end = protected.min(mosi.len());
                flip_random_bit(mosi.get_mut(..end).unwrap_or_default(), &mut part.rng);
            }
            // A frame longer than MAX_FRAME is wrong for both slaves: pass a
            // truncated command that fails their length checks.
            let seen = if len > MAX_FRAME { &mosi[..0] } else { &*mosi };
            match which {
                Which::Gyro => gyro::frame(part, seen, miso_frame),
                Which::Accel => accel::frame(part, seen, miso_frame),
            }
            corrupt_miso(&mut link, which, miso_frame, &mut part.rng);
            // Chances are stateful (forced frame counts): write them back.
            match which {
                Which::Gyro => part.faults.gyro = link,
                Which::Accel => part.faults.accel = link,
            }
        }
    }
    // Hand the answer back to the master's read buffers, in order.
    let mut answer = miso_frame.iter().copied();
    for op in operations.iter_mut() {
        match op {
            Operation::Read(buf) | Operation::TransferInPlace(buf) => buf
                .iter_mut()
                .for_each(|b| *b = answer.next().unwrap_or(0xFF)),
            Operation::Transfer(read, write) => {
                let n = read.len().max(write.len());
                let mut taken = answer.by_ref().take(n);
                read.iter_mut()
                    .for_each(|b| *b = taken.next().unwrap_or(0xFF));
                taken.for_each(drop);
            }
            Operation::Write(buf) => answer.by_ref().take(buf.len()).for_each(drop),
            Operation::DelayNs(_) => {}
        }
    }
    Ok(())
}

fn flip_random_bit(bytes: &mut [u8], rng: &mut Rng) {
    let n = u32::try_from(bytes.len()).unwrap_or(0);
    let bit = rng.below(n.saturating_mul(8));
    if let Some(b) = bytes.get_mut((bit / 8) as usize) {
        *b ^= 1 << (bit % 8);
    }
}

fn corrupt_miso(link: &mut LinkFaults, which: Which, miso: &mut [u8], rng: &mut Rng) {
    if link.miso_parity.fires(rng) {
        // Gyro: bit 0 of word 1 or word 2; accelerometer: dPAR (bit 0 of the
        // status byte).
        let byte = match which {
            Which::Gyro => 1 + 2 * (rng.below(2) as usize),
            Which::Accel => 0,
        };
        if let Some(b) = miso.get_mut(byte) {
            *b ^= 1;
        }
    }
    if link.miso_bit_flip.fires(rng) {
        match which {
            Which::Gyro => flip_random_bit(miso, rng),
            // Not dPAR (bit 0 of the status byte): with
            // `DparScope::PreviousFrame` dPAR vouches for the previous
            // frame, so a flip there could cancel a flip in that frame's
            // data and make two single-bit faults one undetectable double
            // error. dPAR has its own fault, `miso_parity`.
            Which::Accel => {
                let n = u32::try_from(miso.len()).unwrap_or(0);
                let bit = 1 + rng.below(n.saturating_mul(8).saturating_sub(1));
                if let Some(b) = miso.get_mut((bit / 8) as usize) {
                    *b ^= 1 << (bit % 8);
                }
            }
        }
    }
    for (i, b) in miso.iter_mut().take(4).enumerate() {
        let shift = 24 - 8 * i as u32;
        let high = (link.miso_stuck_high >> shift) as u8;
        let low = (link.miso_stuck_low >> shift) as u8;
        *b = (*b | high) & !low;
    }
}

/// The gyro slave (CSB_G) of a shared part.
pub struct GyroSpi<'a, T, S> {
    part: &'a RefCell<Scc1300<T, S>>,
}

/// The accelerometer slave (CSB_A) of a shared part.
pub struct AccelSpi<'a, T, S> {
    part: &'a RefCell<Scc1300<T, S>>,
}

impl<'a, T, S> GyroSpi<'a, T, S> {
    pub fn new(part: &'a RefCell<Scc1300<T, S>>) -> Self {
        Self { part }
    }
}

impl<'a, T, S> AccelSpi<'a, T, S> {
    pub fn new(part: &'a RefCell<Scc1300<T, S>>) -> Self {
        Self { part }
    }
}

impl<T, S> ErrorType for GyroSpi<'_, T, S> {
    type Error = MockBusError;
}

impl<T, S> ErrorType for AccelSpi<'_, T, S> {
    type Error = MockBusError;
}

impl<T: TimeSource, S: SampleSource> SpiDevice for GyroSpi<'_, T, S> {
    fn transaction(&mut self, operations: &mut [Operation<'_, u8>]) -> Result<(), MockBusError> {
        run(self.part, Which::Gyro, operations)
    }
}

impl<T: TimeSource, S: SampleSource> SpiDevice for AccelSpi<'_, T, S> {
    fn transaction(&mut self, operations: &mut [Operation<'_, u8>]) -> Result<(), MockBusError> {
        run(self.part, Which::Accel, operations)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::clock::SimClock;
    use crate::faults::Chance;
    use crate::source::Constant;

    #[test]
    fn operations_of_any_shape_reach_the_part() {
        let clock = SimClock::new();
        let part = RefCell::new(Scc1300::new(&clock, Constant::default(), 1));
        clock.advance_ms(800);
        let mut gyro = GyroSpi::new(&part);
        // Write the command, then read the answer words.
        let mut answer = [0u8; 2];
        gyro.transaction(&mut [
            Operation::Write(&[0x00, 0x40]),
            Operation::Transfer(&mut answer, &[0x00, 0x01]),
        ])
        .unwrap();
        assert_eq!(
            answer,
            [0x00, 0x04],
            "STATUS: latched S_OK clear, LOOPF_OK set"
        );
        assert_eq!(part.borrow().stats().gyro_mosi_errors, 0);
    }

    #[test]
    fn a_part_in_use_is_a_bus_error_that_says_so() {
        extern crate std;
        use std::string::ToString;
        let clock = SimClock::new();
        let part = RefCell::new(Scc1300::new(&clock, Constant::default(), 1));
        let _held = part.borrow_mut();
        let mut buf = [0x08, 0x00];
        let error = AccelSpi::new(&part).transfer_in_place(&mut buf);
        assert_eq!(error, Err(MockBusError));
        assert!(MockBusError.to_string().contains("already in use"));
    }

    #[test]
    fn dead_chip_select_and_stuck_bits() {
        let clock = SimClock::new();
        let part = RefCell::new(Scc1300::new(&clock, Constant::default(), 1));
        part.borrow_mut().faults.accel.dead = Some(DeadLevel::High);
        let mut accel = AccelSpi::new(&part);
        let mut buf = [0x08, 0x00];
        accel.transfer_in_place(&mut buf).unwrap();
        assert_eq!(buf, [0xFF, 0xFF]);
        assert_eq!(part.borrow().stats().accel_frames, 0, "never selected");
        {
            let mut p = part.borrow_mut();
            p.faults.accel.dead = None;
            p.faults.accel.miso_stuck_low = 0x0200_0000; // status bit 1
            p.faults.accel.mosi_bit_flip = Chance::next(1);
        }
        let mut buf = [0x08, 0x00];
        accel.transfer_in_place(&mut buf).unwrap();
        assert_eq!(buf[0] & 0x02, 0);
        assert_eq!(part.borrow().stats().accel_mosi_errors, 1);
    }
}
