//! Every register access of the QEMU board, and with `stack_paint.rs` and
//! `persistent.rs` the only `unsafe` of the probe: the CMSDK APB UART0
//! (its link up and the host's commands down), the interrupt priorities
//! and the UART's NVIC lines, the CMSDK watchdog, the system reset.
//! Each block says why it is sound. Addresses and bits: ARM CMSDK APB UART
//! and watchdog (DDI 0479) and the mps2-an386 memory map (UART0 at
//! 0x4000_4000, its RX interrupt is IRQ 0 and its TX interrupt IRQ 1;
//! watchdog at 0x4000_8000).
#![allow(unsafe_code)]

use cortex_m::interrupt::InterruptNumber;
use cortex_m::peripheral::scb::SystemHandler;
use cortex_m::peripheral::{NVIC, SCB};

const UART0_BASE: usize = 0x4000_4000;
const DATA: usize = UART0_BASE;
const STATE: usize = UART0_BASE + 0x4;
const CTRL: usize = UART0_BASE + 0x8;
/// INTSTATUS on read, INTCLEAR (write 1 to clear) on write.
const INTCLEAR: usize = UART0_BASE + 0xC;
const BAUDDIV: usize = UART0_BASE + 0x10;

const STATE_TX_FULL: u32 = 1 << 0;
const STATE_RX_FULL: u32 = 1 << 1;
const CTRL_TX_ENABLE: u32 = 1 << 0;
const CTRL_RX_ENABLE: u32 = 1 << 1;
const CTRL_TX_INTERRUPT: u32 = 1 << 2;
const CTRL_RX_INTERRUPT: u32 = 1 << 3;
const INT_TX: u32 = 1 << 0;
const INT_RX: u32 = 1 << 1;

/// The board's 25 MHz system clock; UART divider and SysTick count it.
pub const SYSTEM_CLOCK_HZ: u32 = 25_000_000;
const BAUD: u32 = 115_200;

/// UART0's transmit interrupt line.
#[derive(Clone, Copy)]
pub struct Uart0Tx;

pub const UART0_TX_IRQ: i16 = 1;

// SAFETY: 1 is UART0 TX's line on mps2-an386, a valid NVIC interrupt number.
unsafe impl InterruptNumber for Uart0Tx {
    fn number(self) -> u16 {
        UART0_TX_IRQ as u16
    }
}

/// UART0's receive interrupt line.
#[derive(Clone, Copy)]
pub struct Uart0Rx;

pub const UART0_RX_IRQ: i16 = 0;

// SAFETY: 0 is UART0 RX's line on mps2-an386, a valid NVIC interrupt number.
unsafe impl InterruptNumber for Uart0Rx {
    fn number(self) -> u16 {
        UART0_RX_IRQ as u16
    }
}

fn write(addr: usize, value: u32) {
    // SAFETY: only called with the UART0 and watchdog addresses above, which
    // are aligned, always mapped on this board, and have no memory aliasing
    // with Rust objects; a volatile write is how the device is programmed.
    unsafe { core::ptr::write_volatile(addr as *mut u32, value) }
}

fn read(addr: usize) -> u32 {
    // SAFETY: as for `write`; reading these registers has no side effect.
    unsafe { core::ptr::read_volatile(addr as *const u32) }
}

/// 115200 baud (ignored by QEMU, right on hardware), transmitter and
/// receiver with their interrupts on. The receiver holds one byte: its
/// interrupt moves each into the uplink's inbox at once.
pub fn uart_init() {
    write(CTRL, 0);
    write(BAUDDIV, SYSTEM_CLOCK_HZ / BAUD);
    write(
        CTRL,
        CTRL_TX_ENABLE | CTRL_TX_INTERRUPT | CTRL_RX_ENABLE | CTRL_RX_INTERRUPT,
    );
}

/// The received byte, if one is waiting (reading DATA frees the receiver).
pub fn uart_read() -> Option<u8> {
    if read(STATE) & STATE_RX_FULL == 0 {
        return None;
    }
    Some(read(DATA) as u8)
}

/// Acknowledges the receive interrupt.
pub fn uart_clear_rx_interrupt() {
    write(INTCLEAR, INT_RX);
}

/// The transmitter's one-byte buffer is free.
pub fn uart_ready() -> bool {
    read(STATE) & STATE_TX_FULL == 0
}

/// Hands one byte to the transmitter; check [`uart_ready`] first.
pub fn uart_write(byte: u8) {
    write(DATA, u32::from(byte));
}

/// Acknowledges the transmit interrupt (the buffer went empty).
pub fn uart_clear_tx_interrupt() {
    write(INTCLEAR, INT_TX);
}

const WATCHDOG_BASE: usize = 0x4000_8000;
const WDOG_LOAD: usize = WATCHDOG_BASE;
const WDOG_CONTROL: usize = WATCHDOG_BASE + 0x8;
const WDOG_INTCLR: usize = WATCHDOG_BASE + 0xC;
const WDOG_LOCK: usize = WATCHDOG_BASE + 0xC00;
const WDOG_UNLOCK_KEY: u32 = 0x1ACC_E551;
const WDOG_INTERRUPT_AND_RESET: u32 = 0b11;
/// The rate the watchdog counts at in QEMU 7.2's mps2-an386, measured, not
/// the 25 MHz SYSCLK one would expect: a LOAD of 50,000,000 expired after
/// 1.0 s of virtual time (20 SysTick periods without feeding).
const WDOG_COUNTS_PER_MS: u32 = 50_000;

/// Starts the CMSDK watchdog: after `timeout_ms` without [`watchdog_feed`]
/// it raises its interrupt (the NMI on this board), after twice that it
/// resets the chip. The registers are locked again against stray writes.
pub fn watchdog_start(timeout_ms: u32) {
    write(WDOG_LOCK, WDOG_UNLOCK_KEY);
    write(WDOG_LOAD, WDOG_COUNTS_PER_MS.saturating_mul(timeout_ms));
    write(WDOG_CONTROL, WDOG_INTERRUPT_AND_RESET);
    write(WDOG_LOCK, 0);
}

/// Restarts the watchdog's count (clearing its interrupt reloads it).
pub fn watchdog_feed() {
    write(WDOG_LOCK, WDOG_UNLOCK_KEY);
    write(WDOG_INTCLR, 1);
    write(WDOG_LOCK, 0);
}

/// The acquisition timer (SysTick) preempts the UART's interrupts, so the
/// sample instant never waits for transmission or reception; then the
/// UART's lines are enabled.
pub fn set_priorities_and_enable_uart_irq(scb: &mut SCB, nvic: &mut NVIC) {
    // SAFETY: changing priorities is unsafe only because it can break
    // priority-based critical sections; this program uses none (its critical
    // sections mask all interrupts), and it runs before interrupts are on.
    unsafe {
        scb.set_priority(SystemHandler::SysTick, 0x00);
        nvic.set_priority(Uart0Tx, 0x80);
        nvic.set_priority(Uart0Rx, 0x80);
        NVIC::unmask(Uart0Tx);
        NVIC::unmask(Uart0Rx);
    }
}

/// Restarts the chip (SCB AIRCR SYSRESETREQ; in QEMU a guest reset, which
/// keeps RAM: `persistent.rs`).
pub fn system_reset() -> ! {
    cortex_m::peripheral::SCB::sys_reset()
}
