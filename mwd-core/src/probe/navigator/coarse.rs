//! The static (coarse) alignment: the still samples summed, and at its
//! end their means levelled and gyrocompassed (`crate::alignment`), and
//! the filter started from them for the fine alignment.

use super::state::{filter_config, Navigator, Phase};
use crate::alignment::{
    gyrocompass, level_segment, AlignmentConfig, HeadingEstimate, StaticSegment,
};
use crate::conventions::{quat_from_euler, Euler};
use crate::kalman::FilterScalar;
use crate::mechanization::NavState;
use crate::probe_sample::ProbeSample;
use crate::timing::ALIGNMENT_SAMPLES;

impl<T: FilterScalar> Navigator<T> {
    /// A coarse-alignment sample (of one part when `single_part`): added
    /// to the sums, the alignment finished at [`ALIGNMENT_SAMPLES`].
    pub(super) fn coarse_sample(&mut self, sample: &ProbeSample, single_part: bool) {
        let Phase::Coarse(sums) = &mut self.phase else {
            return;
        };
        self.coarse_single_part |= single_part;
        sums.add(sample);
        if sums.samples() >= ALIGNMENT_SAMPLES as usize {
            let segment = sums.segment();
            // A single part in the coarse alignment: its gyro alone cannot
            // gyrocompass.
            self.finish_coarse_alignment(&segment, !self.coarse_single_part);
        }
    }

    fn finish_coarse_alignment(&mut self, segment: &StaticSegment, gyrocompass_possible: bool) {
        let mut config = AlignmentConfig::probe(self.position.lat);
        config.noise = *self.noise;
        let (roll, pitch, roll_pitch_std) = match level_segment(segment, &config) {
            Ok(l) => (l.roll.value, l.pitch.value, [l.roll.sigma, l.pitch.sigma]),
            Err(_) => (0.0, 0.0, [f64::NAN; 2]),
        };
        // Without a usable heading the solution runs on with heading 0 and
        // says so through its (infinite) standard deviation; the filter
        // starts it with its largest prior (30 deg, see `physical`).
        // One part's gyro alone cannot gyrocompass: not even tried.
        let estimate =
            gyrocompass_possible.then(|| gyrocompass(core::slice::from_ref(segment), &config));
        // A heading whose mirror candidate explains the data as well is
        // undetermined however small its sigma unless a prior chose it
        // (`ambiguous` stays set when one did); the probe has none
        // (`AlignmentConfig::probe`), so the lower misfit is a coin toss.
        // A horizontal tool's cross-axis gyros see only the sine of its
        // heading, and a quiet grade's 1 deg sigma once went out on the
        // mirror 60 deg away; the tie-in brings the heading.
        let unchosen = |h: &HeadingEstimate| h.ambiguous && config.heading_prior.is_none();
        let (heading, heading_std) = match estimate {
            Some(Ok(h)) if h.determined && !unchosen(&h) => (h.heading.value, h.heading.sigma),
            Some(Ok(h)) => (h.heading.value, f64::INFINITY),
            Some(Err(_)) | None => (0.0, f64::INFINITY),
        };
        let sigma = [roll_pitch_std[0], roll_pitch_std[1], heading_std];
        self.set_heading_source(sigma);
        // A levelling that failed leaves no tilt sigma: the filter then
        // starts from a 10 deg one.
        let filter_sigma = sigma.map(|s| if s.is_nan() { 10f64.to_radians() } else { s });
        let attitude = quat_from_euler(&Euler::new(roll, pitch, heading));
        self.filter.restart(
            NavState::at_rest(attitude, self.position),
            self.position,
            filter_config(&self.position, &filter_sigma, self.noise),
        );
        self.covariance_invalid = false;
        self.coasting = false;
        self.was_still = false;
        self.forget_drilling();
        self.phase = Phase::Fine { samples: 0 };
    }
}
