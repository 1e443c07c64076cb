//! The probe's state, the same on every board: the two parts (while the
//! acquisition has them), the cycle's bookkeeping, the transmit queue and
//! the navigation inbox. A board keeps it inside a
//! [`SharedProbe`](super::SharedProbe) behind a critical section, calls
//! [`ProbeState::acquire`] from its 20 Hz timer interrupt and runs a
//! [`RecoveryJob`] from its main loop; it adds only its timer, UART and
//! watchdog.

use embedded_hal::delay::DelayNs;
use embedded_hal::spi::SpiDevice;
use mwd_core::protocol::frame::NO_PART;
use mwd_core::protocol::{Event, EventKind, Payload, RawSample};
use mwd_core::timing::sample_time_us;

use super::budget::NAV_ROOM_BYTES;
use super::cycle::AcquisitionCycle;
use super::frame_queue::{FrameQueue, TX_QUEUE_LEN};
use super::sample_inbox::{SampleInbox, NAV_INBOX_LEN};
use super::sensor_wire::reset_event_code;
use crate::scc1300::{Part, PartReading};

/// The probe's two parts.
pub type Sensors<G, A> = [Part<G, A>; 2];

/// Parts taken from the acquisition for their blocking recovery, with the
/// readings that asked for it.
pub struct RecoveryJob<G, A> {
    sensors: Sensors<G, A>,
    readings: [PartReading; 2],
    /// Samples skipped before the recovery began (for the Resync event).
    skipped_before: u32,
}

impl<G: SpiDevice, A: SpiDevice> RecoveryJob<G, A> {
    /// Runs the recovery of each part that asked for it (this waits: call
    /// it outside any critical section); `report` gets one SensorReset event
    /// per part, stamped by the caller.
    pub fn run(&mut self, delay: &mut impl DelayNs, mut report: impl FnMut(u8, u16)) {
        for (index, (part, reading)) in self.sensors.iter_mut().zip(&self.readings).enumerate() {
            if reading.needs_recovery() {
                report(index as u8, reset_event_code(&part.recover(delay, reading)));
            }
        }
    }
}

/// The shared state of one probe.
pub struct ProbeState<G, A> {
    /// False until the parts are started: the timer then does nothing.
    streaming: bool,
    /// The parts, while they are the acquisition's (None during recovery).
    sensors: Option<Sensors<G, A>>,
    /// Parts waiting for the main loop to recover them.
    recovery: Option<RecoveryJob<G, A>>,
    cycle: AcquisitionCycle,
    queue: FrameQueue<TX_QUEUE_LEN>,
    /// Samples from the acquisition to the navigation.
    nav_inbox: SampleInbox<NAV_INBOX_LEN>,
}

impl<G, A> ProbeState<G, A> {
    pub const fn new() -> Self {
        Self {
            streaming: false,
            sensors: None,
            recovery: None,
            cycle: AcquisitionCycle::new(),
            queue: FrameQueue::new(),
            nav_inbox: SampleInbox::new(),
        }
    }

    /// True once the parts are started and the timer samples them.
    pub fn is_streaming(&self) -> bool {
        self.streaming
    }

    /// True while the acquisition has the parts (false during a recovery).
    pub fn has_parts(&self) -> bool {
        self.sensors.is_some()
    }

    /// The acquisition's counters (samples, skipped, faults).
    pub fn cycle(&self) -> &AcquisitionCycle {
        &self.cycle
    }

    /// The transmit queue, for its counters (queued, dropped, waiting).
    pub fn queue(&self) -> &FrameQueue<TX_QUEUE_LEN> {
        &self.queue
    }

    /// The transmit queue, for the board's transmitter to drain.
    pub(super) fn queue_mut(&mut self) -> &mut FrameQueue<TX_QUEUE_LEN> {
        &mut self.queue
    }

    /// The navigation inbox, for its counters.
    pub fn nav_inbox(&self) -> &SampleInbox<NAV_INBOX_LEN> {
        &self.nav_inbox
    }

    /// Numbers, encodes and queues one frame for the UART; false (and
    /// counted) when the queue had no room.
    pub fn push(&mut self, payload: &Payload) -> bool {
        self.queue.push(payload)
    }

    /// The next byte for the UART.
    pub fn next_byte(&mut self) -> Option<u8> {
        self.queue.pop()
    }

    /// The oldest sample waiting for the navigation.
    pub fn next_sample(&mut self) -> Option<RawSample> {
        self.nav_inbox.pop()
    }

    /// The oldest sample waiting for the navigation, if the transmit queue
    /// has room for its navigation frame and for what the acquisition may
    /// queue meanwhile ([`NAV_ROOM_BYTES`]); otherwise the sample waits in
    /// the inbox until the UART has drained the queue, so the catch-up after
    /// a long recovery never drops a navigation frame. Samples the inbox
    /// dropped since the last call are reported first, in a SamplesDropped
    /// event (value: how many).
    pub fn next_sample_to_navigate(&mut self) -> Option<RawSample> {
        if TX_QUEUE_LEN - self.queue.len() < NAV_ROOM_BYTES || self.nav_inbox.is_empty() {
            return None;
        }
        let dropped = self.nav_inbox.take_unreported_drops();
        if dropped > 0 {
            let event = self.event(EventKind::SamplesDropped, NO_PART, 0, dropped);
            self.queue.push(&event);
        }
        self.nav_inbox.pop()
    }

    /// An event frame stamped with the time of the next sample.
    pub fn event(&self, kind: EventKind, part: u8, code: u16, value: u32) -> Payload {
        Payload::Event(Event {
            time_us: sample_time_us(self.cycle.samples()),
            kind,
            part,
            code,
            value,
        })
    }

    /// The started parts go to the acquisition; the timer starts sampling.
    pub fn start_streaming(&mut self, sensors: Sensors<G, A>) {
        self.sensors = Some(sensors);
        self.streaming = true;
    }

    /// The parts that asked for recovery, for the main loop.
    pub fn take_recovery(&mut self) -> Option<RecoveryJob<G, A>> {
        self.recovery.take()
    }

    /// The recovered parts go back to the acquisition; returns the Resync
    /// event, which says how many samples the recovery cost.
    pub fn end_recovery(&mut self, job: RecoveryJob<G, A>) -> Payload {
        self.sensors = Some(job.sensors);
        let skipped = self.cycle.skipped().saturating_sub(job.skipped_before);
        self.event(EventKind::Resync, NO_PART, 0, skipped)
    }
}

impl<G: SpiDevice, A: SpiDevice> ProbeState<G, A> {
    /// The timer interrupt's work for one period: sample both parts (or
    /// note the sample skipped while they are away), queue the raw frame
    /// and any fault events, hand the sample to the navigation, and take
    /// the parts away for recovery if a reading asks for it. Never waits.
    pub fn acquire(&mut self) {
        if !self.streaming {
            return;
        }
        let readings = self
            .sensors
            .as_mut()
            .map(|parts| parts.each_mut().map(|part| part.sample()));
        let report = self.cycle.run(readings, &mut self.queue);
        self.nav_inbox.push(report.sample);
        if report.any_recovery() {
            if let (Some(readings), Some(sensors)) = (readings, self.sensors.take()) {
                self.recovery = Some(RecoveryJob {
                    sensors,
                    readings,
                    skipped_before: self.cycle.skipped(),
                });
            }
        }
    }
}

impl<G, A> Default for ProbeState<G, A> {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::app::start_parts;
    use core::cell::RefCell;
    use hil_mock::{
        AccelSpi, Constant, GyroSpi, Scc1300, SimClock, SimDelay, TimeSource, Window,
        SAMPLE_PERIOD_NS,
    };
    use mwd_core::protocol::Decoder;
    use std::vec::Vec;

    type MockPart<'a> = Scc1300<&'a SimClock, Constant>;
    type MockGyro<'a> = GyroSpi<'a, &'a SimClock, Constant>;
    type MockAccel<'a> = AccelSpi<'a, &'a SimClock, Constant>;

    /// Two simulated parts on `clock` reading constant values.
    fn constant_parts(clock: &SimClock) -> [RefCell<MockPart<'_>>; 2] {
        [0, 1].map(|i| RefCell::new(Scc1300::new(clock, Constant::default(), i as u32)))
    }

    /// A new probe that has started the parts on `mocks` (their start-up
    /// frames queued) and the parts, not yet streaming.
    fn started_parts<'a>(
        clock: &SimClock,
        mocks: &'a [RefCell<MockPart<'a>>; 2],
    ) -> (
        ProbeState<MockGyro<'a>, MockAccel<'a>>,
        Sensors<MockGyro<'a>, MockAccel<'a>>,
    ) {
        let mut parts =
            [0, 1].map(|i| Part::new(GyroSpi::new(&mocks[i]), AccelSpi::new(&mocks[i])));
        let mut probe = ProbeState::new();
        start_parts(&mut parts, &mut SimDelay::new(clock), &mut || {}, |p| {
            probe.push(p);
        });
        (probe, parts)
    }

    /// The payloads of the frames waiting for the UART, taken off its queue.
    fn queued_payloads<G, A>(probe: &mut ProbeState<G, A>) -> Vec<Payload> {
        let mut decoder = Decoder::new();
        let mut payloads = Vec::new();
        while let Some(b) = probe.next_byte() {
            decoder.feed(&[b], |f| payloads.push(f.payload));
        }
        payloads
    }

    #[test]
    fn a_recovery_takes_the_parts_away_and_gives_them_back_with_a_resync() {
        let clock = SimClock::new();
        let mocks = constant_parts(&clock);
        let (mut probe, parts) = started_parts(&clock, &mocks);
        probe.acquire();
        assert!(probe.nav_inbox().is_empty(), "not streaming yet");
        probe.start_streaming(parts);
        for _ in 0..10 {
            clock.advance_ns(SAMPLE_PERIOD_NS);
            probe.acquire();
        }
        assert!(probe.take_recovery().is_none());

        // Part 1's gyro loses S_OK for 100 ms: the acquisition hands the
        // parts over, samples on without them, and gets them back.
        let now = clock.now_ns();
        mocks[1].borrow_mut().faults.s_ok_drop = Some(Window {
            start_ns: now,
            end_ns: now + 100_000_000,
        });
        clock.advance_ns(SAMPLE_PERIOD_NS);
        probe.acquire();
        let Some(mut job) = probe.take_recovery() else {
            panic!("part 1 asks for recovery")
        };
        assert!(!probe.has_parts());
        clock.advance_ns(SAMPLE_PERIOD_NS);
        probe.acquire(); // a sample while the parts are away
        let mut resets = Vec::new();
        job.run(&mut SimDelay::new(&clock), |part, code| {
            resets.push((part, code))
        });
        assert_eq!(resets, [(1, 0)], "a transient: the part came back");
        let resync = probe.end_recovery(job);
        assert!(matches!(resync, Payload::Event(e) if e.kind == EventKind::Resync && e.value == 1));
        clock.advance_ns(SAMPLE_PERIOD_NS);
        probe.acquire();
        assert!(probe.has_parts() && probe.take_recovery().is_none());

        // 13 raw samples reached the navigation and the UART, in order.
        let mut counters = Vec::new();
        while let Some(sample) = probe.next_sample() {
            counters.push(sample.sample_counter);
        }
        assert_eq!(counters, (0..13).collect::<Vec<u32>>());
        let payloads = queued_payloads(&mut probe);
        let raw = payloads
            .iter()
            .filter(|p| matches!(p, Payload::Raw(_)))
            .count();
        assert_eq!(raw, 13);
    }

    #[test]
    fn a_part_outside_its_temperature_range_is_flagged_and_evented() {
        use hil_mock::TemperatureExcursion;
        use mwd_core::protocol::frame::raw_flags::TEMPERATURE_OUT_OF_RANGE;
        use mwd_core::sensor_units::COUNT_MAX;

        let clock = SimClock::new();
        let mocks = constant_parts(&clock);
        let (mut probe, parts) = started_parts(&clock, &mocks);
        probe.start_streaming(parts);
        // Part 1 at 200 degC for samples 2..5 (the count clips at 8191),
        // back at 0 degC, then at -60 degC for samples 8..10.
        let excursion = |from: u64, to: u64, degc: i16| {
            let t0 = clock.now_ns();
            Some(TemperatureExcursion {
                window: Window {
                    start_ns: t0 + from * SAMPLE_PERIOD_NS - SAMPLE_PERIOD_NS / 2,
                    end_ns: t0 + to * SAMPLE_PERIOD_NS - SAMPLE_PERIOD_NS / 2,
                },
                degc,
            })
        };
        let mut out_of_range = Vec::new();
        for n in 1..=12u64 {
            if n == 1 {
                mocks[1].borrow_mut().faults.temperature = excursion(2, 5, 200);
            }
            if n == 6 {
                mocks[1].borrow_mut().faults.temperature = excursion(2, 4, -60);
            }
            clock.advance_ns(SAMPLE_PERIOD_NS);
            probe.acquire();
            let sample = probe.next_sample().expect("a sample per period");
            out_of_range.push(
                sample
                    .parts
                    .map(|p| p.flags & TEMPERATURE_OUT_OF_RANGE != 0),
            );
        }
        let flagged: Vec<usize> = (0..12).filter(|&i| out_of_range[i][1]).collect();
        assert_eq!(flagged, [1, 2, 3, 6, 7]);
        assert!(out_of_range.iter().all(|p| !p[0]));

        let events: Vec<_> = queued_payloads(&mut probe)
            .into_iter()
            .filter_map(|p| match p {
                Payload::Event(e) if e.kind == EventKind::Temperature => {
                    Some((e.part, e.code, e.value as i32, e.time_us))
                }
                _ => None,
            })
            .collect();
        let zero_degc = -3250;
        let minus_60_degc = -60 * 65 - 3250;
        let at = |n: u64| n * mwd_core::timing::SAMPLE_PERIOD_US;
        assert_eq!(
            events,
            [
                (1, 1, i32::from(COUNT_MAX), at(1)),
                (1, 2, zero_degc, at(4)),
                (1, 0, minus_60_degc, at(6)),
                (1, 2, zero_degc, at(8)),
            ]
        );
    }
}
