//! Raw samples on their way from the acquisition interrupt to the
//! navigation in the main loop. Bounded: when the navigation falls behind
//! (the once-only coarse alignment, a blocking sensor recovery) for longer
//! than the inbox holds, the oldest sample is dropped and counted, so the
//! navigation always resumes on the newest data, and the main loop reports
//! the loss in a SamplesDropped event (`ProbeState::drop_report`).

use heapless::Deque;
use mwd_core::protocol::RawSample;

use super::budget::NAV_INBOX_NEEDED;

/// The probe's inbox: the samples of the worst blocking recovery plus the
/// slowest navigation step after it (`budget::NAV_INBOX_NEEDED`, 47
/// samples, 2.35 s at 20 Hz), so that by design it never drops.
pub const NAV_INBOX_LEN: usize = NAV_INBOX_NEEDED;

/// A bounded queue of raw samples that drops its oldest when full.
pub struct SampleInbox<const N: usize> {
    samples: Deque<RawSample, N>,
    dropped: u32,
    /// `dropped` when it was last reported.
    reported: u32,
    /// The most samples ever waiting at once.
    high_water: usize,
}

impl<const N: usize> Default for SampleInbox<N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const N: usize> SampleInbox<N> {
    pub const fn new() -> Self {
        Self {
            samples: Deque::new(),
            dropped: 0,
            reported: 0,
            high_water: 0,
        }
    }

    /// Queues `sample`; when full, the oldest waiting sample makes room.
    pub fn push(&mut self, sample: RawSample) {
        if self.samples.is_full() {
            self.samples.pop_front();
            self.dropped = self.dropped.saturating_add(1);
        }
        // Cannot fail: there is room now (N = 0 aside, which keeps nothing).
        let _ = self.samples.push_back(sample);
        self.high_water = self.high_water.max(self.samples.len());
    }

    /// The oldest waiting sample.
    pub fn pop(&mut self) -> Option<RawSample> {
        self.samples.pop_front()
    }

    pub fn is_empty(&self) -> bool {
        self.samples.is_empty()
    }

    /// The most samples that ever waited at once.
    pub fn high_water(&self) -> usize {
        self.high_water
    }

    /// Samples dropped because the navigation fell behind.
    pub fn dropped(&self) -> u32 {
        self.dropped
    }

    /// Samples dropped since the last call (none: 0): what the next
    /// SamplesDropped event reports.
    pub fn take_unreported_drops(&mut self) -> u32 {
        let new = self.dropped.wrapping_sub(self.reported);
        self.reported = self.dropped;
        new
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(n: u32) -> RawSample {
        RawSample {
            sample_counter: n,
            ..RawSample::default()
        }
    }

    #[test]
    fn keeps_the_newest_and_counts_what_it_drops() {
        let mut inbox = SampleInbox::<3>::new();
        for n in 0..5 {
            inbox.push(sample(n));
        }
        assert_eq!((inbox.dropped(), inbox.high_water()), (2, 3));
        let kept: [u32; 3] = core::array::from_fn(|_| inbox.pop().map_or(99, |s| s.sample_counter));
        assert_eq!(kept, [2, 3, 4]);
        assert!(inbox.is_empty() && inbox.pop().is_none());
        assert_eq!(inbox.take_unreported_drops(), 2);
        assert_eq!(inbox.take_unreported_drops(), 0);
        for n in 0..4 {
            inbox.push(sample(n));
        }
        assert_eq!((inbox.dropped(), inbox.take_unreported_drops()), (3, 1));
    }
}
