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
//!   raw sample (navigation frames); feeds the watchdog; sleeps otherwise.
#![no_std]
#![no_main]

mod board;

use core::cell::RefCell;

use cortex_m_rt::entry;
use critical_section::{CriticalSection, Mutex};
use defmt_rtt as _;
use firmware::app::{start_parts, ProbeState, Recovery};
use mwd_core::earth::Position;
use mwd_core::probe::Navigator;
use mwd_core::protocol::frame::NO_PART;
use mwd_core::protocol::{EventKind, Payload};
use panic_probe as _;
use stm32f4xx_hal::pac::{self, interrupt, Interrupt, NVIC};
use stm32f4xx_hal::prelude::*;
use stm32f4xx_hal::serial::TxListen;
use stm32f4xx_hal::timer::{Event as TimerEvent, Flag};

use board::{Device, Timer, Uart};

/// The main loop must come round within this (a recovery holds it ~1 s).
const WATCHDOG_MS: u32 = 2_000;
const VERSION: u16 = 1;
/// NVIC priorities (upper 4 bits on the F411; lower number = more urgent).
const PRIORITY_ACQUISITION: u8 = 0x10;
const PRIORITY_UART: u8 = 0x20;

/// Everything the contexts share; only touched inside critical sections.
struct Shared {
    probe: ProbeState<Device, Device>,
    uart: Option<Uart>,
    timer: Option<Timer>,
}

static SHARED: Mutex<RefCell<Shared>> = Mutex::new(RefCell::new(Shared {
    probe: ProbeState::new(),
    uart: None,
    timer: None,
}));

fn with_shared<R>(f: impl FnOnce(&mut Shared, CriticalSection) -> R) -> R {
    critical_section::with(|cs| f(&mut SHARED.borrow_ref_mut(cs), cs))
}

/// Bytes wait: let the TX-empty interrupt move them (it fires at once if
/// the transmitter is idle).
fn kick_transmitter(shared: &mut Shared) {
    if let (false, Some(uart)) = (shared.probe.queue.is_empty(), shared.uart.as_mut()) {
        uart.listen();
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

#[interrupt]
fn TIM2() {
    with_shared(|shared, _| {
        if let Some(timer) = shared.timer.as_mut() {
            timer.clear_flags(Flag::Update);
        }
        shared.probe.acquire();
        kick_transmitter(shared);
    });
}

#[interrupt]
fn USART1() {
    with_shared(|shared, _| {
        let Some(uart) = shared.uart.as_mut() else {
            return;
        };
        match shared.probe.queue.pop() {
            // TXE is set (that is why we are here), so the write succeeds.
            Some(byte) => {
                let _ = uart.write(byte);
            }
            None => uart.unlisten(),
        }
    });
}

/// Recovery of the parts that asked for it, outside any critical section.
fn recover(mut job: Recovery<Device, Device>, delay: &mut stm32f4xx_hal::timer::SysDelay) {
    job.run(delay, |part, code| {
        defmt::warn!("part {=u8} recovered, code {=u16}", part, code);
        push_event(EventKind::SensorReset, part, code, 0);
    });
    let resync = with_shared(|shared, _| shared.probe.end_recovery(job));
    push(&resync);
}

#[entry]
fn main() -> ! {
    let (Some(dp), Some(core)) = (pac::Peripherals::take(), cortex_m::Peripherals::take()) else {
        defmt::panic!("peripherals taken twice");
    };
    let board = match board::init(dp, core.SYST) {
        Ok(board) => board,
        Err(what) => defmt::panic!("board set-up failed: {=str}", what),
    };
    let board::Board {
        mut sensors,
        uart,
        mut timer,
        mut delay,
        mut watchdog,
    } = board;
    defmt::info!("probe-stm32 v{=u16}: booting", VERSION);
    if timer.start(20.Hz()).is_err() {
        defmt::panic!("TIM2 cannot run at 20 Hz");
    }
    timer.listen(TimerEvent::Update);
    with_shared(|shared, _| {
        shared.uart = Some(uart);
        shared.timer = Some(timer);
    });
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

    push_event(EventKind::Boot, NO_PART, VERSION, 0);
    watchdog.start(WATCHDOG_MS.millis());
    start_parts(&mut sensors, &mut delay, push);
    with_shared(|shared, _| shared.probe.start_streaming(sensors));
    defmt::info!("streaming at 20 Hz");

    // The probe's site: the MGWD paper's test site until it is configurable.
    let mut navigator = Navigator::new(Position::paper_site());
    loop {
        watchdog.feed();
        if let Some(job) = with_shared(|shared, _| shared.probe.take_recovery()) {
            recover(job, &mut delay);
        }
        while let Some(sample) = with_shared(|shared, _| shared.probe.nav_inbox.pop()) {
            push(&Payload::Nav(navigator.step(&sample)));
        }
        cortex_m::asm::wfi();
    }
}
