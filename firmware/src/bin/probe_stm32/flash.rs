//! The configuration's flash on the STM32F411: sectors 6 and 7, 128 KiB
//! each at 0x0804_0000 and 0x0806_0000 (RM0383 3.3, table 5), one per
//! slot of `firmware::app::config_store`, behind embedded-storage's
//! `NorFlash`. They lie above the program's 256 KiB budget (memory.x,
//! which asserts that the program ends before them).
//!
//! Register-level and minimal (RM0383 3.5-3.8):
//! - unlock: the two KEYR keys; lock again (CR.LOCK) after each operation;
//! - parallelism x32 (CR.PSIZE = 2), allowed at the board's 3.3 V
//!   (2.7-3.6 V), the fastest: one word per program step;
//! - erase: CR.SER with the sector in CR.SNB, then CR.STRT, wait SR.BSY;
//! - program: CR.PG, then 32-bit writes to the flash addresses, each
//!   waited for (SR.BSY);
//! - the error flags (PGSERR, PGPERR, PGAERR, WRPERR, OPERR) cleared
//!   before and checked after each operation; the data cache is reset
//!   after an erase or program (RM0383 3.4.2: it may hold the old words).
//!
//! While a sector erases, every read of the flash stalls the bus (RM0383
//! 3.5.1), code fetches included: the whole board stops, for up to seconds
//! on a 128 KiB sector (DS10314, flash programming characteristics), which
//! is longer than the watchdog's shortest period (2 s,
//! `firmware::app::watchdog`). So the erase is started and waited for by a
//! function that runs from RAM, interrupts masked (their vectors and
//! handlers are in flash), feeding the watchdog meanwhile. Acquisition
//! stops for the erase: configuration is a surface operation.
#![allow(unsafe_code)]

use embedded_storage::nor_flash::{
    check_erase, check_read, check_write, ErrorType, NorFlash, NorFlashError, NorFlashErrorKind,
    ReadNorFlash,
};
use stm32f4xx_hal::pac;

/// Sector 6's address and the two sectors' size (RM0383 table 5).
pub const CONFIG_FLASH_START: u32 = 0x0804_0000;
const SECTOR_LEN: usize = 128 * 1024;
const FIRST_SECTOR: u8 = 6;
const SECTORS: usize = 2;

/// KEYR's unlock sequence (RM0383 3.5.1).
const KEY1: u32 = 0x4567_0123;
const KEY2: u32 = 0xCDEF_89AB;
/// SR: BSY, and the error flags (write 1 to clear).
const SR_BSY: u32 = 1 << 16;
const SR_ERRORS: u32 = 0b1111_0010; // PGSERR PGPERR PGAERR WRPERR, OPERR
/// CR: STRT (sector erase start).
const CR_STRT: u32 = 1 << 16;
/// IWDG_KR's reload key (RM0383 19.4.1).
const IWDG_RELOAD: u32 = 0xAAAA;
/// Rounds of the erase's wait loop during which the watchdog is fed: at
/// least 4 cycles each at the board's 96 MHz, so at least 4 s, twice the
/// longest 128 KiB erase at x32 the datasheet gives; a flash that stays
/// busy longer stops being fed and the watchdog resets the chip.
const ERASE_FEED_ROUNDS: u32 = 4 * 96_000_000 / 4;

/// A failed operation: the checks of embedded-storage, or the flash's
/// error flags (`status`: SR, or CR when it stayed locked; kind `Other`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FlashError {
    kind: NorFlashErrorKind,
    pub status: u32,
}

impl NorFlashError for FlashError {
    fn kind(&self) -> NorFlashErrorKind {
        self.kind
    }
}

impl From<NorFlashErrorKind> for FlashError {
    fn from(kind: NorFlashErrorKind) -> Self {
        Self { kind, status: 0 }
    }
}

/// Sectors 6-7 as one 256 KiB NOR flash (offset 0 is 0x0804_0000).
pub struct SectorFlash {
    flash: pac::FLASH,
}

impl SectorFlash {
    pub fn new(flash: pac::FLASH) -> Self {
        Self { flash }
    }

    /// Unlocks CR and clears the error flags; fails if CR stays locked
    /// (a wrong key sequence locks it until the next reset).
    fn unlock(&mut self) -> Result<(), FlashError> {
        while self.flash.sr().read().bsy().bit_is_set() {}
        if self.flash.cr().read().lock().bit_is_set() {
            // SAFETY: KEYR is write-only and takes any value; the two keys
            // in order unlock CR.
            self.flash.keyr().write(|w| unsafe { w.key().bits(KEY1) });
            self.flash.keyr().write(|w| unsafe { w.key().bits(KEY2) });
        }
        // SAFETY: writing 1s clears exactly the error flags.
        self.flash.sr().write(|w| unsafe { w.bits(SR_ERRORS) });
        if self.flash.cr().read().lock().bit_is_set() {
            return Err(FlashError {
                kind: NorFlashErrorKind::Other,
                status: self.flash.cr().read().bits(),
            });
        }
        Ok(())
    }

    /// Locks CR, resets the data cache, and reports the error flags.
    fn finish(&mut self) -> Result<(), FlashError> {
        while self.flash.sr().read().bsy().bit_is_set() {}
        let status = self.flash.sr().read().bits();
        // From CR's reset value: PG and SER cleared, LOCK set.
        self.flash.cr().write(|w| w.lock().set_bit());
        // The data cache may hold words read before the operation: reset it
        // (only while disabled, RM0383 3.4.2).
        let dcen = self.flash.acr().read().dcen().bit_is_set();
        self.flash.acr().modify(|_, w| w.dcen().clear_bit());
        self.flash.acr().modify(|_, w| w.dcrst().set_bit());
        self.flash.acr().modify(|_, w| w.dcrst().clear_bit());
        self.flash.acr().modify(|_, w| w.dcen().bit(dcen));
        if status & SR_ERRORS == 0 {
            Ok(())
        } else {
            Err(FlashError {
                kind: NorFlashErrorKind::Other,
                status,
            })
        }
    }
}

/// Starts the erase set up in CR (writing `cr_start`) and waits for it,
/// feeding the watchdog. In RAM (cortex-m-rt copies `.data` there at
/// start-up), never inlined, and calling nothing: a fetch from flash would
/// stall until the erase ends. Returns SR.
///
/// SAFETY (for callers): `cr`, `sr` and `iwdg_kr` are FLASH_CR, FLASH_SR
/// and IWDG_KR; interrupts must be masked. IWDG_KR is the HAL watchdog's
/// register: with interrupts masked nothing else touches it meanwhile,
/// and the reload key is what the HAL's feed writes.
#[link_section = ".data.config_flash_erase_wait"]
#[inline(never)]
unsafe fn start_erase_and_wait(cr: *mut u32, sr: *const u32, iwdg_kr: *mut u32, cr_start: u32) {
    // SAFETY: per the function's contract, device registers.
    unsafe {
        cr.write_volatile(cr_start);
        let mut rounds = 0u32;
        while sr.read_volatile() & SR_BSY != 0 {
            if rounds < ERASE_FEED_ROUNDS {
                iwdg_kr.write_volatile(IWDG_RELOAD);
                rounds += 1;
            }
        }
    }
}

impl ErrorType for SectorFlash {
    type Error = FlashError;
}

impl ReadNorFlash for SectorFlash {
    const READ_SIZE: usize = 1;

    fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), Self::Error> {
        check_read(self, offset, bytes.len())?;
        let start = (CONFIG_FLASH_START + offset) as *const u8;
        for (i, byte) in bytes.iter_mut().enumerate() {
            // SAFETY: within sectors 6-7 (checked above), always mapped and
            // readable; volatile because erase and program change them.
            *byte = unsafe { start.add(i).read_volatile() };
        }
        Ok(())
    }

    fn capacity(&self) -> usize {
        SECTORS * SECTOR_LEN
    }
}

impl NorFlash for SectorFlash {
    const WRITE_SIZE: usize = 4;
    const ERASE_SIZE: usize = SECTOR_LEN;

    fn erase(&mut self, from: u32, to: u32) -> Result<(), Self::Error> {
        check_erase(self, from, to)?;
        for sector in (from as usize / SECTOR_LEN)..(to as usize / SECTOR_LEN) {
            self.unlock()?;
            // At most 2 sectors (checked above): 6 or 7.
            let snb = FIRST_SECTOR + sector as u8;
            // `modify`, not `write`: a write starts from CR's reset value,
            // whose LOCK bit would lock the flash again.
            // SAFETY: SNB takes a sector number (6 and 7 exist on the F411).
            self.flash.cr().modify(|_, w| unsafe {
                w.pg().clear_bit().mer().clear_bit();
                w.psize().psize32().ser().set_bit().snb().bits(snb)
            });
            let cr_start = self.flash.cr().read().bits() | CR_STRT;
            let iwdg_kr = pac::IWDG::ptr();
            cortex_m::interrupt::free(|_| {
                // SAFETY: the three registers of the contract, interrupts
                // masked in this closure.
                unsafe {
                    start_erase_and_wait(
                        self.flash.cr().as_ptr(),
                        self.flash.sr().as_ptr(),
                        (*iwdg_kr).kr().as_ptr(),
                        cr_start,
                    )
                }
            });
            self.finish()?;
        }
        Ok(())
    }

    fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), Self::Error> {
        check_write(self, offset, bytes.len())?;
        self.unlock()?;
        // `modify`: see `erase`.
        self.flash.cr().modify(|_, w| {
            w.ser().clear_bit().mer().clear_bit();
            w.psize().psize32().pg().set_bit()
        });
        let mut address = (CONFIG_FLASH_START + offset) as *mut u32;
        for word in bytes.chunks_exact(4) {
            let value = u32::from_le_bytes([word[0], word[1], word[2], word[3]]);
            // SAFETY: a word-aligned address within sectors 6-7 (checked
            // above), programmed as CR.PG allows; one word at a time, each
            // waited for. (Fetches stall for the few microseconds each
            // takes, not long enough to matter.)
            unsafe {
                address.write_volatile(value);
                address = address.add(1);
            }
            while self.flash.sr().read().bsy().bit_is_set() {}
            if self.flash.sr().read().bits() & SR_ERRORS != 0 {
                break;
            }
        }
        self.finish()
    }
}
