//! The QEMU board's sensors: two hil-mock SCC1300 parts behind the real
//! driver, on four "chip selects" that call into the simulated parts.
//!
//! The parts read the board's time (whole 20 Hz timer periods), so their
//! 800 ms start-up and any timed fault follow the same clock as the
//! samples, and a run repeats exactly.
//!
//! The drilling run (feature `qemu-drilling`) feeds both parts from a
//! simulated sensor stream read through semihosting (`stream_file.rs`,
//! `hil_mock::stream`): raw sample `n` quantises the stream's record `n`,
//! and the run ends with the stream.

use core::cell::{OnceCell, RefCell};

use critical_section::Mutex;
use embedded_hal::delay::DelayNs;
use embedded_hal::spi::{ErrorType, Operation, SpiDevice};
use firmware::app::SamplePeriods;
use firmware::scc1300::Part;
use hil_mock::{
    AccelSpi, Chance, GyroSpi, MockBusError, Scc1300, TemperatureExcursion, TimeSource, Window,
    SAMPLE_PERIOD_NS,
};
#[cfg(not(feature = "qemu-drilling"))]
use hil_mock::{MountedSource, StillProbe};
#[cfg(not(feature = "qemu-drilling"))]
use mwd_core::sensor_units::PART_MOUNTINGS;

use crate::run_length::SAMPLES_PER_SECOND;

/// Timer periods since boot, counted by the SysTick interrupt.
pub static TICKS: SamplePeriods = SamplePeriods::new();

/// The board's clock as the simulated parts see it.
pub struct BoardClock;

impl TimeSource for BoardClock {
    fn now_ns(&self) -> u64 {
        u64::from(TICKS.count()) * SAMPLE_PERIOD_NS
    }
}

/// Waits by sleeping until enough timer periods have passed: rounded up to
/// whole periods, so every wait of the driver is at least what it asked.
pub struct TickDelay;

impl DelayNs for TickDelay {
    fn delay_ns(&mut self, ns: u32) {
        let periods = u64::from(ns).div_ceil(SAMPLE_PERIOD_NS) as u32;
        let target = TICKS.count().wrapping_add(periods);
        // Wrapping comparison: correct across the counter's overflow.
        while (TICKS.count().wrapping_sub(target) as i32) < 0 {
            cortex_m::asm::wfi();
        }
    }
}

/// The parts sense a probe lying still at the MGWD paper's site and
/// attitude, with earth rate, gravity, residual biases and white noise
/// (`hil_mock::StillProbe`); each part has its own noise stream.
#[cfg(not(feature = "qemu-drilling"))]
type PartSource = MountedSource<StillProbe>;
/// The drilling run: each part reads its values of the stream's current
/// record (already in its own axes, sensor errors applied by the host).
#[cfg(feature = "qemu-drilling")]
type PartSource = hil_mock::StreamSource<fn(usize) -> hil_mock::PhysicalSample>;
type MockPart = Scc1300<BoardClock, PartSource>;

/// The two simulated parts; set once at boot, then used from whichever
/// context (timer interrupt or main loop) holds the driver.
static PARTS: Mutex<[OnceCell<RefCell<MockPart>>; 2]> =
    Mutex::new([OnceCell::new(), OnceCell::new()]);

/// Which slave of a part a [`MockBus`] selects.
#[derive(Clone, Copy)]
enum Slave {
    Gyro,
    Accel,
}

/// One chip select of one simulated part.
pub struct MockBus {
    part: usize,
    slave: Slave,
}

impl ErrorType for MockBus {
    type Error = MockBusError;
}

impl SpiDevice for MockBus {
    fn transaction(&mut self, operations: &mut [Operation<'_, u8>]) -> Result<(), MockBusError> {
        critical_section::with(|cs| {
            let parts = PARTS.borrow(cs);
            let part = parts
                .get(self.part)
                .and_then(OnceCell::get)
                .ok_or(MockBusError)?;
            match self.slave {
                Slave::Gyro => GyroSpi::new(part).transaction(operations),
                Slave::Accel => AccelSpi::new(part).transaction(operations),
            }
        })
    }
}

/// The probe's two parts, as the driver sees them.
pub type Sensors = firmware::app::Sensors<MockBus, MockBus>;

/// The parts' source: the still probe, each part its own noise stream.
#[cfg(not(feature = "qemu-drilling"))]
fn part_source(index: usize) -> PartSource {
    MountedSource {
        body: StillProbe::paper_test(1 + index as u64),
        mounting: PART_MOUNTINGS[index],
    }
}

/// How many samples the run streams.
#[cfg(not(feature = "qemu-drilling"))]
pub fn samples_to_run() -> u32 {
    crate::run_length::SAMPLES_TO_RUN
}

/// Called by the timer just before it takes raw sample `sample` (counted
/// from the start of streaming).
pub fn before_sample(sample: u32) {
    inject_scheduled_faults(sample);
    #[cfg(feature = "qemu-drilling")]
    drilling::select(sample);
}

/// Powers the simulated parts up (now) and returns their drivers.
pub fn power_up() -> Sensors {
    #[cfg(feature = "qemu-drilling")]
    drilling::open();
    critical_section::with(|cs| {
        for (index, cell) in PARTS.borrow(cs).iter().enumerate() {
            let source = part_source(index);
            // Already set only if called twice; keep the first parts then.
            let _ = cell.set(RefCell::new(Scc1300::new(
                BoardClock,
                source,
                1 + index as u32,
            )));
        }
    });
    [0, 1].map(|part| {
        Part::new(
            MockBus {
                part,
                slave: Slave::Gyro,
            },
            MockBus {
                part,
                slave: Slave::Accel,
            },
        )
    })
}

/// The fault run (feature `qemu-fault-demo`): faults injected into the
/// simulated parts at fixed samples, so the end-to-end test sees each one
/// come back as event frames while the stream goes on. `sample` counts
/// from the start of streaming.
pub fn inject_scheduled_faults(sample: u32) {
    // When each fault comes (tests/tests/qemu_probe.rs expects these times).
    const PARITY_ERRORS: u32 = 10 * SAMPLES_PER_SECOND;
    const S_OK_DROP: u32 = 20 * SAMPLES_PER_SECOND;
    const POWER_CYCLE: u32 = 30 * SAMPLES_PER_SECOND;
    const OVERHEAT: u32 = 40 * SAMPLES_PER_SECOND;
    const BOTH_LOOPS_FAIL: u32 = 50 * SAMPLES_PER_SECOND;
    if !cfg!(feature = "qemu-fault-demo") {
        return;
    }
    let now_ns = BoardClock.now_ns();
    critical_section::with(|cs| {
        let parts = PARTS.borrow(cs);
        let with_part = |index: usize, f: &mut dyn FnMut(&mut MockPart)| {
            if let Some(part) = parts.get(index).and_then(OnceCell::get) {
                f(&mut part.borrow_mut());
            }
        };
        match sample {
            // Two corrupted gyro answers on part 0 (parity errors).
            PARITY_ERRORS => with_part(0, &mut |p| p.faults.gyro.miso_parity = Chance::next(2)),
            // Part 1's gyro loses S_OK for 100 ms (not ready, then the
            // driver's supervision).
            S_OK_DROP => with_part(1, &mut |p| {
                p.faults.s_ok_drop = Some(Window {
                    start_ns: now_ns,
                    end_ns: now_ns + 100_000_000,
                })
            }),
            // Part 0 power-cycles (both slaves restart: recovery).
            POWER_CYCLE => with_part(0, &mut |p| p.faults.reset_at_ns = Some(now_ns)),
            // Part 1 reads 200 degC for 1 s (its count clips at 8191).
            OVERHEAT => with_part(1, &mut |p| {
                p.faults.temperature = Some(TemperatureExcursion {
                    window: Window {
                        start_ns: now_ns,
                        end_ns: now_ns + 1_000_000_000,
                    },
                    degc: 200,
                })
            }),
            // Both gyros lose their drive loop: the driver's worst recovery
            // (two soft resets with their 800 ms start-ups, ~1.9 s here).
            BOTH_LOOPS_FAIL => {
                for index in 0..2 {
                    with_part(index, &mut |p| p.faults.loop_failure_at_ns = Some(now_ns));
                }
            }
            _ => {}
        }
    });
}

#[cfg(feature = "qemu-drilling")]
use drilling::part_source;
#[cfg(feature = "qemu-drilling")]
pub use drilling::samples_to_run;

/// The drilling run's stream player, shared by both parts.
#[cfg(feature = "qemu-drilling")]
mod drilling {
    use core::cell::RefCell;
    use core::sync::atomic::{AtomicU32, Ordering};

    use cortex_m_semihosting::hprintln;
    use critical_section::Mutex;
    use hil_mock::{PhysicalSample, StreamError, StreamPlayer, StreamSource};

    use super::PartSource;
    use crate::stream_file::{self, HostFile};

    /// The player's read buffer: 12 records (480 bytes), one semihosting
    /// read per 0.6 s of samples. RAM: the buffer plus ~70 bytes of state
    /// (the probe's 32 KiB budget, docs/budgets.md).
    const BUFFER_LEN: usize = 12 * hil_mock::stream::RECORD_LEN;

    type Player = StreamPlayer<HostFile, BUFFER_LEN>;

    static PLAYER: Mutex<RefCell<Option<Player>>> = Mutex::new(RefCell::new(None));
    /// The stream's length in samples: the run's length. Until the stream
    /// is open, no limit.
    static SAMPLES: AtomicU32 = AtomicU32::new(u32::MAX);

    pub fn samples_to_run() -> u32 {
        SAMPLES.load(Ordering::Relaxed)
    }

    fn fail(error: StreamError) -> ! {
        hprintln!(
            "probe-qemu: sensor stream {}: {}",
            stream_file::path(),
            error
        );
        crate::exit::fail("the sensor stream could not be read")
    }

    /// Opens the stream (its header and first record) or ends the run.
    pub fn open() {
        let player = match HostFile::open().and_then(Player::open) {
            Ok(player) => player,
            Err(e) => fail(e),
        };
        SAMPLES.store(player.header().sample_count, Ordering::Relaxed);
        critical_section::with(|cs| *PLAYER.borrow_ref_mut(cs) = Some(player));
    }

    /// Makes record `sample` current (the timer never asks beyond the
    /// stream's length: the run ends there).
    pub fn select(sample: u32) {
        let result = critical_section::with(|cs| match PLAYER.borrow_ref_mut(cs).as_mut() {
            Some(player) => player.advance_to(sample),
            None => Ok(()),
        });
        if let Err(e) = result {
            fail(e);
        }
    }

    /// Part `part`'s value in the current record.
    fn feed(part: usize) -> PhysicalSample {
        critical_section::with(|cs| {
            PLAYER
                .borrow_ref(cs)
                .as_ref()
                .map_or_else(PhysicalSample::default, |p| p.part(part))
        })
    }

    pub fn part_source(index: usize) -> PartSource {
        StreamSource {
            feed: feed as fn(usize) -> PhysicalSample,
            part: index,
        }
    }
}
