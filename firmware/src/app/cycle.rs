//! One 20 Hz acquisition cycle, as the timer interrupt runs it: the two
//! parts' readings become a raw-sample frame, and every sensor fault in them
//! becomes an event frame, so the surface sees each fault and the stream
//! goes on.
//!
//! A part's temperature leaving or re-entering its operating range becomes
//! a Temperature event (the raw frames flag every sample outside it).
//!
//! The cycle never waits: a part that needs its (blocking) recovery is
//! reported to the caller, which hands it to the lower-priority main loop;
//! the samples taken while the parts are away still go out as raw frames
//! with no valid flags, so the sample counter and the 20 Hz rate stay
//! intact and the host sees exactly which samples were skipped.

use mwd_core::protocol::{Payload, RawSample};
use mwd_core::timing::sample_time_us;

use super::frame_queue::FrameQueue;
use super::sensor_wire::{
    part_temperature, raw_part, sensor_fault_event, temperature_event, TemperatureRange,
};
use crate::scc1300::PartReading;

/// What one cycle asks of its caller.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct CycleReport {
    /// Parts (by index) whose reading asks for the recovery sequence.
    pub recovery_needed: [bool; 2],
    /// Sensor faults seen in this cycle.
    pub faults: u32,
    /// The sample sent, for the main loop's navigation.
    pub sample: RawSample,
}

impl CycleReport {
    pub fn any_recovery(&self) -> bool {
        self.recovery_needed.iter().any(|&r| r)
    }
}

/// The acquisition side's bookkeeping across cycles.
#[derive(Debug, Clone, Default)]
pub struct AcquisitionCycle {
    samples: u32,
    skipped: u32,
    faults_per_part: [u32; 2],
    /// Each part's temperature as last measured (inside at boot).
    temperature: [TemperatureRange; 2],
}

impl AcquisitionCycle {
    pub const fn new() -> Self {
        Self {
            samples: 0,
            skipped: 0,
            faults_per_part: [0; 2],
            temperature: [TemperatureRange::Inside; 2],
        }
    }

    /// Runs one cycle: `readings` is `None` when the parts are away for
    /// recovery (the sample is skipped). Queues the raw frame and one event
    /// frame per faulty slave.
    pub fn run<const N: usize>(
        &mut self,
        readings: Option<[PartReading; 2]>,
        queue: &mut FrameQueue<N>,
    ) -> CycleReport {
        let n = self.samples;
        self.samples = self.samples.wrapping_add(1);
        // The timer, not the code's progress, fixes the sample's instant.
        let time_us = sample_time_us(n);
        let mut report = CycleReport {
            sample: RawSample {
                time_us,
                sample_counter: n,
                parts: Default::default(),
            },
            ..CycleReport::default()
        };
        let Some(readings) = readings else {
            self.skipped = self.skipped.saturating_add(1);
            queue.push(&Payload::Raw(report.sample));
            return report;
        };
        report.sample.parts = readings.map(|r| raw_part(&r));
        queue.push(&Payload::Raw(report.sample));
        for (index, reading) in readings.iter().enumerate() {
            for error in [reading.gyro_error, reading.accel_error]
                .into_iter()
                .flatten()
            {
                report.faults += 1;
                let count = self.count_fault(index);
                queue.push(&sensor_fault_event(time_us, index as u8, &error, count));
            }
            if let Some(flag) = report.recovery_needed.get_mut(index) {
                *flag = reading.needs_recovery();
            }
            if let (Some((range, count)), Some(last)) =
                (part_temperature(reading), self.temperature.get_mut(index))
            {
                if range != *last {
                    *last = range;
                    queue.push(&temperature_event(time_us, index as u8, range, count));
                }
            }
        }
        report
    }

    fn count_fault(&mut self, part: usize) -> u32 {
        match self.faults_per_part.get_mut(part) {
            Some(count) => {
                *count = count.saturating_add(1);
                *count
            }
            None => 0,
        }
    }

    /// Cycles run so far (the next sample's counter).
    pub fn samples(&self) -> u32 {
        self.samples
    }

    /// Cycles whose parts were away for recovery.
    pub fn skipped(&self) -> u32 {
        self.skipped
    }

    /// Each part's temperature as last measured.
    pub fn temperatures(&self) -> [TemperatureRange; 2] {
        self.temperature
    }

    /// Sensor faults of each part so far.
    pub fn faults_per_part(&self) -> [u32; 2] {
        self.faults_per_part
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::app::sensor_wire::fault_code;
    use crate::scc1300::{Error, Slave};
    use mwd_core::protocol::frame::raw_flags;
    use mwd_core::protocol::{Decoder, EventKind, Frame};
    use mwd_core::timing::SAMPLE_PERIOD_US;
    use std::vec::Vec;

    /// A reading with both slaves valid (no error, zero counts).
    fn good() -> PartReading {
        PartReading::default()
    }

    fn frames(queue: &mut FrameQueue<1024>) -> Vec<Frame> {
        let mut decoder = Decoder::new();
        let mut out = Vec::new();
        while let Some(b) = queue.pop() {
            decoder.feed(&[b], |f| out.push(f));
        }
        assert_eq!(decoder.stats().corrupt(), 0);
        out
    }

    #[test]
    fn faults_become_events_and_recovery_is_requested_not_run() {
        let mut cycle = AcquisitionCycle::new();
        let mut queue = FrameQueue::<1024>::new();
        let report = cycle.run(Some([good(), good()]), &mut queue);
        assert!(!report.any_recovery());
        assert_eq!(report.faults, 0);
        assert_eq!(
            report.sample.parts[1].flags,
            raw_flags::GYRO_VALID | raw_flags::ACCEL_VALID
        );

        let mut faulty = good();
        faulty.gyro_error = Some(Error::NotReady);
        faulty.accel_error = Some(Error::Saturated(Slave::Accel));
        let report = cycle.run(Some([good(), faulty]), &mut queue);
        assert_eq!(report.recovery_needed, [false, true]);
        assert_eq!(report.faults, 2);

        let report = cycle.run(None, &mut queue);
        assert!(!report.any_recovery());
        assert_eq!((cycle.samples(), cycle.skipped()), (3, 1));
        assert_eq!(cycle.faults_per_part(), [0, 2]);

        let got = frames(&mut queue);
        let kinds: Vec<_> = got.iter().map(|f| f.payload.kind() as u8).collect();
        let (raw, event) = (
            mwd_core::protocol::FrameKind::RawSample as u8,
            mwd_core::protocol::FrameKind::Event as u8,
        );
        assert_eq!(kinds, [raw, raw, event, event, raw]);
        let Payload::Event(e) = got[3].payload else {
            panic!("event expected")
        };
        assert_eq!((e.kind, e.part), (EventKind::SensorFault, 1));
        assert_eq!(
            (e.code, e.value),
            (fault_code(&Error::Saturated(Slave::Accel)), 2)
        );
        assert_eq!(e.time_us, SAMPLE_PERIOD_US);
        let Payload::Raw(skipped) = got[4].payload else {
            panic!("raw expected")
        };
        assert_eq!(skipped.sample_counter, 2);
        assert_eq!(skipped.time_us, 2 * SAMPLE_PERIOD_US);
        assert!(skipped.parts.iter().all(|p| p.flags == 0));
    }
}
