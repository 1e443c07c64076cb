//! The real board: an STM32F411CEU6 ("black pill", 25 MHz crystal). The one
//! place that names pins and clocks.
//!
//! | signal              | pin  | note                                   |
//! | ------------------- | ---- | -------------------------------------- |
//! | SPI1 SCK            | PA5  | both SCC1300 parts, mode 0, 500 kHz     |
//! | SPI1 MISO           | PA6  |                                        |
//! | SPI1 MOSI           | PA7  |                                        |
//! | part 0 gyro CS      | PA4  | active low                             |
//! | part 0 accel CS     | PB0  | active low                             |
//! | part 1 gyro CS      | PB1  | active low                             |
//! | part 1 accel CS     | PB10 | active low (PB2 is BOOT1: not used)    |
//! | USART1 TX           | PA9  | frames to the surface, 115200 8N1      |
//! | USART1 RX           | PA10 | the host's commands (uplink), 115200   |
//! | SWDIO / SWCLK       | PA13 / PA14 | probe-rs: flashing, RTT logs    |
//!
//! Timers: TIM2 at 20 Hz is the acquisition; SysTick is the blocking delay
//! of start-up and recovery; the independent watchdog runs from the LSI.
//! Flash sectors 6-7 hold the configuration (`flash.rs`).

use core::cell::RefCell;

use critical_section::Mutex;
use embedded_hal_bus::spi::{CriticalSectionDevice, NoDelay};
use firmware::app::WATCHDOG_TIMEOUT_MS;
use firmware::scc1300::datasheet::SPI_CLOCK_HZ;
use firmware::scc1300::Part;
use stm32f4xx_hal::gpio::{ErasedPin, Output, PushPull};
use stm32f4xx_hal::pac::{self, SPI1, TIM2, USART1};
use stm32f4xx_hal::prelude::*;
use stm32f4xx_hal::rcc::Clocks;
use stm32f4xx_hal::serial::{config::Config, Rx, Serial, Tx};
use stm32f4xx_hal::spi::{Mode, Phase, Polarity, Spi};
use stm32f4xx_hal::timer::{CounterHz, SysDelay};
use stm32f4xx_hal::watchdog::IndependentWatchdog;

/// The crystal of the black pill and the core clock (the F411's 100 MHz
/// maximum would need the PLL's odd divider; 96 MHz keeps USB's 48 MHz).
const HSE_MHZ: u32 = 25;
const SYSCLK_MHZ: u32 = 96;
pub const BAUD: u32 = 115_200;

pub type Bus = Spi<SPI1>;
pub type Cs = ErasedPin<Output<PushPull>>;
pub type Device = CriticalSectionDevice<'static, Bus, Cs, NoDelay>;
pub type Sensors = firmware::app::Sensors<Device, Device>;
pub type Uart = Tx<USART1>;
pub type UartRx = Rx<USART1>;
pub type Timer = CounterHz<TIM2>;

/// What the application needs from the board.
pub struct Board {
    pub sensors: Sensors,
    pub uart: Uart,
    pub uart_rx: UartRx,
    /// The flash's registers (the configuration's sectors).
    pub flash: pac::FLASH,
    pub timer: Timer,
    pub delay: SysDelay,
    pub watchdog: IndependentWatchdog,
}

/// The watchdog first, then clocks, pins and peripherals. Fails (the caller
/// logs and resets) only on a configuration the HAL rejects, which is a
/// build-time mistake; a hang here (e.g. a crystal that never starts:
/// `freeze` waits for it) is ended by the watchdog.
pub fn init(dp: pac::Peripherals, syst: cortex_m::peripheral::SYST) -> Result<Board, &'static str> {
    // From the LSI, independent of the clocks set up below; its timeout is
    // sized against the LSI's 17-47 kHz (`firmware::app::watchdog`).
    let mut watchdog = IndependentWatchdog::new(dp.IWDG);
    watchdog.start(WATCHDOG_TIMEOUT_MS.millis());
    let rcc = dp.RCC.constrain();
    let clocks: Clocks = rcc
        .cfgr
        .use_hse(HSE_MHZ.MHz())
        .sysclk(SYSCLK_MHZ.MHz())
        .freeze();
    let gpioa = dp.GPIOA.split();
    let gpiob = dp.GPIOB.split();

    let mode = Mode {
        polarity: Polarity::IdleLow,
        phase: Phase::CaptureOnFirstTransition,
    };
    let spi = dp.SPI1.spi(
        (gpioa.pa5, gpioa.pa6, gpioa.pa7),
        mode,
        SPI_CLOCK_HZ.Hz(),
        &clocks,
    );
    // The four devices share the bus from the timer interrupt and the main
    // loop (recovery), so the bus lives in a critical-section mutex.
    let bus: &'static Mutex<RefCell<Bus>> =
        cortex_m::singleton!(: Mutex<RefCell<Bus>> = Mutex::new(RefCell::new(spi)))
            .ok_or("SPI bus set up twice")?;
    let cs = |pin: Cs| {
        let mut pin = pin;
        pin.set_high();
        CriticalSectionDevice::new(bus, pin, NoDelay).map_err(|_| "chip select")
    };
    let sensors = [
        Part::new(
            cs(gpioa.pa4.into_push_pull_output().erase())?,
            cs(gpiob.pb0.into_push_pull_output().erase())?,
        ),
        Part::new(
            cs(gpiob.pb1.into_push_pull_output().erase())?,
            cs(gpiob.pb10.into_push_pull_output().erase())?,
        ),
    ];

    let (uart, uart_rx) = Serial::new(
        dp.USART1,
        (gpioa.pa9, gpioa.pa10),
        Config::default().baudrate(BAUD.bps()),
        &clocks,
    )
    .map_err(|_| "USART1 configuration")?
    .split();
    let timer = dp.TIM2.counter_hz(&clocks);
    let delay = syst.delay(&clocks);
    Ok(Board {
        sensors,
        uart,
        uart_rx,
        flash: dp.FLASH,
        timer,
        delay,
        watchdog,
    })
}
