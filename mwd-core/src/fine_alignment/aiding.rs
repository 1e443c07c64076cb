//! Aiding measurements between steps, at the current solution (the
//! drilling constraints, a station's rate gyrocompass, a reference
//! heading), fed back as a step's updates are.

use super::filter::FineAlignment;
use crate::kalman::{FilterScalar, Measurement, UpdateReport};

impl<T: FilterScalar, const N: usize> FineAlignment<T, N> {
    /// One aiding measurement between steps, at the current solution
    /// (e.g. the non-holonomic constraint while drilling, built with
    /// [`state`](Self::state)), fed back as a step's updates are. Never
    /// inlined: one copy per measurement type.
    #[inline(never)]
    pub fn aid<M: Measurement<T>>(&mut self, measurement: &M) -> UpdateReport {
        let report = self.filter.update(measurement);
        if report.accepted > 0 {
            self.feed_back();
        }
        report
    }

    /// [`aid`](Self::aid) for a measurement whose noise is the mean of
    /// sensor samples that also propagated the state: scalar `k`'s noise
    /// is `1 / samples` times the sum that column `k` of snapshot `slot`
    /// holds the state's covariance with (kept by its owner as the samples
    /// come, `kalman::CrossCovariances::start_zero`); each scalar reads its
    /// column after the ones before it updated it. An empty slot is the
    /// plain update.
    #[inline(never)]
    pub fn aid_correlated<M: Measurement<T>>(
        &mut self,
        measurement: &M,
        slot: usize,
        samples: u32,
    ) -> UpdateReport {
        let mut report = UpdateReport::default();
        let scale = T::one() / T::of(f64::from(samples.max(1)));
        for k in 0..measurement.len() {
            let outcome = match measurement.scalar(k) {
                Some(m) => match self.filter.cross.column(slot, k) {
                    Some(sum) => {
                        let s = sum.map(|v| v * scale);
                        self.filter.update_scalar_correlated(&m, &s)
                    }
                    None => self.filter.update_scalar(&m),
                },
                None => crate::kalman::ScalarOutcome::NonFinite,
            };
            report.count(&outcome);
        }
        if report.accepted > 0 {
            self.feed_back();
        }
        report
    }

    /// The largest normalised innovation squared among `measurement`'s
    /// scalars at the current solution, each against the covariance of
    /// now (none of them used): `None` when one is not a finite number.
    pub fn largest_normalized_innovation<M: Measurement<T>>(&self, measurement: &M) -> Option<T> {
        let mut largest = T::zero();
        for k in 0..measurement.len() {
            let nis = self
                .filter
                .normalized_innovation_squared(&measurement.scalar(k)?)?;
            if nis > largest {
                largest = nis;
            }
        }
        Some(largest)
    }
}
