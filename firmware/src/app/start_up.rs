//! Sensor start-up with retries: the two parts power up together, so the
//! first waits the 800 ms and the second only runs its steps; a part that
//! fails is tried again (from its soft start) a few times, each failure
//! reported as an event frame, before the probe streams anyway with that
//! part flagged in every raw frame.

use embedded_hal::delay::DelayNs;
use embedded_hal::spi::SpiDevice;
use mwd_core::protocol::Payload;

use super::sensor_wire::sensor_fault_event;
use crate::scc1300::{Error, Part};

/// Start-up attempts per part before giving up on it.
pub const START_ATTEMPTS: u32 = 3;

/// Starts both parts; returns the error of each part that never started.
/// Each failed attempt goes to `report` as an event frame (stamped 0: the
/// start-up runs before streaming). A callback, not the queue, because the
/// queue is shared with interrupts and must not stay locked while the
/// start-up waits.
///
/// `after_attempt` runs after each attempt (the board feeds its watchdog
/// there: an attempt is at most `budget::PART_START_WORST_MS`).
pub fn start_parts<G: SpiDevice, A: SpiDevice>(
    parts: &mut [Part<G, A>; 2],
    delay: &mut impl DelayNs,
    after_attempt: &mut impl FnMut(),
    mut report: impl FnMut(&Payload),
) -> [Option<Error>; 2] {
    let mut outcome = [None, None];
    for (index, (part, result)) in parts.iter_mut().zip(&mut outcome).enumerate() {
        for attempt in 1..=START_ATTEMPTS {
            // Only the first part's first attempt waits the power-up time.
            let started = if index == 0 && attempt == 1 {
                part.start(delay)
            } else {
                part.start_powered(delay)
            };
            after_attempt();
            match started {
                Ok(()) => {
                    *result = None;
                    break;
                }
                Err(error) => {
                    #[cfg(feature = "defmt")]
                    defmt::warn!(
                        "part {=usize} start-up attempt {=u32} failed",
                        index,
                        attempt
                    );
                    *result = Some(error);
                    report(&sensor_fault_event(0, index as u8, &error, attempt));
                }
            }
        }
    }
    outcome
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::app::FrameQueue;
    use core::cell::RefCell;
    use hil_mock::{
        AccelSpi, Constant, DeadLevel, GyroSpi, Scc1300, SimClock, SimDelay, SAMPLE_PERIOD_NS,
    };
    use mwd_core::protocol::Decoder;
    use std::vec::Vec;

    #[test]
    fn a_dead_part_is_retried_reported_and_the_other_starts() {
        let clock = SimClock::new();
        let mocks =
            [0, 1].map(|i| RefCell::new(Scc1300::new(&clock, Constant::default(), i as u32)));
        mocks[1].borrow_mut().faults.gyro.dead = Some(DeadLevel::Low);
        let mut parts =
            [0, 1].map(|i| Part::new(GyroSpi::new(&mocks[i]), AccelSpi::new(&mocks[i])));
        let mut queue = FrameQueue::<1024>::new();
        let mut attempts = 0;
        let outcome = start_parts(
            &mut parts,
            &mut SimDelay::new(&clock),
            &mut || attempts += 1,
            |p| {
                queue.push(p);
            },
        );
        assert_eq!(attempts, 1 + START_ATTEMPTS);
        assert_eq!(outcome[0], None);
        assert!(matches!(outcome[1], Some(Error::NoResponse(_))));

        let mut decoder = Decoder::new();
        let mut events = Vec::new();
        while let Some(b) = queue.pop() {
            decoder.feed(&[b], |f| events.push(f.payload));
        }
        assert_eq!(events.len(), START_ATTEMPTS as usize);
        for (attempt, payload) in (1..).zip(events) {
            let Payload::Event(e) = payload else {
                panic!("event frames only")
            };
            assert_eq!((e.part, e.value), (1, attempt));
        }
        // The good part samples cleanly after its start-up.
        clock.advance_ns(SAMPLE_PERIOD_NS);
        let reading = parts[0].sample();
        assert_eq!((reading.gyro_error, reading.accel_error), (None, None));
    }
}
