//! A power cut in the middle of a configuration write, made on purpose:
//! the QEMU probe built with the feature `power-cut-test` wraps its flash
//! in [`PowerCutFlash`], which programs only the first bytes of a write
//! and then cuts the power (a reset that the next boot reports as
//! power-on). The end-to-end test (tests/tests/qemu_power_cut.rs) then
//! checks what the two-slot store promises
//! ([`super::config_store`]): after the cut the previous configuration
//! loads. The normal builds never construct it.
//!
//! Which write is cut, and where, is [`POWER_CUT_PLAN`], indexed by the
//! write's number in the run (counted across the resets by the board).

use embedded_storage::nor_flash::{ErrorType, NorFlash, ReadNorFlash};
use mwd_core::config::record::RECORD_LEN;

/// Bytes of each write of the run that reach the flash before the power
/// goes, by the write's number (the first is 0); `None`, and every write
/// past the plan, is whole. In the record's layout
/// (`mwd_core::config::record`: magic 4, format 2, version 4, ..., CRC 4):
/// - write 0 whole: the configuration the cuts must leave in place;
/// - 0: the slot erased, nothing programmed;
/// - 8: in the header (the version half written);
/// - 150: in the body (part 0's calibration);
/// - `RECORD_LEN - 2`: half the CRC;
/// - `RECORD_LEN`: the whole record, power lost before the ACK: the new
///   configuration is committed (the control that the cut writes do reach
///   the flash).
pub const POWER_CUT_PLAN: [Option<usize>; 6] = [
    None,
    Some(0),
    Some(8),
    Some(150),
    Some(RECORD_LEN - 2),
    Some(RECORD_LEN),
];

/// The board's power, as the power-cut test sees it.
pub trait PowerSupply {
    /// The number of this write in the run (counted across resets), and
    /// the count moves on.
    fn next_write(&mut self) -> usize;
    /// Cuts the power: the board restarts as from power-on.
    fn cut(&mut self) -> !;
}

/// A flash whose writes are cut as [`POWER_CUT_PLAN`] says.
pub struct PowerCutFlash<F, P> {
    inner: F,
    power: P,
}

impl<F, P> PowerCutFlash<F, P> {
    pub fn new(inner: F, power: P) -> Self {
        Self { inner, power }
    }
}

/// The largest write unit [`program_prefix`] handles (STM32F4 at most 4,
/// the RAM flash 4).
const MAX_WRITE_SIZE: usize = 16;

/// Programs the first `keep` bytes of `bytes` at `offset`, the rest left
/// as they were (erased): the write unit holding the cut is padded with
/// 0xFF, which NOR programming leaves unchanged.
pub fn program_prefix<F: NorFlash>(
    flash: &mut F,
    offset: u32,
    bytes: &[u8],
    keep: usize,
) -> Result<(), F::Error> {
    let keep = keep.min(bytes.len());
    let whole = keep / F::WRITE_SIZE * F::WRITE_SIZE;
    if whole > 0 {
        flash.write(offset, bytes.get(..whole).unwrap_or_default())?;
    }
    let rest = bytes.get(whole..keep).unwrap_or_default();
    if rest.is_empty() || F::WRITE_SIZE > MAX_WRITE_SIZE {
        return Ok(());
    }
    let mut unit = [0xFFu8; MAX_WRITE_SIZE];
    unit.iter_mut().zip(rest).for_each(|(to, from)| *to = *from);
    // `whole` is within `bytes`, whose length the caller's offset fits.
    flash.write(
        offset + whole as u32,
        unit.get(..F::WRITE_SIZE).unwrap_or_default(),
    )
}

impl<F: ErrorType, P> ErrorType for PowerCutFlash<F, P> {
    type Error = F::Error;
}

impl<F: ReadNorFlash, P> ReadNorFlash for PowerCutFlash<F, P> {
    const READ_SIZE: usize = F::READ_SIZE;

    fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), Self::Error> {
        self.inner.read(offset, bytes)
    }

    fn capacity(&self) -> usize {
        self.inner.capacity()
    }
}

impl<F: NorFlash, P: PowerSupply> NorFlash for PowerCutFlash<F, P> {
    const WRITE_SIZE: usize = F::WRITE_SIZE;
    const ERASE_SIZE: usize = F::ERASE_SIZE;

    fn erase(&mut self, from: u32, to: u32) -> Result<(), Self::Error> {
        self.inner.erase(from, to)
    }

    fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), Self::Error> {
        let planned = POWER_CUT_PLAN.get(self.power.next_write()).copied();
        match planned.flatten() {
            Some(keep) => {
                program_prefix(&mut self.inner, offset, bytes, keep)?;
                self.power.cut()
            }
            None => self.inner.write(offset, bytes),
        }
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::app::config_store::{ConfigStore, LoadSource};
    use crate::app::ram_flash::{RamNorFlash, RAM_FLASH_ERASE_SIZE};
    use mwd_core::config::ProbeConfig;
    use mwd_core::earth::Position;
    use std::panic::{catch_unwind, AssertUnwindSafe};

    /// Counts writes like the QEMU board's persistent counter; the cut
    /// unwinds out of the save, as the reset leaves it.
    struct Bench<'a>(&'a mut usize);

    impl PowerSupply for Bench<'_> {
        fn next_write(&mut self) -> usize {
            *self.0 += 1;
            *self.0 - 1
        }
        fn cut(&mut self) -> ! {
            std::panic::panic_any("power cut")
        }
    }

    #[test]
    fn a_prefix_keeps_exactly_its_bytes() {
        for keep in 0..12 {
            let mut memory = [0u8; RAM_FLASH_ERASE_SIZE];
            let mut flash = RamNorFlash::new(&mut memory);
            flash.erase(0, RAM_FLASH_ERASE_SIZE as u32).unwrap();
            let bytes: std::vec::Vec<u8> = (1..=12).collect();
            program_prefix(&mut flash, 4, &bytes, keep).unwrap();
            for (i, cell) in memory[4..16].iter().enumerate() {
                let expected = if i < keep { bytes[i] } else { 0xFF };
                assert_eq!(*cell, expected, "keep {keep}, byte {i}");
            }
        }
    }

    /// The plan run on the host against the same store and RAM flash as
    /// the QEMU probe: each cut leaves the previous version, except the
    /// one after the record's last byte.
    #[test]
    fn every_planned_cut_leaves_a_whole_configuration() {
        let mut memory = [0u8; 2 * RAM_FLASH_ERASE_SIZE];
        let mut writes = 0;
        let mut stored = 0;
        for (step, planned) in POWER_CUT_PLAN.iter().enumerate() {
            let config = ProbeConfig {
                version: stored + 1,
                site: Position::new(0.1 * step as f64, 0.2, 10.0),
                ..ProbeConfig::default()
            };
            let flash = PowerCutFlash::new(RamNorFlash::new(&mut memory), Bench(&mut writes));
            let mut store = ConfigStore::new(flash, 0).unwrap();
            let saved = catch_unwind(AssertUnwindSafe(|| store.save(&config)));
            assert_eq!(saved.is_err(), planned.is_some(), "step {step}");
            let mut store = ConfigStore::new(RamNorFlash::new(&mut memory), 0).unwrap();
            let loaded = store.load();
            let committed = planned.is_none_or(|keep| keep >= RECORD_LEN);
            if committed {
                stored = config.version;
                assert_eq!(loaded.config, config, "step {step}");
            }
            assert!(
                matches!(loaded.source, LoadSource::Slot { version, .. } if version == stored),
                "step {step}: {loaded:?}"
            );
        }
        assert_eq!((writes, stored), (POWER_CUT_PLAN.len(), 2));
    }
}
