//! The probe on the real board (STM32F411, see `board.rs` for the pin map):
//! the same application core as the QEMU probe, with the two SCC1300 parts
//! on SPI1, frames out of USART1 at 115200 baud and logs through defmt over
//! RTT (`cargo run` in `firmware/` flashes through probe-rs and shows them).
//!
//! Contexts, highest priority first:
//! - TIM2 at 20 Hz: takes the sample (its instant is the timer's, not the
//!   main loop's) and queues the raw frame and any fault events;
//! - USART1 (TX empty): moves the next queued byte into the transmitter;
//! - main loop: start-up, blocking sensor recovery, the navigation on each
//!   raw sample (navigation frames); feeds the watchdog between those steps
//!   (`firmware::app::budget`); sleeps otherwise.
//!
//! Nothing hangs the board: the watchdog starts first thing
//! (`board::init`), and a panic or fault resets the chip at once (the
//! `HardFault` handler below), after panic-probe has logged it.
//!
//! What the contexts share and do is `firmware::app::SharedProbe`, as on
//! the QEMU board; this file adds USART1 as its `Transmitter`, TIM2, the
//! NVIC and the watchdog.
#![no_std]
#![no_main]

mod board;

use core::cell::RefCell;

use cortex_m_rt::{entry, exception, ExceptionFrame};
use critical_section::Mutex;
use defmt_rtt as _;
use firmware::app::boot::{boot_event_value, ConfigSource, ResetCause};
use firmware::app::{FrameQueue, SharedProbe, Transmitter, FIRMWARE_VERSION, TX_QUEUE_LEN};
use mwd_core::earth::Position;
use mwd_core::probe::Navigator;
use mwd_core::timing::SAMPLE_RATE_HZ;
use panic_probe as _;
use stm32f4xx_hal::pac::{self, interrupt, Interrupt, NVIC};
use stm32f4xx_hal::prelude::*;
use stm32f4xx_hal::serial::TxListen;
use stm32f4xx_hal::timer::{Event as TimerEvent, Flag};

use board::{Device, Timer, Uart};

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
    PROBE.with(|shared| shared.acquire());
}

#[interrupt]
fn USART1() {
    PROBE.with(|shared| shared.transmitter_ready());
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
        mut timer,
        mut delay,
        mut watchdog,
    } = board;
    defmt::info!("probe-stm32 v{=u16}: booting", FIRMWARE_VERSION);
    if timer.start(SAMPLES_PER_SECOND.Hz()).is_err() {
        defmt::panic!("TIM2 cannot run at the sample rate");
    }
    timer.listen(TimerEvent::Update);
    PROBE.with(|shared| shared.transmitter_mut().uart = Some(uart));
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

    // No configuration on this board yet: its source is not reported.
    PROBE.announce_boot_with(boot_event_value(reset_cause, ConfigSource::NotReported, 0));
    // The watchdog runs since `board::init`; the start-up feeds it after
    // each attempt.
    watchdog.feed();
    PROBE.start_streaming(sensors, &mut delay, &mut || watchdog.feed());
    defmt::info!("streaming at {=u32} Hz", SAMPLES_PER_SECOND);

    // The probe's site: the MGWD paper's test site until it is configurable.
    let mut navigator = Navigator::new(Position::paper_site());
    loop {
        PROBE.main_loop_pass(
            &mut delay,
            &mut navigator,
            &mut || watchdog.feed(),
            |part, code| defmt::warn!("part {=u8} recovered, code {=u16}", part, code),
            |_| {},
        );
        cortex_m::asm::wfi();
    }
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
