//! A NOR flash emulated in RAM, for a board without a flash the probe may
//! write (QEMU's mps2-an386 loads its code into RAM): the configuration
//! store ([`super::config_store`]) runs on it unchanged. It behaves as NOR
//! flash does, so the store is exercised as on a real part: erase sets
//! whole units to 0xFF, a write can only clear bits (AND), writes and
//! erases must be aligned. Where the RAM keeps its contents across a reset
//! (an uninitialised section), the configuration survives a reboot.

use embedded_storage::nor_flash::{
    check_erase, check_read, check_write, ErrorType, NorFlash, NorFlashError, NorFlashErrorKind,
    ReadNorFlash,
};

/// The emulated erase unit: small, as RAM is scarce; the store's slot is
/// the record rounded up to it.
pub const RAM_FLASH_ERASE_SIZE: usize = 512;

/// A write or erase outside the region or off its alignment.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RamFlashError(NorFlashErrorKind);

impl NorFlashError for RamFlashError {
    fn kind(&self) -> NorFlashErrorKind {
        self.0
    }
}

/// NOR flash semantics over a borrowed RAM region.
pub struct RamNorFlash<'a> {
    memory: &'a mut [u8],
}

impl<'a> RamNorFlash<'a> {
    pub fn new(memory: &'a mut [u8]) -> Self {
        Self { memory }
    }
}

impl ErrorType for RamNorFlash<'_> {
    type Error = RamFlashError;
}

impl ReadNorFlash for RamNorFlash<'_> {
    const READ_SIZE: usize = 1;

    fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), Self::Error> {
        check_read(self, offset, bytes.len()).map_err(RamFlashError)?;
        let start = offset as usize;
        let from = self
            .memory
            .get(start..start + bytes.len())
            .ok_or(RamFlashError(NorFlashErrorKind::OutOfBounds))?;
        bytes.copy_from_slice(from);
        Ok(())
    }

    fn capacity(&self) -> usize {
        self.memory.len()
    }
}

impl NorFlash for RamNorFlash<'_> {
    const WRITE_SIZE: usize = 4;
    const ERASE_SIZE: usize = RAM_FLASH_ERASE_SIZE;

    fn erase(&mut self, from: u32, to: u32) -> Result<(), Self::Error> {
        check_erase(self, from, to).map_err(RamFlashError)?;
        self.memory
            .get_mut(from as usize..to as usize)
            .ok_or(RamFlashError(NorFlashErrorKind::OutOfBounds))?
            .fill(0xFF);
        Ok(())
    }

    fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), Self::Error> {
        check_write(self, offset, bytes.len()).map_err(RamFlashError)?;
        let start = offset as usize;
        let to = self
            .memory
            .get_mut(start..start + bytes.len())
            .ok_or(RamFlashError(NorFlashErrorKind::OutOfBounds))?;
        // NOR programming only clears bits: a write over unerased flash
        // yields the AND, as on the real part.
        for (cell, byte) in to.iter_mut().zip(bytes) {
            *cell &= byte;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::app::config_store::{ConfigStore, LoadSource};
    use mwd_core::config::ProbeConfig;

    #[test]
    fn nor_rules_hold() {
        let mut memory = [0u8; 1024];
        let mut flash = RamNorFlash::new(&mut memory);
        assert!(flash.erase(0, 100).is_err(), "not a whole unit");
        assert!(flash.write(2, &[0; 4]).is_err(), "unaligned");
        assert!(flash.write(1024, &[0; 4]).is_err(), "outside");
        flash.erase(0, 512).unwrap();
        flash.write(0, &[0xF0, 0x0F, 0xFF, 0x00]).unwrap();
        flash.write(0, &[0x3C, 0x3C, 0x3C, 0x3C]).unwrap();
        let mut back = [0u8; 4];
        flash.read(0, &mut back).unwrap();
        assert_eq!(back, [0x30, 0x0C, 0x3C, 0x00], "a write only clears bits");
    }

    #[test]
    fn the_store_keeps_a_configuration_in_it_across_a_new_handle() {
        let mut memory = [0u8; 2 * RAM_FLASH_ERASE_SIZE];
        let mut store = ConfigStore::new(RamNorFlash::new(&mut memory), 0).unwrap();
        assert_eq!(store.load().source, LoadSource::Defaults, "zeroed RAM");
        let config = ProbeConfig {
            version: 1,
            ..ProbeConfig::default()
        };
        store.save(&config).unwrap();
        // The first driver is done with the memory (its borrow ends here).
        // As after a reset: a new driver over the same memory.
        let mut store = ConfigStore::new(RamNorFlash::new(&mut memory), 0).unwrap();
        let loaded = store.load();
        assert_eq!(
            loaded.source,
            LoadSource::Slot {
                index: 0,
                version: 1
            }
        );
        assert_eq!(loaded.config, config);
    }
}
