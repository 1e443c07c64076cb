//! A start from a tie-in (`crate::probe::tie_in`, derivation section 4c)
//! instead of, or after, the static alignment: [`Navigator::start_from_tie_in`].

use super::state::{filter_config, square, Navigator, Phase};
use crate::conventions::{dcm_from_quat, quat_from_euler, DrillingAngles};
use crate::fine_alignment::TiltPrior;
use crate::kalman::FilterScalar;
use crate::mechanization::{NavState, ProbeInput};
use crate::probe::station::angles_and_jacobian;
use crate::probe::tie_in::{TieIn, TieInTilt};

impl<T: FilterScalar> Navigator<T> {
    pub(super) fn tie_in(&mut self, tie_in: &TieIn) {
        if !matches!(self.phase, Phase::Navigating) || self.covariance_invalid {
            self.restart_from_tie_in(tie_in);
            return;
        }
        // The filter starts again at the probe's own levelled tilt and the
        // tie-in's azimuth: what it learned in the fine alignment rested on
        // a heading that may have been tens of degrees off (its gyro-bias
        // estimates absorbed the misplaced earth rate: kept, the window's
        // azimuths came out 11 deg RMS instead of 6). The tilt starts as a
        // levelling with these accelerometers (`TiltPrior` default: its
        // error holds their biases) from the coarse levelling's noise; the
        // heading error is the tie-in's alone.
        let (own, _) = angles_and_jacobian(&dcm_from_quat(&self.filter.state().attitude));
        let given = tie_in.angles();
        let sigma = tie_in.sigma();
        let start = DrillingAngles {
            azimuth: given.azimuth,
            ..own
        };
        let levelling = [self.coarse_std[0], self.coarse_std[1]].map(|s| {
            if s.is_finite() {
                f64::from(s)
            } else {
                10f64.to_radians()
            }
        });
        let config = filter_config(
            &self.position,
            &[levelling[0], levelling[1], sigma.azimuth],
            self.noise,
        );
        let state = NavState::at_rest(quat_from_euler(&start.to_euler()), self.position);
        self.filter.restart(state, self.position, config);
        self.filter.set_heading(0.0, square(sigma.azimuth));
        self.filter.start_navigation();
        // Inclination and toolface are fused with the probe's levelling.
        let (angles, jacobian) = angles_and_jacobian(&dcm_from_quat(&self.filter.state().attitude));
        let row = |i: usize| [0, 1, 2].map(|k| T::of(jacobian[(i, k)]));
        let tilt = TieInTilt {
            rows: [row(0), row(2)],
            innovation: [
                T::of(angles.inclination - given.inclination),
                T::of(crate::conventions::wrap_pi(
                    angles.toolface - given.toolface,
                )),
            ],
            variance: [
                T::of(square(sigma.inclination)),
                T::of(square(sigma.toolface)),
            ],
        };
        self.filter.aid(&tilt);
        let euler_std = self.filter.euler_std();
        self.set_heading_source([euler_std.x, euler_std.y, sigma.azimuth]);
        self.input = ProbeInput::new();
        self.coasting = false;
        self.coarse_single_part = false;
        // `was_still` is kept: the roll is the levelling's, held as at the
        // end of the fine alignment (`enter_navigation`).
        self.forget_drilling();
    }

    /// [`start_from_tie_in`](Self::start_from_tie_in) before the probe
    /// has levelled itself (or with a covariance that lost its meaning):
    /// the filter starts again from the tie-in's attitude and sigmas.
    fn restart_from_tie_in(&mut self, tie_in: &TieIn) {
        let sigma = tie_in.euler_sigma();
        let mut config = filter_config(&self.position, &sigma, self.noise);
        config.tilt_prior = TiltPrior::Independent;
        let start = NavState::at_rest(tie_in.attitude(), self.position);
        self.filter.restart(start, self.position, config);
        self.filter
            .set_attitude_error_covariance(&tie_in.attitude_error_covariance());
        self.filter.start_navigation();
        self.set_heading_source(sigma);
        self.input = ProbeInput::new();
        self.held = None;
        self.missed = 0;
        self.coasting = false;
        self.covariance_invalid = false;
        self.coarse_single_part = false;
        self.was_still = false;
        self.forget_drilling();
        self.phase = Phase::Navigating;
    }
}
