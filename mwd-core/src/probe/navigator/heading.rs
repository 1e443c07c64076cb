//! The heading's checks: once its sigma passes the first-order limit in
//! navigation the heading stays lost until the next tie-in or alignment
//! (a new source of the attitude), and a reference azimuth from outside
//! the probe is one update.

use super::state::{Navigator, Phase};
use crate::conventions::DEG;
use crate::kalman::{FilterScalar, UpdateReport};

/// The largest azimuth 1-sigma (rad) a station or frame reports as
/// determined: 10 deg, the first-order limit measured for the probe's tool
/// model (docs/probe-tool-model.md): beyond it the small-angle azimuth
/// sigma no longer covers the error, so the azimuth is flagged
/// undetermined and its sigma sent as infinite; in navigation it stays so
/// until the next tie-in (`Navigator::note_heading_loss`).
pub const AZIMUTH_SIGMA_LIMIT_RAD: f64 = 10.0 * DEG;

impl<T: FilterScalar> Navigator<T> {
    /// Once the navigating filter's azimuth sigma passes the first-order
    /// limit ([`AZIMUTH_SIGMA_LIMIT_RAD`]), the heading stays undetermined
    /// until the next tie-in, even when the sigma comes back under it.
    /// Past the limit the small-angle model no longer holds, and the rate
    /// gyrocompass's heading information, taken at an estimate that may
    /// be tens of degrees off (a cross-axis gyro sees the earth rate as
    /// the cosine of the heading), makes the sigma shrink by what the
    /// estimate believes, not by what the data tell. On the simulated
    /// 1000 m lateral (40 runs) the SCC1300's 666 station azimuths that
    /// came back under the limit were 87 % within 2 sigma, their error
    /// over sigma 1.67 RMS, one 92 deg off under a 9.3 deg sigma
    /// (docs/lateral-study.md, "A heading once lost stays lost"). A NaN
    /// sigma counts as past.
    /// A heading never found (an infinite sigma already) is not "lost".
    pub(super) fn note_heading_loss(&mut self, heading_std: f64) {
        let navigating = matches!(self.phase, Phase::Navigating);
        if navigating && self.loses_heading(heading_std) {
            self.coarse_std[2] = f32::INFINITY;
            self.heading_lost = true;
        }
    }

    /// Whether a heading sigma (rad, the filter's Euler heading) loses a
    /// heading that was found: past the limit, or NaN.
    pub(super) fn loses_heading(&self, heading_std: f64) -> bool {
        let within = heading_std <= AZIMUTH_SIGMA_LIMIT_RAD; // false for NaN
        self.coarse_std[2].is_finite() && !within
    }

    /// While the heading is undetermined (never found, or lost past the
    /// first-order limit), its error is kept apart from every other state
    /// after each navigating cycle (`FineAlignment::decouple_heading`).
    /// Such a heading is tens of degrees off (10-150 deg in simulated days
    /// of a still SCC1300), where the error model's first-order link from
    /// the heading to the tilt (the earth rate resolved through it, -omega_in x phi in eq. 11)
    /// no longer holds: the updates then moved heading and tilt together
    /// by what the estimate believed. In a station's first zero-velocity
    /// updates after 12 h of still free navigation the heading moved 57
    /// deg and the pitch 4 mrad, against a 0.86 mrad sigma. Kept apart,
    /// the still probe's pitch held its error within 2 sigma in 96-99.7 %
    /// of the epochs of its first ten hours (78-94 % before), its roll in
    /// 99.5-100 % (docs/filter-derivation.md section 5c; the day's rest
    /// came with the first-estimates linearisation past the longest
    /// station, `navigation_step`). Nothing reported is
    /// lost: an undetermined heading is not reported until the next tie-in
    /// or alignment, which gives the heading afresh.
    pub(super) fn keep_undetermined_heading_apart(&mut self) {
        if !self.coarse_std[2].is_finite() && !self.covariance_invalid {
            self.filter.decouple_heading();
        }
    }

    /// The roll, pitch and heading sigmas of a new source of the attitude
    /// (the coarse alignment, a tie-in): a heading lost before is
    /// forgotten.
    pub(super) fn set_heading_source(&mut self, sigma: [f64; 3]) {
        self.coarse_std = sigma.map(|s| s as f32);
        self.heading_lost = false;
    }

    /// One reference-azimuth update (rad, true north; 1-sigma `sigma` rad)
    /// at the current solution (`aid_sources::HeadingReference`: the probe
    /// as the backup of a reference heading, docs/redundant-rins.md); call
    /// it between steps. Only while navigating with a valid covariance;
    /// `None` then, or for a reference the source refuses. A heading lost
    /// past the first-order limit stays undetermined after it: unlike a
    /// tie-in, a reference does not restart the filter, whose gyro-bias
    /// estimates were learned at the lost heading (`note_heading_loss`).
    pub fn aid_heading(&mut self, azimuth: f64, sigma: f64) -> Option<UpdateReport> {
        if !self.is_navigating() || self.covariance_invalid {
            return None;
        }
        let reference =
            crate::aid_sources::HeadingReference::<T>::at(self.filter.state(), azimuth, sigma)
                .ok()?;
        Some(self.filter.aid(&reference))
    }
}
