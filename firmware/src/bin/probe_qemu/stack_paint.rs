//! Stack high-water mark by painting: at boot the unused stack (from the
//! end of static RAM up to just below the current stack pointer) is filled
//! with a pattern; at the end of the run the lowest overwritten word shows
//! how deep the stack ever went. Reads linker symbols and writes memory no
//! Rust object owns, so it is the second (and last) module with `unsafe`.
#![allow(unsafe_code)]

const PAINT: u32 = 0x5AC0_FFEE;
/// Left unpainted below the stack pointer at the time of painting: the
/// painting loop's own frame and any interrupt that arrives meanwhile.
const MARGIN_BYTES: usize = 256;

extern "C" {
    /// Lowest stack address (end of .bss/.uninit), from sections-qemu.x.
    static _stack_end: u32;
    /// Top of RAM, where the stack starts.
    static _stack_start: u32;
}

/// Only the symbols' addresses are taken, never their (meaningless)
/// contents.
fn bounds() -> (usize, usize) {
    (
        core::ptr::addr_of!(_stack_end) as usize,
        core::ptr::addr_of!(_stack_start) as usize,
    )
}

/// Paints the stack's free part. Call once, early in `main`.
pub fn paint() {
    let (low, _) = bounds();
    let sp = cortex_m::register::msp::read() as usize;
    let high = sp.saturating_sub(MARGIN_BYTES) & !3;
    let mut addr = low;
    while addr < high {
        // SAFETY: [low, high) lies between the end of all statics and below
        // the live stack (minus a margin): no object lives there, and the
        // address is word-aligned (both bounds are).
        unsafe { core::ptr::write_volatile(addr as *mut u32, PAINT) };
        addr += 4;
    }
}

/// Deepest stack use since [`paint`], in bytes.
pub fn high_water_bytes() -> usize {
    let (low, top) = bounds();
    let mut addr = low;
    while addr < top {
        // SAFETY: reading word-aligned RAM inside the stack region.
        if unsafe { core::ptr::read_volatile(addr as *const u32) } != PAINT {
            break;
        }
        addr += 4;
    }
    top - addr
}
