//! What the measurement update did with each scalar: used, gated out,
//! or rejected as not finite or degenerate.

/// What happened to one scalar measurement.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ScalarOutcome<T> {
    /// Used: innovation `z - h x` and its variance `h P h^T + r`.
    Accepted { innovation: T, variance: T },
    /// The normalised innovation squared exceeded the gate; not used.
    Gated { innovation: T, variance: T },
    /// Measurement value, row or variance not finite; not used.
    NonFinite,
    /// Innovation variance not positive (or not finite after the product);
    /// not used.
    Degenerate,
}

impl<T> ScalarOutcome<T> {
    pub fn is_accepted(&self) -> bool {
        matches!(self, ScalarOutcome::Accepted { .. })
    }
}

/// Counts of the outcomes of a (vector) measurement's scalars.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct UpdateReport {
    pub accepted: u8,
    pub gated: u8,
    pub non_finite: u8,
    pub degenerate: u8,
}

impl UpdateReport {
    pub fn all_accepted(&self) -> bool {
        self.gated == 0 && self.non_finite == 0 && self.degenerate == 0
    }

    pub(crate) fn count<T>(&mut self, outcome: &ScalarOutcome<T>) {
        let slot = match outcome {
            ScalarOutcome::Accepted { .. } => &mut self.accepted,
            ScalarOutcome::Gated { .. } => &mut self.gated,
            ScalarOutcome::NonFinite => &mut self.non_finite,
            ScalarOutcome::Degenerate => &mut self.degenerate,
        };
        *slot = slot.saturating_add(1);
    }
}
