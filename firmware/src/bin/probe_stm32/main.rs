//! The probe on the real board (STM32F411, see `board.rs` for the pin map):
//! the same application core as the QEMU probe, with the two SCC1300 parts
//! on SPI1, frames out of USART1 at 115200 baud and logs through defmt over
//! RTT (`cargo run` in `firmware/` flashes through probe-rs and shows them).
//!
//! Contexts, highest priority first:
//! - TIM2 at 20 Hz: takes the sample (its instant is the timer's, not the
//!   main loop's) and queues the raw frame and any fault events;
//! - USART1: each received byte into the uplink's bounded inbox
//!   (`firmware::app::uplink_rx`), nothing more; on TX empty, the next
//!   queued byte into the transmitter;
//! - main loop (`firmware::app::main_loop`, the same on every board):
//!   start-up, blocking sensor recovery, the navigation on each raw sample
//!   (navigation frames), then the host's commands
//!   (`firmware::app::uplink_service`: a bounded number of bytes per
//!   sample period, each command answered on the downlink); feeds the
//!   watchdog between those steps (`firmware::app::budget`); sleeps
//!   otherwise.
//!
//! The configuration lives in flash sectors 6-7 (`flash.rs`); the boot
//! event says the reset cause (RCC_CSR) and whether the configuration came
//! from flash or is the defaults.
//!
//! Nothing hangs the board: the watchdog starts first thing
//! (`board::init`), and a panic or fault resets the chip at once (the
//! `HardFault` handler below), after panic-probe has logged it.
//!
//! What the contexts share and do is `firmware::app::SharedProbe`, as on
//! the QEMU board; this file adds USART1 as its `Transmitter` and
//! receiver, TIM2, the NVIC, the flash and the watchdog, and is the main
//! loop's `Board`.
#![no_std]
#![no_main]

mod board;
mod flash;

use core::cell::RefCell;
use core::convert::Infallible;

use cortex_m_rt::{entry, exception, ExceptionFrame};
use critical_section::Mutex;
use defmt_rtt as _;
use firmware::app::boot::ResetCause;
use firmware::app::main_loop;
use firmware::app::uplink_rx::{InboxWriter, UplinkInbox};
use firmware::app::{
    BoardBasics, FrameQueue, SamplePeriods, SharedProbe, Transmitter, Watchdog, FIRMWARE_VERSION,
    TX_QUEUE_LEN,
};
use mwd_core::timing::SAMPLE_RATE_HZ;
use panic_probe as _;
use stm32f4xx_hal::pac::{self, interrupt, Interrupt, NVIC};
use stm32f4xx_hal::prelude::*;
use stm32f4xx_hal::serial::{RxISR, RxListen, TxISR, TxListen};
use stm32f4xx_hal::timer::{Event as TimerEvent, Flag, SysDelay};
use stm32f4xx_hal::watchdog::IndependentWatchdog;

use board::{Device, Timer, Uart, UartRx};
use flash::SectorFlash;

/// The acquisition timer's rate: one interrupt per sample.
const SAMPLES_PER_SECOND: u32 = SAMPLE_RATE_HZ as u32;
/// NVIC priorities (upper 4 bits on the F411; lower number = more urgent).
const PRIORITY_ACQUISITION: u8 = 0x10;
const PRIORITY_UART: u8 = 0x20;

/// USART1's transmitter, driven by its TX-empty interrupt.
struct Usart1 {
    /// Set once the board is up.
    uart: Option<Uart>,
}

impl Transmitter for Usart1 {
    /// Bytes wait: let the TX-empty interrupt move them (it fires at once
    /// if the transmitter is idle).
    fn kick(&mut self, queue: &mut FrameQueue<TX_QUEUE_LEN>) {
        if let (false, Some(uart)) = (queue.is_empty(), self.uart.as_mut()) {
            uart.listen();
        }
    }

    fn ready(&mut self, queue: &mut FrameQueue<TX_QUEUE_LEN>) {
        let Some(uart) = self.uart.as_mut() else {
            return;
        };
        // The interrupt is shared with the receiver: only an empty
        // transmit register takes a byte (none is lost to a full one).
        if !uart.is_tx_empty() {
            return;
        }
        match queue.pop() {
            // TXE is set (that is why we are here), so the write succeeds.
            Some(byte) => {
                let _ = uart.write(byte);
            }
            None => uart.unlisten(),
        }
    }
}

/// Everything the contexts share.
static PROBE: SharedProbe<Device, Device, Usart1> = SharedProbe::new(Usart1 { uart: None });
/// The acquisition timer, whose interrupt flag its interrupt clears.
static TIMER: Mutex<RefCell<Option<Timer>>> = Mutex::new(RefCell::new(None));
/// Sample periods begun (TIM2 interrupts), for one main-loop pass each.
static TICKS: SamplePeriods = SamplePeriods::new();
/// USART1's receiver and the interrupt's end of the uplink inbox (set once
/// in `main`).
static UPLINK_RX: Mutex<RefCell<Option<(UartRx, InboxWriter<'static>)>>> =
    Mutex::new(RefCell::new(None));

/// Every panic ends here (panic-probe logs it, then executes `udf`, which
/// escalates to a hard fault), as does any real fault: reset the chip
/// rather than spin, so a failed start-up (the `panic!`s in `main` and
/// `board::init`) reboots the probe, which announces itself again with a
/// boot event, instead of hanging it.
// SAFETY: cortex-m-rt requires the handler to be an `unsafe fn`; it only
// requests a system reset.
#[exception]
unsafe fn HardFault(_frame: &ExceptionFrame) -> ! {
    cortex_m::peripheral::SCB::sys_reset()
}

#[interrupt]
fn TIM2() {
    critical_section::with(|cs| {
        if let Some(timer) = TIMER.borrow_ref_mut(cs).as_mut() {
            timer.clear_flags(Flag::Update);
        }
    });
    TICKS.begin();
    PROBE.with(|shared| shared.acquire());
}

/// USART1: received bytes into the inbox (a full inbox drops and counts
/// them; a byte with a framing, noise or overrun error is discarded, which
/// the uplink's CRC then catches), then the transmitter.
#[interrupt]
fn USART1() {
    critical_section::with(|cs| {
        if let Some((rx, writer)) = UPLINK_RX.borrow_ref_mut(cs).as_mut() {
            while rx.is_rx_not_empty() {
                if let Ok(byte) = rx.read() {
                    writer.push(byte);
                }
            }
        }
    });
    PROBE.with(|shared| shared.transmitter_ready());
}

/// The real board as the main loop sees it (`firmware::app::main_loop`):
/// TIM2's periods for its clock, SysTick for its delay, the independent
/// watchdog.
struct Stm32 {
    basics: BoardBasics<SysDelay, Iwdg>,
}

/// The independent watchdog (started in `board::init`).
struct Iwdg(IndependentWatchdog);

impl Watchdog for Iwdg {
    fn feed(&mut self) {
        self.0.feed();
    }
}

impl main_loop::Board for Stm32 {
    type Gyro = Device;
    type Accel = Device;
    type Uart = Usart1;
    type Flash = SectorFlash;
    type Delay = SysDelay;
    type Watchdog = Iwdg;
    type Stop = Infallible;

    fn basics(&mut self) -> &mut BoardBasics<SysDelay, Iwdg> {
        &mut self.basics
    }

    fn wait_for_interrupt(&mut self) {
        cortex_m::asm::wfi();
    }

    /// The last byte may still be on the line (the transmitter cannot say):
    /// its 87 us at 115200 baud, then the reset.
    fn reboot(&mut self) -> ! {
        self.basics.delay.delay_ms(1);
        cortex_m::peripheral::SCB::sys_reset()
    }
}

#[entry]
fn main() -> ! {
    let (Some(dp), Some(core)) = (pac::Peripherals::take(), cortex_m::Peripherals::take()) else {
        defmt::panic!("peripherals taken twice");
    };
    let reset_cause = take_reset_cause(&dp.RCC);
    let board = match board::init(dp, core.SYST) {
        Ok(board) => board,
        Err(what) => defmt::panic!("board set-up failed: {=str}", what),
    };
    let board::Board {
        sensors,
        uart,
        mut uart_rx,
        flash,
        mut timer,
        delay,
        watchdog,
    } = board;
    defmt::info!("probe-stm32 v{=u16}: booting", FIRMWARE_VERSION);
    if timer.start(SAMPLES_PER_SECOND.Hz()).is_err() {
        defmt::panic!("TIM2 cannot run at the sample rate");
    }
    timer.listen(TimerEvent::Update);
    PROBE.with(|shared| shared.transmitter_mut().uart = Some(uart));
    let Some(inbox) = cortex_m::singleton!(: UplinkInbox = UplinkInbox::new()) else {
        defmt::panic!("uplink inbox taken twice");
    };
    let (writer, mut uplink_reader) = inbox.split();
    uart_rx.listen();
    critical_section::with(|cs| *UPLINK_RX.borrow_ref_mut(cs) = Some((uart_rx, writer)));
    critical_section::with(|cs| *TIMER.borrow_ref_mut(cs) = Some(timer));
    // SAFETY: register writes of the NVIC, done once before the handlers
    // share anything; both handlers only touch state behind critical
    // sections, so unmasking them cannot break a critical section.
    unsafe {
        let mut nvic = core.NVIC;
        nvic.set_priority(Interrupt::TIM2, PRIORITY_ACQUISITION);
        nvic.set_priority(Interrupt::USART1, PRIORITY_UART);
        NVIC::unmask(Interrupt::TIM2);
        NVIC::unmask(Interrupt::USART1);
    }

    // The watchdog runs since `board::init`; the start-up feeds it after
    // each attempt.
    let mut board = Stm32 {
        basics: BoardBasics::new(delay, Iwdg(watchdog), &TICKS),
    };
    // The loop never returns here (`Infallible`).
    match main_loop::run(
        &mut board,
        &PROBE,
        sensors,
        SectorFlash::new(flash),
        reset_cause,
        &mut uplink_reader,
    ) {}
}

/// Why the chip restarted, from RCC_CSR's reset flags (RM0383 6.3.21),
/// which are then cleared (RMVF) so the next boot sees only its own. The
/// pin flag is set by every reset (the internal ones drive NRST too) and
/// a power-on also sets the brown-out flag, hence the order.
fn take_reset_cause(rcc: &pac::RCC) -> ResetCause {
    let csr = rcc.csr().read();
    let cause = if csr.porrstf().bit_is_set() {
        ResetCause::PowerOn
    } else if csr.borrstf().bit_is_set() {
        ResetCause::BrownOut
    } else if csr.wdgrstf().bit_is_set() || csr.wwdgrstf().bit_is_set() {
        ResetCause::Watchdog
    } else if csr.sftrstf().bit_is_set() {
        ResetCause::Software
    } else if csr.padrstf().bit_is_set() {
        ResetCause::Pin
    } else {
        // The low-power reset, or no flag: nothing to tell.
        ResetCause::NotReported
    };
    rcc.csr().modify(|_, w| w.rmvf().set_bit());
    cause
}
