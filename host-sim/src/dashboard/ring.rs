//! Bounded series for the dashboard: a ring buffer whose items carry the
//! number of the update that added them (so a page that reconnects gets
//! exactly what it missed), and a decimator that turns a 20 Hz series into
//! one point per bucket for the long window.

use std::collections::VecDeque;

/// A ring of at most `capacity` items, each stamped with an increasing
/// update number.
#[derive(Debug, Clone)]
pub struct Ring<T> {
    items: VecDeque<(u64, T)>,
    capacity: usize,
    /// The update number of the newest item dropped (0: none).
    dropped_through: u64,
}

impl<T> Ring<T> {
    pub fn new(capacity: usize) -> Self {
        Self {
            items: VecDeque::with_capacity(capacity),
            capacity: capacity.max(1),
            dropped_through: 0,
        }
    }

    pub fn push(&mut self, update: u64, item: T) {
        if self.items.len() == self.capacity {
            if let Some((dropped, _)) = self.items.pop_front() {
                self.dropped_through = dropped;
            }
        }
        self.items.push_back((update, item));
    }

    pub fn len(&self) -> usize {
        self.items.len()
    }

    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    pub fn capacity(&self) -> usize {
        self.capacity
    }

    /// Whether a reader that has seen every update up to `cursor` can be
    /// brought up to date from this ring (nothing it lacks was dropped).
    pub fn covers(&self, cursor: u64) -> bool {
        self.dropped_through <= cursor
    }

    /// The items added after update `cursor`, oldest first.
    pub fn since(&self, cursor: u64) -> impl Iterator<Item = &T> {
        // Items are in update order: skip the old ones from the back.
        let newer = self
            .items
            .iter()
            .rev()
            .take_while(|(u, _)| *u > cursor)
            .count();
        self.items
            .iter()
            .skip(self.items.len() - newer)
            .map(|(_, item)| item)
    }

    pub fn last(&self) -> Option<&T> {
        self.items.back().map(|(_, item)| item)
    }
}

/// Averages fixed-size buckets of a series of `N` channels: the long
/// window's points. A channel's NaN values are left out of its mean; a
/// channel with no number in a bucket averages to NaN (shown as a gap).
#[derive(Debug, Clone)]
pub struct BucketMean<const N: usize> {
    per_bucket: usize,
    sums: [f64; N],
    counts: [u32; N],
    seen: usize,
    first_time_s: f64,
}

impl<const N: usize> BucketMean<N> {
    pub fn new(per_bucket: usize) -> Self {
        Self {
            per_bucket: per_bucket.max(1),
            sums: [0.0; N],
            counts: [0; N],
            seen: 0,
            first_time_s: f64::NAN,
        }
    }

    /// Adds one point at `time_s`; returns the finished bucket (its first
    /// time and the channels' means) when this point completes one.
    pub fn push(&mut self, time_s: f64, values: &[f32; N]) -> Option<(f64, [f32; N])> {
        if self.seen == 0 {
            self.first_time_s = time_s;
        }
        for ((sum, count), v) in self.sums.iter_mut().zip(&mut self.counts).zip(values) {
            if v.is_finite() {
                *sum += f64::from(*v);
                *count += 1;
            }
        }
        self.seen += 1;
        if self.seen < self.per_bucket {
            return None;
        }
        let means = std::array::from_fn(|i| {
            if self.counts[i] == 0 {
                f32::NAN
            } else {
                (self.sums[i] / f64::from(self.counts[i])) as f32
            }
        });
        let first = self.first_time_s;
        *self = Self::new(self.per_bucket);
        Some((first, means))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_ring_keeps_the_newest_and_knows_what_it_dropped() {
        let mut ring = Ring::new(3);
        for u in 1..=5 {
            ring.push(u, u * 10);
        }
        assert_eq!(ring.len(), 3);
        assert_eq!(ring.since(0).copied().collect::<Vec<_>>(), [30, 40, 50]);
        assert_eq!(ring.since(4).copied().collect::<Vec<_>>(), [50]);
        assert_eq!(ring.since(5).count(), 0);
        assert!(!ring.covers(1), "update 2 was dropped");
        assert!(ring.covers(2));
    }

    #[test]
    fn buckets_average_their_numbers_and_skip_nans() {
        let mut mean = BucketMean::<2>::new(3);
        assert!(mean.push(0.0, &[1.0, f32::NAN]).is_none());
        assert!(mean.push(0.05, &[2.0, f32::NAN]).is_none());
        let (t, m) = mean.push(0.1, &[6.0, f32::NAN]).expect("a full bucket");
        assert_eq!(t, 0.0);
        assert_eq!(m[0], 3.0);
        assert!(m[1].is_nan());
        assert!(mean.push(0.15, &[1.0, 1.0]).is_none());
    }
}
