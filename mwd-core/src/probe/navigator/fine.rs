//! The fine alignment's end: from the filter with zero updates to
//! navigation, at the fine alignment's full length or on the surface's
//! "start surveying" (`commands`).

use super::state::{Navigator, Phase};
use crate::kalman::FilterScalar;

impl<T: FilterScalar> Navigator<T> {
    /// From the fine alignment to navigation, at its full length or by
    /// [`start_surveying`](Self::start_surveying).
    pub(super) fn enter_navigation(&mut self) {
        self.filter.start_navigation();
        // The roll-derived tool-axis rate starts from the next sample on.
        self.input = crate::mechanization::ProbeInput::new();
        // The fine alignment held the roll as at rest: should the first
        // navigating cycle find the probe moving, its roll offset goes
        // into the variance as after any still period.
        self.was_still = true;
        self.phase = Phase::Navigating;
    }
}
