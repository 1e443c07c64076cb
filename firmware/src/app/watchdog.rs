//! The watchdog's timeout, sized against the longest stretch the main loop
//! goes without feeding it ([`WATCHDOG_UNFED_WORST_MS`]) and against the
//! real board's clock for it: the STM32F411's IWDG counts the LSI RC
//! oscillator, 17 to 47 kHz (32 kHz typical; STM32F411 datasheet, LSI
//! oscillator characteristics), while the HAL converts a timeout to
//! counts at 32 kHz. The fastest LSI therefore fires after 32/47 of the
//! programmed time, the slowest after 32/17 of it.

use super::budget::WATCHDOG_UNFED_WORST_MS;

/// A board's watchdog, as the main loop feeds it
/// ([`main_loop`](super::main_loop)); started by the board, with
/// [`WATCHDOG_TIMEOUT_MS`].
pub trait Watchdog {
    /// Restarts the watchdog's count.
    fn feed(&mut self);
}

/// LSI frequency range of the STM32F411 (datasheet) and the nominal value
/// stm32f4xx-hal 0.22 converts with (`watchdog.rs`, `LSI_KHZ`).
pub const LSI_MIN_HZ: u32 = 17_000;
pub const LSI_NOMINAL_HZ: u32 = 32_000;
pub const LSI_MAX_HZ: u32 = 47_000;

/// The shortest the watchdog may fire: twice the worst unfed stretch, so
/// that twice as long a recovery or step as the budget assumes still does
/// not reset a working probe.
pub const WATCHDOG_SHORTEST_MS: u32 = 2 * WATCHDOG_UNFED_WORST_MS;

/// The timeout the boards program (the HAL's milliseconds at the nominal
/// LSI; the QEMU board's watchdog has an exact clock): long enough that the
/// fastest LSI still gives [`WATCHDOG_SHORTEST_MS`] (the test below checks
/// that the HAL's rounding keeps it so).
pub const WATCHDOG_TIMEOUT_MS: u32 =
    (WATCHDOG_SHORTEST_MS as u64 * LSI_MAX_HZ as u64).div_ceil(LSI_NOMINAL_HZ as u64) as u32;

/// The IWDG's prescaler divider and reload for a timeout, as
/// stm32f4xx-hal 0.22's `IndependentWatchdog::setup` computes them: the
/// smallest divider (4 to 256) whose 4096-count period at the nominal LSI
/// covers the timeout, then the reload scaled down to it (rounded down).
pub const fn iwdg_divider_and_reload(timeout_ms: u32) -> (u32, u32) {
    const MAX_RELOAD: u32 = 0xFFF;
    let lsi_khz = LSI_NOMINAL_HZ / 1_000;
    let mut divider = 8;
    while divider < 256 && timeout_ms > (MAX_RELOAD + 1) * divider / lsi_khz {
        divider *= 2;
    }
    if timeout_ms == 0 {
        divider = 4;
    }
    let max_period_ms = (MAX_RELOAD + 1) * divider / lsi_khz;
    let reload = timeout_ms as u64 * MAX_RELOAD as u64 / max_period_ms as u64;
    let reload = if reload > MAX_RELOAD as u64 {
        MAX_RELOAD
    } else {
        reload as u32
    };
    (divider, reload)
}

/// When the IWDG fires, in ms, for a divider and reload at an LSI of
/// `lsi_hz` (RM0383, IWDG: (reload + 1) * divider / f_LSI).
pub const fn iwdg_period_ms(divider: u32, reload: u32, lsi_hz: u32) -> u32 {
    ((reload as u64 + 1) * divider as u64 * 1_000 / lsi_hz as u64) as u32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_fastest_lsi_still_outlasts_twice_the_worst_stretch() {
        let (divider, reload) = iwdg_divider_and_reload(WATCHDOG_TIMEOUT_MS);
        let shortest = iwdg_period_ms(divider, reload, LSI_MAX_HZ);
        let nominal = iwdg_period_ms(divider, reload, LSI_NOMINAL_HZ);
        let longest = iwdg_period_ms(divider, reload, LSI_MIN_HZ);
        assert!(shortest >= WATCHDOG_SHORTEST_MS, "{shortest} ms");
        assert!(shortest >= 2 * WATCHDOG_UNFED_WORST_MS);
        // The figures docs/budgets.md gives.
        assert_eq!(WATCHDOG_TIMEOUT_MS, 2_938);
        assert_eq!((divider, reload), (32, 2_937));
        assert_eq!((shortest, nominal, longest), (2_000, 2_938, 5_530));
        // The old 2 s timeout fired after 1.36 s at 47 kHz, below the
        // 2 s the worst recovery blocked for.
        let (d, r) = iwdg_divider_and_reload(2_000);
        assert_eq!(iwdg_period_ms(d, r, LSI_MAX_HZ), 1_361);
    }

    #[test]
    fn the_hal_arithmetic_covers_its_range() {
        // Dividers 4 .. 256, reload at most 4095 (32.768 s at 32 kHz).
        assert_eq!(iwdg_divider_and_reload(0), (4, 0));
        assert_eq!(iwdg_divider_and_reload(1_000), (8, 3_999));
        assert_eq!(iwdg_divider_and_reload(40_000), (256, 4_095));
    }
}
