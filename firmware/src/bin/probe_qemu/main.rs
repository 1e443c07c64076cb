//! The probe on QEMU's mps2-an386 board (Cortex-M4F, 25 MHz): the real
//! SCC1300 driver reads two hil-mock parts, the application core makes the
//! frames, and CMSDK UART0 carries them out.
//!
//! Contexts, highest priority first:
//! - SysTick at 20 Hz: takes the sample (its instant is the timer's, not the
//!   main loop's) and queues the raw frame and any fault events;
//! - UART0 TX interrupt: moves the next queued byte into the transmitter;
//! - main loop: start-up, blocking sensor recovery, the navigation on each
//!   raw sample (navigation frames); feeds the watchdog; sleeps otherwise.
//!
//! The run ends after `PROBE_QEMU_RUN_SECONDS` simulated seconds (a
//! compile-time setting, default 60): the queue is drained, a summary is
//! printed through semihosting, and QEMU exits with success.
#![no_std]
#![no_main]
#![deny(unsafe_code)]

mod exit;
mod mock_sensors;
mod registers;
mod stack_paint;

use core::cell::RefCell;
use core::sync::atomic::Ordering;

use cortex_m::peripheral::syst::SystClkSource;
use cortex_m::peripheral::SYST;
use cortex_m_rt::{entry, exception};
use critical_section::{CriticalSection, Mutex};
use firmware::app::{start_parts, ProbeState, Recovery};
use mwd_core::earth::Position;
use mwd_core::probe::Navigator;
use mwd_core::protocol::frame::{nav_mode, NO_PART};
use mwd_core::protocol::{EventKind, Payload};

use mock_sensors::{MockBus, TickDelay, TICKS};
use registers::SYSTEM_CLOCK_HZ;

/// Simulated seconds of streaming before the probe exits.
const RUN_SECONDS: u32 = parse_seconds(option_env!("PROBE_QEMU_RUN_SECONDS"), 60);
const SAMPLES_TO_RUN: u32 = RUN_SECONDS * 20;
/// SysTick reload for 20 Hz at the board's clock.
const RELOAD: u32 = SYSTEM_CLOCK_HZ / 20 - 1;
/// The main loop must come round within this (it normally does every
/// 50 ms; a sensor recovery holds it up to about a second).
const WATCHDOG_MS: u32 = 2_000;
/// Firmware version in the boot event.
const VERSION: u16 = 1;

const fn parse_seconds(text: Option<&str>, default: u32) -> u32 {
    let Some(text) = text else { return default };
    let bytes = text.as_bytes();
    let mut value = 0u32;
    let mut i = 0;
    while i < bytes.len() {
        let digit = bytes[i].wrapping_sub(b'0');
        assert!(digit < 10, "PROBE_QEMU_RUN_SECONDS must be a number");
        value = value * 10 + digit as u32;
        i += 1;
    }
    value
}

/// Everything the contexts share; only touched inside critical sections.
struct Shared {
    probe: ProbeState<MockBus, MockBus>,
    /// A byte is in the UART and its interrupt will ask for the next.
    tx_busy: bool,
}

static SHARED: Mutex<RefCell<Shared>> = Mutex::new(RefCell::new(Shared {
    probe: ProbeState::new(),
    tx_busy: false,
}));

fn with_shared<R>(f: impl FnOnce(&mut Shared, CriticalSection) -> R) -> R {
    critical_section::with(|cs| f(&mut SHARED.borrow_ref_mut(cs), cs))
}

/// Starts the transmitter if it is idle and bytes wait. (If the UART is
/// unexpectedly still full, the next push or timer tick tries again.)
fn kick_transmitter(shared: &mut Shared) {
    if shared.tx_busy || !registers::uart_ready() {
        return;
    }
    if let Some(byte) = shared.probe.queue.pop() {
        registers::uart_write(byte);
        shared.tx_busy = true;
    }
}

fn push(payload: &Payload) {
    with_shared(|shared, _| {
        shared.probe.queue.push(payload);
        kick_transmitter(shared);
    });
}

fn push_event(kind: EventKind, part: u8, code: u16, value: u32) {
    with_shared(|shared, _| {
        let event = shared.probe.event(kind, part, code, value);
        shared.probe.queue.push(&event);
        kick_transmitter(shared);
    });
}

#[exception]
fn SysTick() {
    TICKS.fetch_add(1, Ordering::Relaxed);
    with_shared(|shared, _| {
        // The run length is counted here, so the last sample is exact
        // whatever the main loop is doing.
        if shared.probe.cycle.samples() >= SAMPLES_TO_RUN {
            return;
        }
        if shared.probe.streaming {
            mock_sensors::inject_scheduled_faults(shared.probe.cycle.samples());
        }
        shared.probe.acquire();
        kick_transmitter(shared);
    });
}

/// UART0 TX: the transmitter's buffer went empty.
pub fn on_uart_tx() {
    registers::uart_clear_tx_interrupt();
    with_shared(|shared, _| {
        shared.tx_busy = false;
        kick_transmitter(shared);
    });
}

/// Runs the recovery of the parts that asked for it, outside any critical
/// section (it waits), then gives them back to the acquisition.
fn recover(mut job: Recovery<MockBus, MockBus>) {
    job.run(&mut TickDelay, |part, code| {
        push_event(EventKind::SensorReset, part, code, 0)
    });
    let resync = with_shared(|shared, _| shared.probe.end_recovery(job));
    push(&resync);
}

/// Instruction budget of the busiest 20 Hz cycle and the sum for the mean,
/// in SysTick counts (25 MHz; under `-icount shift=0` one count is 40
/// instructions).
#[derive(Default)]
struct CycleCost {
    worst: u32,
    total: u64,
    cycles: u32,
    /// Periods whose work ran into the next period (not in the figures
    /// above), and the longest such stretch of work.
    overruns: u32,
    longest_overrun: u64,
    /// The periods in which the navigation changed mode (the once-only
    /// coarse alignment and the filter's start): not in `worst`/`total`,
    /// their longest is reported on its own.
    mode_changes: u32,
    longest_mode_change: u64,
}

#[entry]
fn main() -> ! {
    stack_paint::paint();
    let Some(mut core) = cortex_m::Peripherals::take() else {
        exit::fail("core peripherals taken twice")
    };
    registers::uart_init();
    registers::set_priorities_and_enable_uart_irq(&mut core.SCB, &mut core.NVIC);
    let mut syst = core.SYST;
    syst.set_clock_source(SystClkSource::Core);
    syst.set_reload(RELOAD);
    syst.clear_current();
    syst.enable_interrupt();
    syst.enable_counter();

    push_event(EventKind::Boot, NO_PART, VERSION, 0);
    registers::watchdog_start(WATCHDOG_MS);
    let mut sensors = mock_sensors::power_up();
    start_parts(&mut sensors, &mut TickDelay, push);
    with_shared(|shared, _| shared.probe.start_streaming(sensors));

    let mut cost = CycleCost::default();
    // The simulated site: the MGWD paper's test site.
    let mut navigator = Navigator::new(Position::paper_site());
    let mut mode = nav_mode::INITIALISING;
    loop {
        registers::watchdog_feed();
        let tick = TICKS.load(Ordering::Relaxed);
        if let Some(job) = with_shared(|shared, _| shared.probe.take_recovery()) {
            recover(job);
        }
        let mut mode_changed = false;
        while let Some(sample) = with_shared(|shared, _| shared.probe.nav_inbox.pop()) {
            let solution = navigator.step(&sample);
            mode_changed |= solution.mode != mode && mode != nav_mode::INITIALISING;
            mode = solution.mode;
            push(&Payload::Nav(solution));
        }
        if cfg!(feature = "qemu-stall-demo") && with_shared(|s, _| s.probe.cycle.samples()) >= 200 {
            // A hung main loop (the watchdog run): interrupts go on.
            loop {
                cortex_m::asm::wfi();
            }
        }
        let (samples, idle) = with_shared(|s, _| {
            let p = &s.probe;
            let done = p.queue.is_empty() && !s.tx_busy && p.nav_inbox.is_empty();
            (p.cycle.samples(), done)
        });
        if samples >= SAMPLES_TO_RUN && idle {
            exit::finish(&summary(&cost));
        }
        // The cycle's work is done: SysTick counts since the period began
        // (only if no new period started meanwhile).
        let elapsed = RELOAD - SYST::get_current();
        let now_tick = TICKS.load(Ordering::Relaxed);
        if mode_changed {
            let periods = now_tick.wrapping_sub(tick);
            let ticks = u64::from(periods) * u64::from(RELOAD + 1) + u64::from(elapsed);
            cost.mode_changes += 1;
            cost.longest_mode_change = cost.longest_mode_change.max(ticks);
        } else if now_tick != tick {
            // Whole periods plus this one's part (read before the tick
            // count, so possibly one period short: a lower bound).
            let periods = now_tick.wrapping_sub(tick);
            let ticks = u64::from(periods) * u64::from(RELOAD + 1) + u64::from(elapsed);
            cost.overruns += 1;
            cost.longest_overrun = cost.longest_overrun.max(ticks);
        } else if samples > 0 {
            cost.worst = cost.worst.max(elapsed);
            cost.total += u64::from(elapsed);
            cost.cycles += 1;
        }
        cortex_m::asm::wfi();
    }
}

/// The run's figures for the host (semihosting stdout).
struct Summary {
    samples: u32,
    skipped: u32,
    queued: u32,
    dropped: u32,
    worst_ticks: u32,
    mean_ticks: u32,
    stack_bytes: usize,
    nav_dropped: u32,
    overruns: u32,
    longest_overrun_ticks: u64,
    mode_changes: u32,
    longest_mode_change_ticks: u64,
}

fn summary(cost: &CycleCost) -> Summary {
    let mean_ticks = (cost.total / u64::from(cost.cycles.max(1))) as u32;
    with_shared(|s, _| Summary {
        samples: s.probe.cycle.samples(),
        skipped: s.probe.cycle.skipped(),
        queued: s.probe.queue.queued(),
        dropped: s.probe.queue.dropped(),
        worst_ticks: cost.worst,
        mean_ticks,
        stack_bytes: stack_paint::high_water_bytes(),
        nav_dropped: s.probe.nav_inbox.dropped(),
        overruns: cost.overruns,
        longest_overrun_ticks: cost.longest_overrun,
        mode_changes: cost.mode_changes,
        longest_mode_change_ticks: cost.longest_mode_change,
    })
}
