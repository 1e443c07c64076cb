//! The shared glue through the driver's worst recovery, on a board in
//! simulated time (the 20 Hz timer, the UART at 115200 baud, hil-mock
//! parts): no frame lost, the watchdog fed in time, inbox drops reported
//! (`super::super::budget`, docs/budgets.md).

extern crate std;

use super::*;
use crate::app::sensor_wire::fault_code;
use crate::app::test_support::{
    assert_navigated_in_order, drain, events_of, sent_frames, TestUart,
};
use crate::scc1300::Part;
use hil_mock::{
    AccelSpi, Constant, GyroSpi, Scc1300, SimClock, SimDelay, TimeSource, SAMPLE_PERIOD_NS,
};
use mwd_core::earth::Position;
use std::vec::Vec;

/// A board in simulated time, as the QEMU and real boards run: the 20 Hz
/// timer interrupt acquires, the UART's interrupt takes one byte every
/// 86.8 us (115200 baud 8N1), the main loop sleeps until the next interrupt,
/// and the driver's waits let the interrupts run meanwhile. Navigation and
/// SPI take no time here (their real cost is in the budget's margins); the
/// watchdog's feeds are timed.
struct SimBoard<'a, G, A> {
    clock: &'a SimClock,
    probe: &'a SharedProbe<G, A, TestUart>,
    next_tick_ns: core::cell::Cell<u64>,
    last_feed_ns: core::cell::Cell<u64>,
    longest_unfed_ns: core::cell::Cell<u64>,
}

/// One byte at 115200 baud, 10 bits per byte.
const BYTE_NS: u64 = 1_000_000_000 * 10 / 115_200;

impl<'a, G: SpiDevice, A: SpiDevice> SimBoard<'a, G, A> {
    fn new(clock: &'a SimClock, probe: &'a SharedProbe<G, A, TestUart>) -> Self {
        Self {
            clock,
            probe,
            next_tick_ns: core::cell::Cell::new(clock.now_ns() + SAMPLE_PERIOD_NS),
            last_feed_ns: core::cell::Cell::new(clock.now_ns()),
            longest_unfed_ns: core::cell::Cell::new(0),
        }
    }

    /// The next interrupt's time: the timer's, or the UART's next byte
    /// slot while it sends.
    fn next_interrupt_ns(&self) -> u64 {
        let now = self.clock.now_ns();
        let byte = if self.probe.with(|s| !s.transmitter().is_idle()) {
            (now / BYTE_NS + 1) * BYTE_NS
        } else {
            u64::MAX
        };
        byte.min(self.next_tick_ns.get())
    }

    /// Lets time pass to `until_ns`, running every interrupt on the way.
    fn run_until(&self, until_ns: u64) {
        loop {
            let next = self.next_interrupt_ns();
            let now = self.clock.now_ns();
            if next > until_ns {
                self.clock.advance_ns(until_ns.saturating_sub(now));
                return;
            }
            self.clock.advance_ns(next - now);
            if next == self.next_tick_ns.get() {
                self.next_tick_ns.set(next + SAMPLE_PERIOD_NS);
                self.probe.with(|s| s.acquire());
            } else {
                self.probe.with(|s| s.transmitter_ready());
            }
        }
    }

    /// The main loop's `wfi`.
    fn wait_for_interrupt(&self) {
        self.run_until(self.next_interrupt_ns());
    }

    fn feed(&self) {
        let now = self.clock.now_ns();
        let unfed = now - self.last_feed_ns.get();
        self.longest_unfed_ns
            .set(self.longest_unfed_ns.get().max(unfed));
        self.last_feed_ns.set(now);
    }
}

/// The board's blocking delay: interrupts go on while the main loop waits.
struct BoardDelay<'b, 'a, G, A>(&'b SimBoard<'a, G, A>);

impl<G: SpiDevice, A: SpiDevice> DelayNs for BoardDelay<'_, '_, G, A> {
    fn delay_ns(&mut self, ns: u32) {
        self.0.run_until(self.0.clock.now_ns() + u64::from(ns));
    }
}

#[test]
fn both_gyros_losing_their_loop_lose_no_frame_and_starve_no_watchdog() {
    use crate::app::budget::{RECOVERY_WORST_MS, WATCHDOG_UNFED_WORST_MS};
    use crate::app::watchdog::WATCHDOG_SHORTEST_MS;
    use crate::app::NAV_INBOX_LEN;

    let clock = SimClock::new();
    let mocks = [0, 1].map(|i| RefCell::new(Scc1300::new(&clock, Constant::default(), i)));
    let parts = [0, 1].map(|i| Part::new(GyroSpi::new(&mocks[i]), AccelSpi::new(&mocks[i])));
    let probe = SharedProbe::new(TestUart::default());
    let board = SimBoard::new(&clock, &probe);
    let mut delay = BoardDelay(&board);
    probe.announce_boot();
    let started = probe.start_streaming(parts, &mut delay, &mut || board.feed());
    assert_eq!(started, [None, None]);

    // Both gyros lose their drive loop at 3 s: the worst recovery the
    // driver has (two soft resets with their 800 ms start-ups, ~1.8 s).
    let fault_ns = clock.now_ns() + 3_000_000_000;
    for mock in &mocks {
        mock.borrow_mut().faults.loop_failure_at_ns = Some(fault_ns);
    }
    let mut navigator = Navigator::new(Position::paper_site());
    let mut resets = Vec::new();
    let end_ns = clock.now_ns() + 8_000_000_000;
    while clock.now_ns() < end_ns {
        probe.main_loop_pass(
            &mut delay,
            &mut navigator,
            &mut || board.feed(),
            |part, code| resets.push((part, code)),
            |_| {},
        );
        board.wait_for_interrupt();
    }
    // Let the UART finish (the timer stops with the run).
    board.next_tick_ns.set(u64::MAX);
    while probe.with(|s| !s.transmitter().is_idle() || !s.probe().nav_inbox().is_empty()) {
        probe.main_loop_pass(
            &mut delay,
            &mut navigator,
            &mut || board.feed(),
            |_, _| {},
            |_| {},
        );
        board.wait_for_interrupt();
    }

    let loop_failure = fault_code(&Error::LoopFailure);
    assert_eq!(resets, [(0, loop_failure), (1, loop_failure)]);
    let (queue_dropped, inbox_dropped, high_water, samples) = probe.with(|s| {
        let p = s.probe();
        (
            p.queue().dropped(),
            p.nav_inbox().dropped(),
            p.nav_inbox().high_water(),
            p.cycle().samples(),
        )
    });
    assert_eq!((queue_dropped, inbox_dropped), (0, 0));
    // The recovery did block the navigation for most of its budget, and
    // the inbox held it all.
    let recovery_samples = (RECOVERY_WORST_MS / 50) as usize;
    assert!(
        high_water > recovery_samples * 8 / 10 && high_water <= NAV_INBOX_LEN,
        "inbox high-water {high_water} of {NAV_INBOX_LEN}"
    );
    // The watchdog was fed at least every part's recovery, well within
    // the shortest the real board's IWDG may fire.
    let unfed_ms = board.longest_unfed_ns.get() / 1_000_000;
    assert!(
        unfed_ms <= u64::from(WATCHDOG_UNFED_WORST_MS) && unfed_ms >= 800,
        "{unfed_ms} ms"
    );
    assert!(unfed_ms < u64::from(WATCHDOG_SHORTEST_MS));

    // On the wire: no gap, every sample's raw frame and navigation frame,
    // and the navigation frames are what a fresh navigator makes of the
    // raw frames.
    let frames = sent_frames(&probe);
    assert_navigated_in_order(&frames, samples as usize);
    let events = events_of(&frames);
    assert!(events.iter().all(|e| e.kind != EventKind::SamplesDropped));
    assert!(events
        .iter()
        .any(|e| e.kind == EventKind::Resync && e.value as usize > recovery_samples * 8 / 10));
}

#[test]
fn samples_the_inbox_drops_are_reported_in_an_event() {
    use crate::app::NAV_INBOX_LEN;

    let clock = SimClock::new();
    let mocks = [0, 1].map(|i| RefCell::new(Scc1300::new(&clock, Constant::default(), i)));
    let parts = [0, 1].map(|i| Part::new(GyroSpi::new(&mocks[i]), AccelSpi::new(&mocks[i])));
    let mut delay = SimDelay::new(&clock);
    let probe = SharedProbe::new(TestUart::default());
    probe.start_streaming(parts, &mut delay, &mut || {});
    let mut navigator = Navigator::new(Position::paper_site());
    // The navigation stalls for 3, then 2 samples more than the inbox holds.
    for overflow in [3, 2] {
        for _ in 0..NAV_INBOX_LEN + overflow {
            clock.advance_ns(SAMPLE_PERIOD_NS);
            probe.with(|shared| shared.acquire());
            drain(&probe);
        }
        // The UART keeps up with the navigation here.
        probe.navigate_waiting(&mut navigator, &mut || {}, |_| drain(&probe));
        drain(&probe);
        assert!(probe.with(|s| s.probe().nav_inbox().is_empty()));
    }

    let frames = sent_frames(&probe);
    let drops: Vec<(u8, u32, u64)> = events_of(&frames)
        .iter()
        .filter(|e| e.kind == EventKind::SamplesDropped)
        .map(|e| (e.part, e.value, e.time_us))
        .collect();
    let period_us = SAMPLE_PERIOD_NS / 1_000;
    let first = (NAV_INBOX_LEN + 3) as u64;
    let second = first + (NAV_INBOX_LEN + 2) as u64;
    assert_eq!(
        drops,
        [
            (NO_PART, 3, first * period_us),
            (NO_PART, 2, second * period_us)
        ]
    );
    // The event comes before the first navigation frame it concerns.
    let first_nav = frames
        .iter()
        .position(|f| matches!(f.payload, Payload::Nav(_)));
    let first_drop = frames.iter().position(
        |f| matches!(f.payload, Payload::Event(e) if e.kind == EventKind::SamplesDropped),
    );
    assert!(first_drop < first_nav);
}
