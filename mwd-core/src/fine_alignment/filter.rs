//! The fine alignment's filter ([`FineAlignment`]): the strapdown
//! mechanization and the error-state filter, started and restarted in
//! place, one step per sample (mechanization, time update, the zero
//! updates, feedback), and what it tells about itself.

use super::config::{
    add_levelling_bias_correlation, ArInitialCovariance, BiasWalk, FineAlignmentConfig,
    SpecificForceInModel, TiltPrior,
};
use crate::aid_sources::{ZeroPosition, ZeroVelocity};
use crate::earth::{LocalEarth, Position};
use crate::error_model::{
    AugmentedTransition, LinearizationPoint, ATT, NAV_STATES, POS, STATES, STATES_WITH_BIASES, VEL,
};
use crate::kalman::{CrossCovariances, FilterScalar, KalmanFilter, UpdateReport};
use crate::mechanization::{ImuSample, NavState, Strapdown};
use nalgebra::{SMatrix, SVector, UnitQuaternion, Vector3};

/// What a step adds for a sample that was not (all) measured
/// ([`FineAlignment::step_with`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepNoise {
    /// Variance added to each attitude-error state (rad^2).
    pub attitude: f64,
    /// Variance added to each velocity-error state ((m/s)^2).
    pub velocity: f64,
    /// No zero-velocity or zero-position update in this step.
    pub skip_updates: bool,
}

impl StepNoise {
    /// A measured sample: nothing added.
    pub const NONE: Self = Self {
        attitude: 0.0,
        velocity: 0.0,
        skip_updates: false,
    };

    pub(super) fn is_none(&self) -> bool {
        self.attitude == 0.0 && self.velocity == 0.0
    }
}

/// What one fine-alignment step did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepReport {
    /// False when the sample held a NaN or infinity: nothing was done.
    pub sample_used: bool,
    pub zero_velocity: UpdateReport,
    pub zero_position: UpdateReport,
    /// The attitude, velocity and position corrections fed back.
    pub correction: [f64; NAV_STATES],
}

/// The fine alignment in progress, with `N` = 33 ([`STATES`]) or 39
/// ([`STATES_WITH_BIASES`]) filter states.
#[derive(Debug, Clone)]
pub struct FineAlignment<T: FilterScalar, const N: usize = STATES> {
    pub(super) strapdown: Strapdown,
    pub(super) filter: KalmanFilter<T, N>,
    pub(super) config: FineAlignmentConfig<N>,
    pub(super) q: SVector<T, N>,
    /// Geodetic terms of F, refreshed when the solution has moved.
    pub(super) earth: LocalEarth,
    /// The local earth at the reference position, for the zero-position
    /// update.
    pub(super) reference: LocalEarth,
    pub(super) steps: u32,
    pub(super) rejected_samples: u32,
    /// The tool-axis rate fed to the mechanization is the frame's at the
    /// computed attitude (`ToolAxisSource::AtRest`), not a measurement:
    /// see [`hold_tool_axis`](Self::hold_tool_axis).
    pub(super) held_tool_axis: bool,
    /// The attitude the error model is linearised at, when fixed
    /// ([`fix_linearization`](Self::fix_linearization)); `None`: the
    /// computed attitude of each step.
    pub(super) linearization_attitude: Option<UnitQuaternion<f64>>,
    pub(super) bias_walk: BiasWalk,
    /// Per accelerometer bias: the random-walk variance added since the
    /// measurements stopped updating them
    /// ([`learn_accel_bias`](Self::learn_accel_bias)).
    pub(super) accel_walk_unlearned: [f64; 3],
    /// The heading turn of the corrections fed back while the model is
    /// linearised at each step's estimate and not yet turned into the
    /// covariance: (w, k) of a rotation about the vertical, unnormalised
    /// ([`turn_with_corrections`](Self::turn_with_corrections)); `None`
    /// in the alignment, which is the paper's filter (from
    /// [`start_navigation`](Self::start_navigation) on: `Some`).
    pub(super) unturned_correction: Option<(f64, f64)>,
}

impl<T: FilterScalar, const N: usize> FineAlignment<T, N> {
    /// Starts from a coarse alignment `initial` (attitude, zero velocity,
    /// known position) and the known position `reference` of the tool.
    pub fn new(initial: NavState, reference: Position, config: FineAlignmentConfig<N>) -> Self {
        let mut alignment = Self {
            strapdown: Strapdown::new(initial, config.model.dt),
            filter: KalmanFilter::new(SMatrix::zeros()),
            config,
            q: SVector::zeros(),
            earth: LocalEarth::at(&initial.position),
            reference: LocalEarth::at(&reference),
            steps: 0,
            rejected_samples: 0,
            held_tool_axis: false,
            linearization_attitude: None,
            bias_walk: BiasWalk::EveryStep,
            accel_walk_unlearned: [0.0; 3],
            unturned_correction: None,
        };
        alignment.restart(initial, reference, config);
        alignment
    }

    /// Starts again, in place, as [`new`](Self::new) would: the probe keeps
    /// one filter for its whole run (moving a 39-state filter costs 6 KiB
    /// of stack per copy).
    pub fn restart(
        &mut self,
        initial: NavState,
        reference: Position,
        config: FineAlignmentConfig<N>,
    ) {
        let model = &config.model;
        let p0 = &mut self.filter.p;
        model.write_initial_covariance(&config.initial_nav_variance, p0);
        if let ArInitialCovariance::Diagonal(v) = config.initial_ar {
            p0.view_mut(
                (NAV_STATES, NAV_STATES),
                (STATES - NAV_STATES, STATES - NAV_STATES),
            )
            .fill(T::zero());
            for i in NAV_STATES..STATES {
                p0[(i, i)] = T::of(v);
            }
        }
        if N == STATES_WITH_BIASES && config.tilt_prior == TiltPrior::LevelledWithSameAccelerometers
        {
            add_levelling_bias_correlation(p0, &initial);
        }
        self.q = model.process_noise(&config.process_noise);
        for i in NAV_STATES..STATES {
            self.q[i] *= T::of(config.ar_noise_scale);
        }
        self.filter.x.fill(T::zero());
        self.filter.cross.clear_all();
        self.filter.gate = config.gate.map(T::of);
        self.filter.consider = 0..0;
        self.strapdown = Strapdown::new(initial, model.dt);
        self.config = config;
        self.earth = LocalEarth::at(&initial.position);
        self.reference = LocalEarth::at(&reference);
        self.steps = 0;
        self.rejected_samples = 0;
        self.held_tool_axis = false;
        self.linearization_attitude = None;
        self.bias_walk = BiasWalk::EveryStep;
        self.accel_walk_unlearned = [0.0; 3];
        self.unturned_correction = None;
    }

    /// One sample: mechanization, time update, measurement updates,
    /// feedback and reset of the navigation errors.
    ///
    /// Never inlined: with its fixed-size loops unrolled it is ~20 KiB of
    /// Cortex-M code, and a caller that calls it from two places (the
    /// probe's alignment and navigation phases) would get two copies.
    pub fn step(&mut self, sample: &ImuSample) -> StepReport {
        self.step_with(sample, &StepNoise::NONE)
    }

    /// [`step`](Self::step) for a sample that is not (all) measured: a held
    /// or substituted one (the probe's sensor gaps and single-part mode).
    /// `extra` is added to the process noise of this step only; with
    /// `extra.skip_updates` no zero update is made (the probe's stillness
    /// was not seen in this sample). Never inlined, as said above.
    #[inline(never)]
    pub fn step_with(&mut self, sample: &ImuSample, extra: &StepNoise) -> StepReport {
        // A non-finite sample would poison the mechanization for good: skip
        // it and say so (the caller counts it; the next sample goes on).
        let finite = sample
            .rate
            .iter()
            .chain(sample.specific_force.iter())
            .all(|v| v.is_finite());
        if !finite {
            self.rejected_samples = self.rejected_samples.saturating_add(1);
            return StepReport {
                sample_used: false,
                zero_velocity: UpdateReport::default(),
                zero_position: UpdateReport::default(),
                correction: [0.0; NAV_STATES],
            };
        }
        self.strapdown.step(sample);
        let state = *self.strapdown.state();
        let c_bn = self
            .linearization_attitude
            .unwrap_or(state.attitude)
            .to_rotation_matrix()
            .into_inner();
        if !self.earth.is_near(&state.position) {
            self.earth = LocalEarth::at(&state.position);
        }
        let lp = LinearizationPoint {
            c_bn,
            velocity_n: state.velocity,
            position: state.position,
            specific_force_n: match self.config.specific_force {
                SpecificForceInModel::MeasuredSample => c_bn * sample.specific_force,
                // The local earth's gravity (refreshed within ~10 m: 3e-5
                // m/s^2 at most from the solution's, a linearisation
                // point's), not Somigliana's formula again every step in
                // software f64.
                SpecificForceInModel::GravityAtRest => -self.earth.gravity_n(),
            },
        };
        let phi: AugmentedTransition<T, N> = self.config.model.transition_with(&self.earth, &lp);
        let mut q = self.q;
        self.scale_bias_walk(&mut q);
        if self.held_tool_axis {
            // The held axis's row takes no process noise
            // (`predict_holding_axis`); this step's extra attitude noise
            // (a rate that was not measured, e.g. a gap's held sample)
            // is added after it, about every axis: what was not measured
            // may have turned the tool about its axis too.
            for i in 0..3 {
                q[VEL + i] += T::of(extra.velocity);
            }
            self.predict_with_held_tool_axis(&phi, &q, &c_bn);
            for i in 0..3 {
                self.filter.p[(ATT + i, ATT + i)] += T::of(extra.attitude);
            }
        } else {
            if !extra.is_none() {
                for i in 0..3 {
                    q[ATT + i] += T::of(extra.attitude);
                    q[VEL + i] += T::of(extra.velocity);
                }
            }
            self.filter.predict(&phi, &q);
        }
        self.add_gyro_instability_noise(&c_bn);

        let zero_velocity = match self.config.zero_velocity_variance {
            Some(_) if extra.skip_updates => UpdateReport::default(),
            Some(r) => self
                .filter
                .update(&ZeroVelocity::new(&state.velocity, T::of(r))),
            None => UpdateReport::default(),
        };
        let zero_position = match self.config.zero_position_variance {
            Some(_) if extra.skip_updates => UpdateReport::default(),
            Some(r) => self.filter.update(&ZeroPosition::new(
                &state.position,
                &self.reference,
                T::of(r),
            )),
            None => UpdateReport::default(),
        };

        let correction = self.feed_back();
        self.steps = self.steps.saturating_add(1);
        StepReport {
            sample_used: true,
            zero_velocity,
            zero_position,
            correction,
        }
    }

    /// Feeds the estimated navigation errors back into the mechanization
    /// (closed loop) and zeroes them in the filter; returns them.
    pub(super) fn feed_back(&mut self) -> [f64; NAV_STATES] {
        let correction: [f64; NAV_STATES] = core::array::from_fn(|i| self.filter.x[i].as_f64());
        let v3 = |first: usize| {
            Vector3::new(
                correction[first],
                correction[first + 1],
                correction[first + 2],
            )
        };
        self.strapdown
            .apply_correction(&v3(ATT), &v3(VEL), &v3(POS));
        self.turn_with_corrections(correction[ATT + 2]);
        for i in 0..NAV_STATES {
            self.filter.x[i] = T::zero();
        }
        correction
    }

    /// States `first..first + count` made independent of every state:
    /// their rows and columns of the covariance zeroed (their variances
    /// too, for the caller to set) and their cross-covariances with the
    /// snapshots forgotten (`kalman::CrossCovariances::forget_states`).
    pub(super) fn forget_states(&mut self, first: usize, count: usize) {
        let p = &mut self.filter.p;
        for i in first..first + count {
            for j in 0..N {
                p[(i, j)] = T::zero();
                p[(j, i)] = T::zero();
            }
        }
        self.filter.cross.forget_states(first, count);
    }

    /// Ends the alignment: no more zero-velocity or zero-position updates,
    /// and F21 takes the measured specific force (the tool may now move).
    /// The filter goes on propagating, so the estimated biases keep being
    /// compensated and the covariance grows as the errors do; from here the
    /// gyro biases are constants and their instability rate noise
    /// ([`BiasWalk::InstabilityAsRateNoise`]): navigation lasts hours; and
    /// heading corrections turn the navigation-frame covariance
    /// ([`turn_with_corrections`](Self::turn_with_corrections)).
    pub fn start_navigation(&mut self) {
        self.config.zero_velocity_variance = None;
        self.config.zero_position_variance = None;
        self.config.specific_force = SpecificForceInModel::MeasuredSample;
        self.set_bias_walk(BiasWalk::InstabilityAsRateNoise);
        self.unturned_correction = Some((1.0, 0.0));
    }

    /// Turns the zero-velocity update on (noise variance `variance`,
    /// (m/s)^2) or off for the following steps: the navigator's station
    /// surveys while the probe is still (`probe::navigator`).
    pub fn set_zero_velocity(&mut self, variance: Option<f64>) {
        self.config.zero_velocity_variance = variance;
    }

    /// The navigation frame's rate in body axes at the current solution
    /// (the tool-axis rate of a still tool; [`Strapdown::frame_rate_in_body`]).
    pub fn frame_rate_in_body(&mut self) -> Vector3<f64> {
        self.strapdown.frame_rate_in_body()
    }

    /// The corrected navigation solution.
    pub fn state(&self) -> &NavState {
        self.strapdown.state()
    }

    pub fn filter(&self) -> &KalmanFilter<T, N> {
        &self.filter
    }

    /// Samples processed.
    pub fn steps(&self) -> u32 {
        self.steps
    }

    /// Samples skipped because they held a NaN or infinity.
    pub fn rejected_samples(&self) -> u32 {
        self.rejected_samples
    }

    /// The state's covariance with snapshots of earlier states
    /// (`kalman::CrossCovariances`).
    pub fn snapshots(&self) -> &CrossCovariances<T, N> {
        &self.filter.cross
    }

    /// Starts snapshot `slot` of `z = L x` now, or empties or moves the
    /// snapshots (`kalman::CrossCovariances`).
    pub fn snapshots_mut(&mut self) -> (&SMatrix<T, N, N>, &mut CrossCovariances<T, N>) {
        (&self.filter.p, &mut self.filter.cross)
    }
}
