//! Leaving QEMU: semihosting prints to the host's stdout and ends the
//! emulator with an exit status the end-to-end test checks. Faults end the
//! run with failure instead of hanging it.

use cortex_m_rt::{exception, ExceptionFrame};
use cortex_m_semihosting::{debug, hprintln};

use firmware::app::uplink_rx::UplinkStats;

/// SysTick counts per instruction under `-icount shift=0`: one instruction
/// is 1 ns of virtual time, one 25 MHz count 40 ns.
const INSTRUCTIONS_PER_TICK: u32 = 40;

/// The run's figures for the host (semihosting stdout).
pub struct Summary {
    pub samples: u32,
    pub skipped: u32,
    pub queued: u32,
    pub dropped: u32,
    pub worst_ticks: u32,
    /// The samples taken when the worst cycle ended (which cycle it was).
    pub worst_at_sample: u32,
    pub mean_ticks: u32,
    pub stack_bytes: usize,
    pub nav_dropped: u32,
    pub nav_inbox_high_water: usize,
    pub overruns: u32,
    pub longest_overrun_ticks: u64,
    pub mode_changes: u32,
    pub longest_mode_change_ticks: u64,
    pub uplink: UplinkStats,
    pub replies_dropped: u32,
}

pub fn finish(summary: &Summary) -> ! {
    hprintln!(
        "probe-qemu: samples={} skipped={} frames_queued={} frames_dropped={} \
         cycle_ticks_worst={} cycle_ticks_mean={} \
         cycle_instructions_worst={} cycle_worst_at_sample={} cycle_instructions_mean={} \
         stack_high_water_bytes={} \
         nav_samples_dropped={} nav_inbox_high_water={} cycle_overruns={} overrun_instructions_longest={} \
         mode_changes={} mode_change_instructions_longest={} \
         uplink_bytes={} uplink_ok={} uplink_crc_failures={} uplink_malformed={} \
         uplink_oversized={} uplink_unknown={} uplink_out_of_range={} \
         uplink_overflowed_bytes={} uplink_replies_dropped={}",
        summary.samples,
        summary.skipped,
        summary.queued,
        summary.dropped,
        summary.worst_ticks,
        summary.mean_ticks,
        summary.worst_ticks * INSTRUCTIONS_PER_TICK,
        summary.worst_at_sample,
        summary.mean_ticks * INSTRUCTIONS_PER_TICK,
        summary.stack_bytes,
        summary.nav_dropped,
        summary.nav_inbox_high_water,
        summary.overruns,
        summary.longest_overrun_ticks * u64::from(INSTRUCTIONS_PER_TICK),
        summary.mode_changes,
        summary.longest_mode_change_ticks * u64::from(INSTRUCTIONS_PER_TICK),
        summary.uplink.bytes,
        summary.uplink.frames_ok,
        summary.uplink.crc_failures,
        summary.uplink.malformed,
        summary.uplink.oversized,
        summary.uplink.unknown,
        summary.uplink.out_of_range,
        summary.uplink.overflowed_bytes,
        summary.replies_dropped,
    );
    debug::exit(debug::EXIT_SUCCESS);
    loop {
        cortex_m::asm::wfi();
    }
}

pub fn fail(why: &str) -> ! {
    hprintln!("probe-qemu: FAILED: {}", why);
    debug::exit(debug::EXIT_FAILURE);
    loop {
        cortex_m::asm::wfi();
    }
}

#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    hprintln!("probe-qemu: panic: {}", info);
    debug::exit(debug::EXIT_FAILURE);
    loop {
        cortex_m::asm::wfi();
    }
}

// cortex-m-rt requires these handlers to be `unsafe fn`; neither does
// anything unsafe.
#[allow(unsafe_code)]
#[exception]
unsafe fn HardFault(frame: &ExceptionFrame) -> ! {
    hprintln!("probe-qemu: hard fault at pc {:#010x}", frame.pc());
    debug::exit(debug::EXIT_FAILURE);
    loop {
        cortex_m::asm::wfi();
    }
}

/// The watchdog's first timeout (wired to the NMI on mps2-an386): the main
/// loop stalled. In QEMU the run ends with failure rather than waiting for
/// the watchdog's reset, so a test sees the stall at once.
#[allow(unsafe_code)]
#[exception]
unsafe fn NonMaskableInt() {
    fail("watchdog: the main loop stalled");
}
