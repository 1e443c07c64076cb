//! The probe on QEMU's mps2-an386 board (Cortex-M4F, 25 MHz): the real
//! SCC1300 driver reads two hil-mock parts, the application core makes the
//! frames, and CMSDK UART0 carries them out.
//!
//! Contexts, highest priority first:
//! - SysTick at 20 Hz: takes the sample (its instant is the timer's, not the
//!   main loop's) and queues the raw frame and any fault events;
//! - UART0 TX interrupt: moves the next queued byte into the transmitter;
//!   UART0 RX interrupt: moves each received byte into the uplink's
//!   bounded inbox (`firmware::app::uplink_rx`), nothing more;
//! - main loop (`firmware::app::main_loop`, the same on every board):
//!   start-up, blocking sensor recovery, the navigation on each raw sample
//!   (navigation frames), then the host's commands
//!   (`firmware::app::uplink_service`: a bounded number of bytes per pass,
//!   each command answered on the downlink); feeds the watchdog between
//!   those steps (`firmware::app::budget`); sleeps otherwise. This board
//!   adds the run's measurements and end at the end of each pass.
//!
//! The configuration lives in RAM that survives a reset (`persistent.rs`),
//! behind the same NOR-flash trait as the real board's flash; the boot
//! event says the reset cause and whether the configuration came from it
//! or is the defaults.
//!
//! What the contexts share and do is `firmware::app::SharedProbe`, as on
//! the real board; this file adds UART0 as its `Transmitter`, SysTick, the
//! watchdog and the run's measurements, and is the main loop's `Board`.
//!
//! The run ends after `PROBE_QEMU_RUN_SECONDS` simulated seconds (a
//! compile-time setting, default 60): the queue is drained, a summary is
//! printed through semihosting, and QEMU exits with success. The drilling
//! run (feature `qemu-drilling`, `mock_sensors.rs`) lasts as its sensor
//! stream.
#![no_std]
#![no_main]
#![deny(unsafe_code)]

mod exit;
mod mock_sensors;
mod persistent;
mod registers;
mod run_length;
mod stack_paint;
#[cfg(feature = "qemu-drilling")]
mod stream_file;

use core::cell::RefCell;
use core::convert::Infallible;
use core::ops::ControlFlow;

use cortex_m::peripheral::syst::SystClkSource;
use cortex_m::peripheral::SYST;
use cortex_m_rt::{entry, exception};
use critical_section::Mutex;
use firmware::app::main_loop::{self, Board, Pass};
use firmware::app::ram_flash::RamNorFlash;
use firmware::app::uplink_rx::{InboxWriter, UplinkInbox};
use firmware::app::uplink_service::UplinkService;
use firmware::app::{
    BoardBasics, OneByteTransmitter, SharedProbe, Transmitter, TxDataRegister, Watchdog,
    WATCHDOG_TIMEOUT_MS,
};
use mwd_core::timing::SAMPLE_PERIOD_US;

use exit::Summary;
use mock_sensors::{MockBus, TickDelay, TICKS};
use registers::SYSTEM_CLOCK_HZ;
use run_length::SAMPLES_PER_SECOND;

/// The configuration's flash: RAM kept across resets, whose writes the
/// power-cut test (feature `power-cut-test`) cuts short on purpose
/// (`firmware::app::power_cut`).
#[cfg(not(feature = "power-cut-test"))]
type ConfigFlash = RamNorFlash<'static>;
#[cfg(feature = "power-cut-test")]
type ConfigFlash =
    firmware::app::power_cut::PowerCutFlash<RamNorFlash<'static>, persistent::PowerCut>;

#[cfg(not(feature = "power-cut-test"))]
fn config_flash(memory: &'static mut [u8]) -> ConfigFlash {
    RamNorFlash::new(memory)
}
#[cfg(feature = "power-cut-test")]
fn config_flash(memory: &'static mut [u8]) -> ConfigFlash {
    firmware::app::power_cut::PowerCutFlash::new(RamNorFlash::new(memory), persistent::PowerCut)
}

/// When the watchdog run (feature `qemu-stall-demo`) hangs its main loop.
const STALL_AT_SAMPLE: u32 = 10 * SAMPLES_PER_SECOND;
/// SysTick reload for one sample period at the board's clock.
const RELOAD: u32 = (SYSTEM_CLOCK_HZ as u64 * SAMPLE_PERIOD_US / 1_000_000) as u32 - 1;

/// CMSDK UART0's data register: its transmitter holds one byte and
/// interrupts when it empties.
struct Uart0Data;

impl TxDataRegister for Uart0Data {
    /// Full only unexpectedly: the next push or timer tick tries again.
    fn has_room(&self) -> bool {
        registers::uart_ready()
    }

    fn write(&mut self, byte: u8) {
        registers::uart_write(byte);
    }
}

/// UART0's transmitter.
type Uart0 = OneByteTransmitter<Uart0Data>;

/// Everything the contexts share.
static PROBE: SharedProbe<MockBus, MockBus, Uart0> =
    SharedProbe::new(OneByteTransmitter::new(Uart0Data));

#[exception]
fn SysTick() {
    TICKS.begin();
    PROBE.with(|shared| {
        // The run length is counted here, so the last sample is exact
        // whatever the main loop is doing.
        let samples = shared.probe().cycle().samples();
        if samples >= mock_sensors::samples_to_run() {
            return;
        }
        if shared.probe().is_streaming() {
            mock_sensors::before_sample(samples);
        }
        shared.acquire();
    });
}

/// The receive interrupt's end of the uplink inbox (set once in `main`).
static UPLINK_WRITER: Mutex<RefCell<Option<InboxWriter<'static>>>> = Mutex::new(RefCell::new(None));

/// UART0 RX: a byte arrived; into the inbox (a full inbox drops and
/// counts it).
pub fn on_uart_rx() {
    registers::uart_clear_rx_interrupt();
    critical_section::with(|cs| {
        let mut writer = UPLINK_WRITER.borrow_ref_mut(cs);
        while let Some(byte) = registers::uart_read() {
            if let Some(writer) = writer.as_mut() {
                writer.push(byte);
            }
        }
    });
}

/// UART0 TX: the transmitter's buffer went empty.
pub fn on_uart_tx() {
    registers::uart_clear_tx_interrupt();
    PROBE.with(|shared| shared.transmitter_ready());
}

/// Instruction budget of the busiest 20 Hz cycle and the sum for the mean,
/// in SysTick counts (25 MHz; under `-icount shift=0` one count is 40
/// instructions).
#[derive(Default)]
struct CycleCost {
    worst: u32,
    /// The samples taken when the worst cycle ended.
    worst_at_sample: u32,
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

/// The QEMU board as the main loop sees it (`firmware::app::main_loop`):
/// SysTick's periods for its clock and delay, the CMSDK watchdog, and at
/// the end of each pass the run's measurements, its end and the watchdog
/// run's hang.
struct Qemu {
    basics: BoardBasics<TickDelay, CmsdkWatchdog>,
    cost: CycleCost,
}

/// The CMSDK watchdog (started in `main`).
struct CmsdkWatchdog;

impl Watchdog for CmsdkWatchdog {
    fn feed(&mut self) {
        registers::watchdog_feed();
    }
}

impl Board for Qemu {
    type Gyro = MockBus;
    type Accel = MockBus;
    type Uart = Uart0;
    type Flash = ConfigFlash;
    type Delay = TickDelay;
    type Watchdog = CmsdkWatchdog;
    type Stop = Infallible;

    fn basics(&mut self) -> &mut BoardBasics<TickDelay, CmsdkWatchdog> {
        &mut self.basics
    }

    fn wait_for_interrupt(&mut self) {
        cortex_m::asm::wfi();
    }

    /// With the reset mark saying "software".
    fn reboot(&mut self) -> ! {
        persistent::mark_software_reset();
        registers::system_reset()
    }

    /// The watchdog run's hang, the end of the run (its summary), and the
    /// pass's cost.
    fn end_of_pass(
        &mut self,
        probe: &SharedProbe<MockBus, MockBus, Uart0>,
        uplink: &UplinkService<ConfigFlash>,
        pass: &Pass,
    ) -> ControlFlow<Infallible> {
        if cfg!(feature = "qemu-stall-demo")
            && probe.with(|s| s.probe().cycle().samples()) >= STALL_AT_SAMPLE
        {
            // A hung main loop (the watchdog run): interrupts go on.
            loop {
                cortex_m::asm::wfi();
            }
        }
        let (samples, idle) = probe.with(|s| {
            let p = s.probe();
            let done =
                p.queue().is_empty() && s.transmitter().is_idle() && p.nav_inbox().is_empty();
            (p.cycle().samples(), done)
        });
        if samples >= mock_sensors::samples_to_run() && idle {
            exit::finish(&summary(&self.cost, uplink));
        }
        self.cost.count(pass, samples);
        ControlFlow::Continue(())
    }
}

impl CycleCost {
    /// The pass's work is done: SysTick counts since its period began
    /// (only if no new period started meanwhile).
    fn count(&mut self, pass: &Pass, samples: u32) {
        let elapsed = RELOAD - SYST::get_current();
        let now_tick = TICKS.count();
        // Since the pass's period began: whole periods plus this one's
        // part (read before the tick count, so possibly one period short:
        // a lower bound).
        let since_pass_began = || {
            let periods = now_tick.wrapping_sub(pass.tick);
            u64::from(periods) * u64::from(RELOAD + 1) + u64::from(elapsed)
        };
        if pass.mode_changed {
            self.mode_changes += 1;
            self.longest_mode_change = self.longest_mode_change.max(since_pass_began());
        } else if now_tick != pass.tick {
            self.overruns += 1;
            self.longest_overrun = self.longest_overrun.max(since_pass_began());
        } else if samples > 0 {
            if elapsed > self.worst {
                self.worst = elapsed;
                self.worst_at_sample = samples;
            }
            self.total += u64::from(elapsed);
            self.cycles += 1;
        }
    }
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

    let reset_cause = persistent::take_reset_cause();
    let Some(flash_memory) = persistent::config_flash() else {
        exit::fail("configuration flash taken twice")
    };
    let Some(inbox) = cortex_m::singleton!(: UplinkInbox = UplinkInbox::new()) else {
        exit::fail("uplink inbox taken twice")
    };
    let (writer, mut uplink_reader) = inbox.split();
    critical_section::with(|cs| *UPLINK_WRITER.borrow_ref_mut(cs) = Some(writer));
    registers::watchdog_start(WATCHDOG_TIMEOUT_MS);

    let mut board = Qemu {
        basics: BoardBasics::new(TickDelay, CmsdkWatchdog, &TICKS),
        cost: CycleCost::default(),
    };
    // The loop never returns here (`Infallible`).
    match main_loop::run(
        &mut board,
        &PROBE,
        mock_sensors::power_up(),
        config_flash(flash_memory),
        reset_cause,
        &mut uplink_reader,
    ) {}
}

fn summary(cost: &CycleCost, uplink: &UplinkService<ConfigFlash>) -> Summary {
    let mean_ticks = (cost.total / u64::from(cost.cycles.max(1))) as u32;
    PROBE.with(|s| Summary {
        samples: s.probe().cycle().samples(),
        skipped: s.probe().cycle().skipped(),
        queued: s.probe().queue().queued(),
        dropped: s.probe().queue().dropped(),
        worst_ticks: cost.worst,
        worst_at_sample: cost.worst_at_sample,
        mean_ticks,
        stack_bytes: stack_paint::high_water_bytes(),
        nav_dropped: s.probe().nav_inbox().dropped(),
        nav_inbox_high_water: s.probe().nav_inbox().high_water(),
        overruns: cost.overruns,
        longest_overrun_ticks: cost.longest_overrun,
        mode_changes: cost.mode_changes,
        longest_mode_change_ticks: cost.longest_mode_change,
        uplink: *uplink.stats(),
        replies_dropped: uplink.replies_dropped(),
    })
}

/// Every interrupt without its own handler lands here: dispatch the UART's two,
/// and treat any other as a fault (nothing else is enabled).
#[allow(unsafe_code)]
#[exception]
unsafe fn DefaultHandler(irqn: i16) {
    if irqn == registers::UART0_TX_IRQ {
        on_uart_tx();
    } else if irqn == registers::UART0_RX_IRQ {
        on_uart_rx();
    } else {
        exit::fail("unexpected interrupt");
    }
}
