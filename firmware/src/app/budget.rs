//! The probe's worst cases in time, derived from the driver's own waits
//! (`crate::scc1300::datasheet`) and retry counts, so that the navigation
//! inbox, the transmit queue and the watchdog follow the driver when it
//! changes. `docs/budgets.md` ("Worst recovery, inbox and watchdog")
//! explains the figures; the host tests in `shared/recovery_tests.rs` run a
//! both-gyros-lose-their-loop recovery on a simulated board against them.

use mwd_core::protocol::{wire_len, FrameKind};
use mwd_core::timing::SAMPLE_PERIOD_US;

use super::frame_queue::TX_QUEUE_LEN;
use super::start_up::START_ATTEMPTS;
use crate::scc1300::datasheet::{ACCEL_SETTLE_MS, GYRO_RECHECK_WAIT_MS, POWER_UP_WAIT_MS};

/// One sample period in ms.
pub const SAMPLE_PERIOD_MS: u32 = (SAMPLE_PERIOD_US / 1_000) as u32;

/// How long a board's delay may take for a wait of `ms`: the QEMU board
/// sleeps in whole timer periods (rounded up), the real board's SysTick
/// delay is exact; the coarser of the two bounds both.
pub const fn board_wait_ms(ms: u32) -> u32 {
    ms.div_ceil(SAMPLE_PERIOD_MS) * SAMPLE_PERIOD_MS
}

/// Bus time a recovery or start-up spends outside its waits: a few dozen
/// 32-bit SPI transactions at 500 kHz (64 us each) and the interrupts that
/// preempt it; 50 ms bounds it many times over.
pub const SPI_AND_INTERRUPTS_MS: u32 = 50;

/// One part's worst recovery (`Part::recover`): the gyro's supervision
/// finds its loop off (60 ms recheck, soft reset, the 800 ms start-up
/// again), then the accelerometer's start-up (10 ms settling) [TN92 step 4].
pub const PART_RECOVERY_WORST_MS: u32 = board_wait_ms(GYRO_RECHECK_WAIT_MS)
    + board_wait_ms(POWER_UP_WAIT_MS)
    + board_wait_ms(ACCEL_SETTLE_MS)
    + SPI_AND_INTERRUPTS_MS;

/// One part's worst start-up (`start_parts`): the 800 ms power-up wait, then
/// every attempt fails after the accelerometer's settling.
pub const PART_START_WORST_MS: u32 = board_wait_ms(POWER_UP_WAIT_MS)
    + START_ATTEMPTS * board_wait_ms(ACCEL_SETTLE_MS)
    + SPI_AND_INTERRUPTS_MS;

/// The worst blocking recovery: both parts, one after the other.
pub const RECOVERY_WORST_MS: u32 = 2 * PART_RECOVERY_WORST_MS;

/// The most sample instants in a stretch of `ms` (one at each end).
pub const fn samples_in_ms(ms: u32) -> usize {
    (ms / SAMPLE_PERIOD_MS) as usize + 1
}

/// The slowest single navigation step: the one that ends the coarse
/// alignment and starts the filter (once, at 5 s): 14.0 M instructions
/// measured on the QEMU board (`mode_change_instructions_longest`,
/// docs/budgets.md), 176 ms at 80 MHz; 250 ms leaves room for a slower
/// clock or flash wait states.
pub const SLOWEST_NAVIGATION_STEP_MS: u32 = 250;

/// Samples the navigation inbox must hold: the navigation has caught up
/// when a recovery starts (`SharedProbe::main_loop_pass` runs it only
/// then), every sample taken during the worst recovery waits, and the
/// first step after it may be the slowest one. After that the navigation
/// drains the inbox at the UART's pace, about five times the sample rate.
pub const NAV_INBOX_NEEDED: usize =
    samples_in_ms(RECOVERY_WORST_MS) + samples_in_ms(SLOWEST_NAVIGATION_STEP_MS);

/// The most bytes one acquisition queues: a raw frame and a fault event per
/// slave of each part.
pub const ACQUISITION_WORST_BYTES: usize =
    wire_len(FrameKind::RawSample.body_len()) + 4 * wire_len(FrameKind::Event.body_len());

/// Room the main loop leaves in the transmit queue before it navigates a
/// sample: its navigation frame and the station survey the step may finish
/// (kind 4, at most one per still period), what the acquisition may queue before the
/// UART has drained as much (one period's worth: the UART drains 576 B per
/// period, more than an acquisition's worst), and the main loop's own
/// events after a recovery (two resets, the resynchronisation, a
/// samples-dropped event). Holding the navigation back until then, rather
/// than dropping its frame, keeps every navigation frame (the samples wait
/// in the inbox, which is sized for it).
pub const NAV_ROOM_BYTES: usize = wire_len(FrameKind::NavSolution.body_len())
    + wire_len(FrameKind::StationSurvey.body_len())
    + ACQUISITION_WORST_BYTES
    + 4 * wire_len(FrameKind::Event.body_len());

// The navigation can go on at all only if the queue holds its room, and
// in steady state (157 B per period, 228 B in the period a station survey
// is sent, of the 576 B the UART drains per period) it never waits for it.
const _: () = assert!(TX_QUEUE_LEN >= 2 * NAV_ROOM_BYTES);

/// The longest the main loop may go without feeding the watchdog: it feeds
/// at each pass, after each part's start-up or recovery, and after each
/// navigation step, so the longest stretch is the longest of those.
pub const WATCHDOG_UNFED_WORST_MS: u32 = max(
    max(PART_RECOVERY_WORST_MS, PART_START_WORST_MS),
    max(SLOWEST_NAVIGATION_STEP_MS, SAMPLE_PERIOD_MS),
);

const fn max(a: u32, b: u32) -> u32 {
    if a > b {
        a
    } else {
        b
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn worst_cases_follow_the_driver() {
        // 60 ms -> 100 ms, 800 ms, 10 ms -> 50 ms on the QEMU board's delay.
        assert_eq!(board_wait_ms(60), 100);
        assert_eq!(board_wait_ms(800), 800);
        assert_eq!(board_wait_ms(10), 50);
        assert_eq!(PART_RECOVERY_WORST_MS, 1_000);
        assert_eq!(RECOVERY_WORST_MS, 2_000);
        assert_eq!(PART_START_WORST_MS, 1_000);
        assert_eq!(samples_in_ms(2_000), 41);
        assert_eq!(NAV_INBOX_NEEDED, 41 + 6);
        assert_eq!(WATCHDOG_UNFED_WORST_MS, 1_000);
        assert_eq!(ACQUISITION_WORST_BYTES, 51 + 4 * 27);
        assert_eq!(NAV_ROOM_BYTES, 106 + 71 + 159 + 108);
    }
}
