//! Time for the simulated part: a [`TimeSource`] it reads, and on the host
//! a [`SimClock`] that tests advance by hand or through [`SimDelay`], so the
//! 800 ms start-up costs no wall-clock time and runs are deterministic.

use core::cell::Cell;
use embedded_hal::delay::DelayNs;
use mwd_core::timing::SAMPLE_PERIOD_US;

/// The probe's sample period on the simulated clock.
pub const SAMPLE_PERIOD_NS: u64 = SAMPLE_PERIOD_US * 1_000;

/// Where the part reads the time, in nanoseconds since its power-up.
pub trait TimeSource {
    fn now_ns(&self) -> u64;
}

/// A clock that only moves when told to.
#[derive(Debug, Default)]
pub struct SimClock {
    now_ns: Cell<u64>,
}

impl SimClock {
    pub const fn new() -> Self {
        Self {
            now_ns: Cell::new(0),
        }
    }

    pub fn advance_ns(&self, ns: u64) {
        self.now_ns.set(self.now_ns.get().saturating_add(ns));
    }

    pub fn advance_ms(&self, ms: u64) {
        self.advance_ns(ms.saturating_mul(1_000_000));
    }
}

impl TimeSource for SimClock {
    fn now_ns(&self) -> u64 {
        self.now_ns.get()
    }
}

impl<T: TimeSource + ?Sized> TimeSource for &T {
    fn now_ns(&self) -> u64 {
        (**self).now_ns()
    }
}

/// A `DelayNs` that advances a [`SimClock`] instead of waiting: hand it to
/// the driver so its start-up and supervision waits move the part's time.
pub struct SimDelay<'a> {
    clock: &'a SimClock,
}

impl<'a> SimDelay<'a> {
    pub fn new(clock: &'a SimClock) -> Self {
        Self { clock }
    }
}

impl DelayNs for SimDelay<'_> {
    fn delay_ns(&mut self, ns: u32) {
        self.clock.advance_ns(u64::from(ns));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn delay_advances_the_clock() {
        let clock = SimClock::new();
        let mut delay = SimDelay::new(&clock);
        delay.delay_ms(800);
        delay.delay_us(5);
        assert_eq!(clock.now_ns(), 800_005_000);
        clock.advance_ms(1);
        let by_ref: &SimClock = &clock;
        assert_eq!(TimeSource::now_ns(&by_ref), 801_005_000);
    }
}
