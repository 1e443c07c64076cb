//! The fine alignment: the filter with zero updates on a still probe, and
//! its end, at its full length or on the surface's "start surveying"
//! (`commands`).

use super::state::{Navigator, Phase};
use crate::fine_alignment::StepNoise;
use crate::kalman::FilterScalar;
use crate::mechanization::ToolAxisSource;
use crate::probe_sample::ProbeSample;
use crate::protocol::frame::nav_flags;
use crate::timing::{FINE_ALIGNMENT_SAMPLES, SAMPLE_INTERVAL_S};

impl<T: FilterScalar> Navigator<T> {
    /// A fine-alignment sample: one step of the filter with its zero
    /// updates, the roll held as at rest; navigation after
    /// [`FINE_ALIGNMENT_SAMPLES`].
    pub(super) fn fine_sample(&mut self, sample: &ProbeSample, extra: &StepNoise) {
        let (imu, _) = self.input.imu_sample(
            &self.filter.frame_rate_in_body(),
            sample,
            ToolAxisSource::AtRest,
            SAMPLE_INTERVAL_S,
        );
        let report = self.filter.step_with(&imu, extra);
        self.held = Some(imu);
        if report.zero_velocity.accepted > 0 {
            self.flags |= nav_flags::ZUPT_APPLIED;
            self.coasting = false;
        }
        let Phase::Fine { samples } = &mut self.phase else {
            return;
        };
        *samples += 1;
        if *samples >= FINE_ALIGNMENT_SAMPLES {
            self.enter_navigation();
        }
    }

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
