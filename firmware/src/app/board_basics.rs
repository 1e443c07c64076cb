//! What the main loop uses alike on every board ([`BoardBasics`]): the
//! blocking delay and the watchdog it drives, and the count of sample
//! periods the board's acquisition interrupt keeps ([`SamplePeriods`]).
//! A board holds them in one [`BoardBasics`] and hands it to the loop
//! ([`Board::basics`](super::main_loop::Board::basics)), so only what
//! differs (its sleep, restart and end of pass) is written per board.

use core::sync::atomic::{AtomicU32, Ordering};

/// Sample periods begun since boot, counted by the board's acquisition
/// interrupt ([`SamplePeriods::begin`]); kept in a static, as interrupts
/// and the main loop share it. Wraps after 2^32 periods.
pub struct SamplePeriods(AtomicU32);

impl SamplePeriods {
    pub const fn new() -> Self {
        Self(AtomicU32::new(0))
    }

    /// The acquisition interrupt's count: a new sample period began.
    pub fn begin(&self) {
        self.0.fetch_add(1, Ordering::Relaxed);
    }

    /// Periods begun since boot (wrapping).
    pub fn count(&self) -> u32 {
        self.0.load(Ordering::Relaxed)
    }
}

impl Default for SamplePeriods {
    fn default() -> Self {
        Self::new()
    }
}

/// The board's blocking delay (the parts' start-up and recovery), its
/// watchdog, and its clock of sample periods, as the main loop uses them.
pub struct BoardBasics<D, W> {
    pub delay: D,
    pub watchdog: W,
    periods: &'static SamplePeriods,
}

impl<D, W> BoardBasics<D, W> {
    pub const fn new(delay: D, watchdog: W, periods: &'static SamplePeriods) -> Self {
        Self {
            delay,
            watchdog,
            periods,
        }
    }

    /// Sample periods begun since boot (wrapping).
    pub fn ticks(&self) -> u32 {
        self.periods.count()
    }
}
