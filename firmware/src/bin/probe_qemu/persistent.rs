//! RAM that keeps its contents across a reset, the QEMU board's stand-in
//! for the real board's flash sector and reset flags: two statics in the
//! `.uninit` section (NOLOAD in sections-qemu.x), which neither the
//! start-up code nor QEMU's `system_reset` touches (QEMU reloads only the
//! ELF's loadable segments). At QEMU's start RAM is zero: no configuration
//! record is valid and no reset mark is set.
//!
//! - the configuration's two slots (`firmware::app::ram_flash`, NOR rules);
//! - the reset mark: the mps2-an386 has no reset-cause register, so the
//!   firmware leaves a word saying how it went down. None at boot: power
//!   on; "software" set just before the reboot command's reset; "running"
//!   set at each boot, so finding it means something else reset the chip
//!   while it ran: the reset pin (QEMU's monitor `system_reset`). The
//!   watchdog's reset never happens here (its first timeout ends the QEMU
//!   run, `exit.rs`). The power-cut test's cut (`PowerCut`) clears the
//!   mark, so its reset reads as the power-on it stands for;
//! - under the feature `power-cut-test`, the number of configuration
//!   writes of the run, which `firmware::app::power_cut::POWER_CUT_PLAN`
//!   is indexed by.
#![allow(unsafe_code)]

use core::mem::MaybeUninit;
use core::sync::atomic::{AtomicBool, Ordering};

use firmware::app::boot::ResetCause;
use firmware::app::ram_flash::RAM_FLASH_ERASE_SIZE;

/// The emulated flash: the configuration's two slots.
pub const CONFIG_FLASH_LEN: usize = 2 * RAM_FLASH_ERASE_SIZE;

#[link_section = ".uninit.probe_config_flash"]
static mut CONFIG_FLASH: MaybeUninit<[u8; CONFIG_FLASH_LEN]> = MaybeUninit::uninit();

#[link_section = ".uninit.probe_reset_mark"]
static mut RESET_MARK: MaybeUninit<u32> = MaybeUninit::uninit();

const MARK_RUNNING: u32 = 0x4D57_4452; // "MWDR"
const MARK_SOFTWARE: u32 = 0x4D57_4453; // "MWDS"

static TAKEN: AtomicBool = AtomicBool::new(false);

/// The emulated flash's memory, once (`None` after).
pub fn config_flash() -> Option<&'static mut [u8; CONFIG_FLASH_LEN]> {
    if TAKEN.swap(true, Ordering::AcqRel) {
        return None;
    }
    let region = core::ptr::addr_of_mut!(CONFIG_FLASH).cast::<u8>();
    // SAFETY: the region is RAM, which always holds some byte values; they
    // are read volatile once here (so the compiler assumes nothing of
    // them, in particular not that they are uninitialised) before a
    // reference is made. `TAKEN` makes the reference unique.
    unsafe {
        for i in 0..CONFIG_FLASH_LEN {
            let cell = region.add(i);
            cell.write_volatile(cell.read_volatile());
        }
        Some(&mut *region.cast::<[u8; CONFIG_FLASH_LEN]>())
    }
}

fn mark() -> *mut u32 {
    core::ptr::addr_of_mut!(RESET_MARK).cast::<u32>()
}

/// Why the chip restarted (see the module's notes); from now on the mark
/// says "running". Call once at boot.
pub fn take_reset_cause() -> ResetCause {
    // SAFETY: an aligned word of RAM only this module touches, read and
    // written volatile from the main thread (interrupts do not use it).
    let found = unsafe { mark().read_volatile() };
    // SAFETY: as above.
    unsafe { mark().write_volatile(MARK_RUNNING) };
    match found {
        MARK_SOFTWARE => ResetCause::Software,
        MARK_RUNNING => ResetCause::Pin,
        _ => ResetCause::PowerOn,
    }
}

/// The next boot is to report a software reset.
pub fn mark_software_reset() {
    // SAFETY: as in `take_reset_cause`.
    unsafe { mark().write_volatile(MARK_SOFTWARE) };
}

/// The next boot is to report a power-on (the power-cut test's cut).
#[cfg(feature = "power-cut-test")]
fn mark_power_on() {
    // SAFETY: as in `take_reset_cause`.
    unsafe { mark().write_volatile(0) };
}

/// The configuration writes of the run, in the low 16 bits under a tag
/// (RAM that no write of this count left reads as none).
#[cfg(feature = "power-cut-test")]
#[link_section = ".uninit.probe_power_cut_writes"]
static mut WRITES: MaybeUninit<u32> = MaybeUninit::uninit();

#[cfg(feature = "power-cut-test")]
const WRITES_TAG: u32 = 0x4D57_0000; // "MW", count

/// The QEMU board's power as the power-cut test cuts it.
#[cfg(feature = "power-cut-test")]
pub struct PowerCut;

#[cfg(feature = "power-cut-test")]
impl firmware::app::power_cut::PowerSupply for PowerCut {
    fn next_write(&mut self) -> usize {
        let cell = core::ptr::addr_of_mut!(WRITES).cast::<u32>();
        // SAFETY: an aligned word of RAM only this module touches, from
        // the main thread (the uplink service's flash writes).
        let found = unsafe { cell.read_volatile() };
        let count = if found & 0xFFFF_0000 == WRITES_TAG {
            found & 0xFFFF
        } else {
            0
        };
        // SAFETY: as above.
        unsafe { cell.write_volatile(WRITES_TAG | (count + 1).min(0xFFFF)) };
        count as usize
    }

    fn cut(&mut self) -> ! {
        mark_power_on();
        crate::registers::system_reset()
    }
}
