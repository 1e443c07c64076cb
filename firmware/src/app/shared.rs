//! The glue every board runs, once: the probe's state and the board's
//! [`Transmitter`] behind one critical section ([`SharedProbe`], kept in a
//! static), reached from the timer interrupt ([`Shared::acquire`]), the
//! UART's interrupt ([`Shared::transmitter_ready`]) and the main loop
//! ([`SharedProbe::main_loop_pass`]: navigation, sensor recovery once it
//! has caught up, navigation again; the watchdog fed between the steps).
//! A board adds its timer, its UART's registers and its watchdog.

use core::cell::RefCell;

use critical_section::Mutex;
use embedded_hal::delay::DelayNs;
use embedded_hal::spi::SpiDevice;
use mwd_core::probe::Navigator;
use mwd_core::protocol::frame::NO_PART;
use mwd_core::protocol::uplink::Reply;
use mwd_core::protocol::{EventKind, NavSolution, Payload};

use super::probe::{ProbeState, Sensors};
use super::start_up::start_parts;
use super::transmitter::Transmitter;
use crate::scc1300::Error;

/// Firmware version, sent in the boot event.
pub const FIRMWARE_VERSION: u16 = 1;

/// What the contexts share: the probe's state and its transmitter.
pub struct Shared<G, A, T> {
    probe: ProbeState<G, A>,
    transmitter: T,
}

impl<G, A, T: Transmitter> Shared<G, A, T> {
    pub fn probe(&self) -> &ProbeState<G, A> {
        &self.probe
    }

    pub fn transmitter(&self) -> &T {
        &self.transmitter
    }

    /// The board's own set-up of its transmitter (e.g. handing it the UART).
    pub fn transmitter_mut(&mut self) -> &mut T {
        &mut self.transmitter
    }

    /// Queues one frame and gets the transmitter going.
    pub fn push(&mut self, payload: &Payload) {
        self.probe.push(payload);
        self.transmitter.kick(self.probe.queue_mut());
    }

    /// Queues the reply to a host command and gets the transmitter going;
    /// false (and counted as dropped) when the queue had no room.
    pub fn push_reply(&mut self, reply: &Reply) -> bool {
        let queued = self.probe.queue_mut().push_reply(reply);
        self.transmitter.kick(self.probe.queue_mut());
        queued
    }

    /// The UART's interrupt: the transmitter can take the next byte.
    pub fn transmitter_ready(&mut self) {
        self.transmitter.ready(self.probe.queue_mut());
    }
}

impl<G: SpiDevice, A: SpiDevice, T: Transmitter> Shared<G, A, T> {
    /// The timer interrupt's work: one acquisition (see
    /// [`ProbeState::acquire`]), then the transmitter. Never waits.
    pub fn acquire(&mut self) {
        self.probe.acquire();
        self.transmitter.kick(self.probe.queue_mut());
    }
}

/// The probe's shared state behind the board's critical section.
pub struct SharedProbe<G, A, T> {
    shared: Mutex<RefCell<Shared<G, A, T>>>,
}

impl<G, A, T> SharedProbe<G, A, T> {
    /// Not streaming, nothing queued: for a `static`.
    pub const fn new(transmitter: T) -> Self {
        Self {
            shared: Mutex::new(RefCell::new(Shared {
                probe: ProbeState::new(),
                transmitter,
            })),
        }
    }
}

impl<G, A, T: Transmitter> SharedProbe<G, A, T> {
    /// Runs `f` on the shared state inside a critical section: keep it short.
    pub fn with<R>(&self, f: impl FnOnce(&mut Shared<G, A, T>) -> R) -> R {
        critical_section::with(|cs| f(&mut self.shared.borrow_ref_mut(cs)))
    }

    pub fn push(&self, payload: &Payload) {
        self.with(|shared| shared.push(payload));
    }

    /// Queues an event stamped with the time of the next sample.
    pub fn push_event(&self, kind: EventKind, part: u8, code: u16, value: u32) {
        self.with(|shared| {
            let event = shared.probe.event(kind, part, code, value);
            shared.push(&event);
        });
    }

    /// The boot event, the first frame of a run, reporting nothing of the
    /// reset or the configuration (value 0).
    pub fn announce_boot(&self) {
        self.push_event(EventKind::Boot, NO_PART, FIRMWARE_VERSION, 0);
    }

    /// The boot event with its value (`boot::boot_event_value`: the reset
    /// cause and the configuration's source and version).
    pub fn announce_boot_with(&self, value: u32) {
        self.push_event(EventKind::Boot, NO_PART, FIRMWARE_VERSION, value);
    }

    /// Navigates the waiting samples, oldest first, outside the critical
    /// section, as long as the transmit queue has room for their frames
    /// ([`ProbeState::next_sample_to_navigate`]; the rest wait for the
    /// UART), and queues each solution, and the station survey a step
    /// finished after it; `on_solution` sees each solution first. The
    /// watchdog is fed after each step (the slowest,
    /// `budget::SLOWEST_NAVIGATION_STEP_MS`, is within its budget).
    pub fn navigate_waiting(
        &self,
        navigator: &mut Navigator,
        feed_watchdog: &mut impl FnMut(),
        mut on_solution: impl FnMut(&NavSolution),
    ) {
        while let Some(sample) = self.with(|shared| {
            let sample = shared.probe.next_sample_to_navigate();
            // A SamplesDropped event may have been queued.
            shared.transmitter.kick(shared.probe.queue_mut());
            sample
        }) {
            let solution = navigator.step(&sample);
            feed_watchdog();
            on_solution(&solution);
            self.push(&Payload::Nav(solution));
            // A station survey the step finished goes right after its
            // navigation frame (docs/protocol.md, kind 4); the queue's room
            // for it was checked with the navigation frame's
            // (`budget::NAV_ROOM_BYTES`).
            if let Some(station) = navigator.take_station() {
                self.push(&Payload::Station(station));
            }
        }
    }
}

impl<G: SpiDevice, A: SpiDevice, T: Transmitter> SharedProbe<G, A, T> {
    /// Starts the parts (each failed attempt reported as an event; this
    /// waits, outside the critical section), then hands them to the
    /// acquisition. Returns the error of each part that never started: it
    /// streams anyway, flagged in every raw frame. The watchdog is fed
    /// after each attempt (`budget::PART_START_WORST_MS` apart at most).
    pub fn start_streaming(
        &self,
        mut sensors: Sensors<G, A>,
        delay: &mut impl DelayNs,
        feed_watchdog: &mut impl FnMut(),
    ) -> [Option<Error>; 2] {
        let outcome = start_parts(&mut sensors, delay, feed_watchdog, |payload| {
            self.push(payload)
        });
        self.with(|shared| shared.probe.start_streaming(sensors));
        outcome
    }

    /// Runs the recovery the acquisition asked for, if any, outside the
    /// critical section (it waits): one SensorReset event per part (also
    /// told to `on_reset`), then the parts go back with a Resync event.
    /// The watchdog is fed after each part's recovery, so the longest it
    /// goes unfed is one part's (`budget::PART_RECOVERY_WORST_MS`), not
    /// both parts'.
    pub fn recover_if_asked(
        &self,
        delay: &mut impl DelayNs,
        feed_watchdog: &mut impl FnMut(),
        mut on_reset: impl FnMut(u8, u16),
    ) {
        let Some(mut job) = self.with(|shared| shared.probe.take_recovery()) else {
            return;
        };
        job.run(delay, |part, code| {
            feed_watchdog();
            on_reset(part, code);
            self.push_event(EventKind::SensorReset, part, code, 0);
        });
        let resync = self.with(|shared| shared.probe.end_recovery(job));
        self.push(&resync);
    }

    /// The main loop's work each time it wakes: the navigation of the
    /// waiting samples; once it has caught up, the recovery the acquisition
    /// asked for, if any, and the navigation of the samples taken
    /// meanwhile. Recovering only when the inbox is empty bounds what it
    /// must hold to one recovery's samples (`budget::NAV_INBOX_NEEDED`),
    /// also when a part fails again and again.
    pub fn main_loop_pass(
        &self,
        delay: &mut impl DelayNs,
        navigator: &mut Navigator,
        feed_watchdog: &mut impl FnMut(),
        on_reset: impl FnMut(u8, u16),
        mut on_solution: impl FnMut(&NavSolution),
    ) {
        feed_watchdog();
        self.navigate_waiting(navigator, feed_watchdog, &mut on_solution);
        if self.with(|shared| shared.probe.nav_inbox().is_empty()) {
            self.recover_if_asked(delay, feed_watchdog, on_reset);
            self.navigate_waiting(navigator, feed_watchdog, &mut on_solution);
        }
    }
}

#[cfg(test)]
mod recovery_tests;
#[cfg(test)]
mod tests;
