//! Raw samples on their way from the acquisition interrupt to the
//! navigation in the main loop. Bounded: when the navigation falls behind
//! (the once-only coarse alignment, a blocking sensor recovery) for longer
//! than the inbox holds, the oldest sample is dropped and counted, so the
//! navigation always resumes on the newest data and the loss is reported.

use heapless::Deque;
use mwd_core::protocol::RawSample;

/// The probe's inbox: 32 samples, 1.6 s at 20 Hz (the coarse alignment's
/// cycle takes ~0.18 s at 80 MHz, a sensor recovery about a second).
pub const NAV_INBOX_LEN: usize = 32;

/// A bounded queue of raw samples that drops its oldest when full.
pub struct SampleInbox<const N: usize> {
    samples: Deque<RawSample, N>,
    dropped: u32,
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
    }

    /// The oldest waiting sample.
    pub fn pop(&mut self) -> Option<RawSample> {
        self.samples.pop_front()
    }

    pub fn is_empty(&self) -> bool {
        self.samples.is_empty()
    }

    /// Samples dropped because the navigation fell behind.
    pub fn dropped(&self) -> u32 {
        self.dropped
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
        assert_eq!(inbox.dropped(), 2);
        let kept: [u32; 3] = core::array::from_fn(|_| inbox.pop().map_or(99, |s| s.sample_counter));
        assert_eq!(kept, [2, 3, 4]);
        assert!(inbox.is_empty() && inbox.pop().is_none());
    }
}
