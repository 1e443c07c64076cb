//! Quasi-stationary fine alignment (paper section 3.2.3 and 4): from the
//! coarse alignment, run the strapdown mechanization and the 33-state
//! filter (or the 39-state one with sensor biases) at the sample rate with zero-velocity and zero-position updates,
//! feeding the estimated navigation errors back into the mechanization
//! after every update (closed loop) and zeroing them in the filter.
//!
//! Only the navigation errors are fed back: the AR states are the filter's
//! memory of the coloured sensor noise, not a correction of the solution,
//! so they stay in the state; so do the bias estimates (the mechanization
//! takes raw samples: the filter's dynamics carry the bias's effect).

use crate::aid_sources::{ZeroPosition, ZeroVelocity};
use crate::conventions::{
    dcm_from_quat, euler_error_jacobian, euler_from_quat, quat_from_euler, DEG,
};
use crate::earth::{gravity_n, normal_gravity, LocalEarth, Position, EARTH_RATE};
use crate::error_model::{
    is_model_size, newest_ar_state, AugmentedModel, AugmentedTransition, LinearizationPoint,
    ProcessNoise, ACCEL_BIAS, ATT, GYRO_AR, GYRO_BIAS, NAV_STATES, POS, STATES, STATES_WITH_BIASES,
    VEL,
};
use crate::kalman::{
    std_dev_of, CrossCovariances, FilterScalar, KalmanFilter, Measurement, Transition,
    UpdateReport, LINKED, SNAPSHOTS,
};
use crate::mechanization::{ImuSample, NavState, Strapdown};
use crate::sensor_noise::ImuNoise;
use nalgebra::{Matrix3, Quaternion, SMatrix, SVector, UnitQuaternion, Vector3};

/// How far the computed attitude may turn from a fixed linearisation point
/// before the point is taken again (rad;
/// [`FineAlignment::fix_linearization`]): 1 deg, well above a station's
/// ZUPT jitter (~0.01 deg), well below the heading a quiet gyro re-finds.
pub const MAX_LINEARIZATION_TURN_RAD: f64 = crate::conventions::DEG;
/// cos(MAX_LINEARIZATION_TURN_RAD / 2) = 0.99996192...
const COS_HALF_MAX_LINEARIZATION_TURN: f64 = 0.999_961_923_064_171;
/// How far a fixed linearisation point's heading may lag the estimate's
/// before it is turned to it, about the vertical (rad;
/// [`FineAlignment::fix_linearization`]): 0.1 deg, far below the SCC1300's
/// heading sigma (~7 deg) and a quiet gyro's station corrections, and far
/// above rounding: a few turns of the covariance per station.
pub const MAX_LINEARIZATION_HEADING_LAG_RAD: f64 = 0.1 * crate::conventions::DEG;
/// sin^2(MAX_LINEARIZATION_HEADING_LAG_RAD / 2) = 7.6154...e-7.
const SIN_SQ_HALF_MAX_HEADING_LAG: f64 = 7.615_433_561_505_986e-7;

/// How the AR states start.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ArInitialCovariance {
    /// Each block at its model's stationary covariance.
    Stationary,
    /// The same variance on every AR state (the paper's P0 = 0.01 I).
    Diagonal(f64),
}

/// How the initial tilt error relates to the accelerometer biases
/// (39-state form; ignored with 33 states).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TiltPrior {
    /// Tilt errors independent of the biases, variances as configured.
    Independent,
    /// The coarse attitude was levelled with these same accelerometers, so
    /// its tilt error holds the bias: phiN = (C_b^n b)_E / g, phiE =
    /// -(C_b^n b)_N / g (the rest state of dv' = f^n x phi + C_b^n b,
    /// derivation section 3b). The configured tilt variances are then the
    /// levelling noise alone; the bias part and its cross-covariance with
    /// the bias states are added.
    LevelledWithSameAccelerometers,
}

/// Which specific force f^n enters F21 = [f^n x] (eq. 12).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SpecificForceInModel {
    /// The sample's C_b^n f^b: the usual choice, and right in motion.
    MeasuredSample,
    /// -g^n, what the alignment's own zero-velocity assumption says the
    /// true specific force is. The sample's sensor noise (0.06 m/s^2 on
    /// body x, Table 4) in [f^n x] phi is a term (C_b^n df) x phi that the
    /// true error dynamics do not have (dv' = C~ df + f^n_true x phi with
    /// the computed C~ in the coupling); with tens of degrees of azimuth
    /// error it makes the noise's direction look like heading information
    /// and the azimuth sigma collapse while the error stays large
    /// (derivation section 6).
    GravityAtRest,
}

/// Settings of the fine alignment of a filter with `N` states (33,
/// [`STATES`], or 39, [`STATES_WITH_BIASES`]): the settings that depend on
/// the sensor-bias states follow from `N`, so they cannot disagree with
/// the filter they are given to.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FineAlignmentConfig<const N: usize = STATES> {
    pub model: AugmentedModel,
    pub process_noise: ProcessNoise,
    /// Initial variances of the navigation errors (rad^2, (m/s)^2, m^2).
    pub initial_nav_variance: [f64; NAV_STATES],
    pub initial_ar: ArInitialCovariance,
    /// ZUPT noise variance, (m/s)^2; `None` disables the ZUPT.
    pub zero_velocity_variance: Option<f64>,
    /// Zero-position noise variance, m^2; `None` disables it.
    pub zero_position_variance: Option<f64>,
    /// Chi-square gate on each scalar innovation; `None` disables gating.
    pub gate: Option<f64>,
    /// Multiplies the AR innovation variances in Q (1 for the models' own).
    pub ar_noise_scale: f64,
    /// Initial tilt-bias correlation (39-state form only).
    pub tilt_prior: TiltPrior,
    /// The specific force of the error model's F21.
    pub specific_force: SpecificForceInModel,
}

impl<const N: usize> FineAlignmentConfig<N> {
    /// The paper's section 4 settings: P0 = 0.01 I, Q = I, R = 0.1 I, the
    /// AR models of Tables 4-5. "Q = I" is read as unit white noise on
    /// every state per second (paper's Gamma = G dt, eq. 16, with G = I:
    /// dt^2 per step) and unit-scaled AR innovations; the paper does not
    /// say more.
    pub fn paper(model: AugmentedModel) -> Self {
        let dt = model.dt;
        Self {
            model,
            process_noise: ProcessNoise {
                nav_per_step: [dt * dt; NAV_STATES],
            },
            initial_nav_variance: [0.01; NAV_STATES],
            initial_ar: ArInitialCovariance::Diagonal(0.01),
            zero_velocity_variance: Some(0.1),
            zero_position_variance: Some(0.1),
            gate: None,
            ar_noise_scale: 1.0,
            tilt_prior: TiltPrior::Independent,
            specific_force: SpecificForceInModel::MeasuredSample,
        }
    }

    /// Settings scaled to the sensors' error budget for a probe that is
    /// really still, starting from a coarse alignment with 1-sigma
    /// `coarse_sigma` (roll, pitch, heading; rad) at `latitude`: P0 from the
    /// coarse sigmas, AR blocks at their stationary covariance, process
    /// noise from the white-noise densities of `noise`, tight ZUPT and
    /// zero-position noise. With the sensor-bias states (`N` = 39) the
    /// tilt-bias correlation of levelling and f^n = -g^n in F21 (derivation
    /// sections 3b and 6). The one place the probe and the host tool take
    /// these settings from.
    pub fn physical(
        mut model: AugmentedModel,
        noise: &ImuNoise,
        coarse_sigma: &[f64; 3],
        latitude: f64,
    ) -> Self {
        const { assert!(is_model_size(N), "the filter has 33 or 39 states") };
        let with_biases = N == STATES_WITH_BIASES;
        let square = |v: f64| v * v;
        let mut p0 = [1e-4; NAV_STATES];
        p0[ATT] = square(coarse_sigma[0].max(0.05 * DEG));
        p0[ATT + 1] = square(coarse_sigma[1].max(0.05 * DEG));
        if with_biases {
            // The coarse tilt sigma holds the accelerometer bias's share,
            // sigma_b / g; the filter adds it back with its correlation to
            // the bias states (`TiltPrior::LevelledWithSameAccelerometers`),
            // so P0 takes the levelling noise alone.
            let bias_tilt = model.biases.accel[0].initial_sigma / normal_gravity(latitude, 0.0);
            for v in &mut p0[ATT..ATT + 2] {
                *v = (*v - square(bias_tilt)).max(square(0.01 * DEG));
            }
        }
        p0[ATT + 2] = square(coarse_sigma[2].clamp(1.0 * DEG, 30.0 * DEG));
        // An azimuth error psi misplaces the horizontal earth rate by
        // Omega cos(lat) sin(psi): a tilt drift the small-angle model cannot
        // follow for large psi. Budgeted as attitude noise over a minute.
        let drift = EARTH_RATE
            * libm::cos(latitude)
            * libm::sin(coarse_sigma[2].min(core::f64::consts::FRAC_PI_2));
        let attitude_density = square(noise.gyro[0].white_density) + square(drift) * 60.0;
        let velocity_density = square(noise.accel[2].white_density);
        // At rest the tool-axis rate fed to the mechanization is the
        // frame's (`ToolAxisSource::AtRest`): its error is that same misplaced
        // earth rate, not the accelerometer-derived rate's noise model.
        model.gyro[1].noise_variance = model.gyro[1].noise_variance.max(square(drift));
        Self {
            process_noise: ProcessNoise::from_densities(
                attitude_density,
                velocity_density,
                0.0,
                model.dt,
            ),
            model,
            initial_nav_variance: p0,
            initial_ar: ArInitialCovariance::Stationary,
            zero_velocity_variance: Some(1e-6),
            zero_position_variance: Some(1e-6),
            gate: None,
            ar_noise_scale: 1.0,
            tilt_prior: if with_biases {
                TiltPrior::LevelledWithSameAccelerometers
            } else {
                TiltPrior::Independent
            },
            specific_force: if with_biases {
                SpecificForceInModel::GravityAtRest
            } else {
                SpecificForceInModel::MeasuredSample
            },
        }
    }
}

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

    fn is_none(&self) -> bool {
        self.attitude == 0.0 && self.velocity == 0.0
    }
}

/// How the bias states' random walk is added in the following steps.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BiasWalk {
    /// The Gauss-Markov instability's one-step increment variance on every
    /// bias state, every step (derivation section 3b): the alignment, about
    /// a minute against tau = 100 s, where the walk stays small against
    /// what the updates learn.
    EveryStep,
    /// Navigation, for hours: the gyro (x, z) bias states hold the residual
    /// constant bias only, and the instability enters as white rate noise
    /// at its zero-frequency density 2 sigma^2 tau. A first-order
    /// Gauss-Markov spectrum 2 sigma^2 tau / (1 + (2 pi f tau)^2) never
    /// exceeds that, so every linear function of the noise (a heading
    /// drift, a station's bias mean) has at most the variance the filter
    /// computes, at every time scale. A random walk on the bias state
    /// instead would add 72 sigma^2 per hour (2 T / tau) for a change the
    /// process cannot make, and one bounded by the instability's own
    /// increment makes the filter carry a station's instability into the
    /// next hour's heading drift, which it has forgotten after ~tau
    /// (derivation section 4h). The accelerometer and tool-axis biases walk
    /// as in [`EveryStep`](Self::EveryStep).
    InstabilityAsRateNoise,
}

/// The accelerometer biases' estimate (m/s^2, body axes) and covariance
/// at one step ([`FineAlignment::accel_bias`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AccelBiasSnapshot {
    pub estimate: Vector3<f64>,
    pub covariance: Matrix3<f64>,
    /// The random-walk variance added per axis up to then.
    walk_added: [f64; 3],
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
    strapdown: Strapdown,
    filter: KalmanFilter<T, N>,
    config: FineAlignmentConfig<N>,
    q: SVector<T, N>,
    /// Geodetic terms of F, refreshed when the solution has moved.
    earth: LocalEarth,
    /// The local earth at the reference position, for the zero-position
    /// update.
    reference: LocalEarth,
    steps: u32,
    rejected_samples: u32,
    /// The tool-axis rate fed to the mechanization is the frame's at the
    /// computed attitude (`ToolAxisSource::AtRest`), not a measurement:
    /// see [`hold_tool_axis`](Self::hold_tool_axis).
    held_tool_axis: bool,
    /// The attitude the error model is linearised at, when fixed
    /// ([`fix_linearization`](Self::fix_linearization)); `None`: the
    /// computed attitude of each step.
    linearization_attitude: Option<UnitQuaternion<f64>>,
    bias_walk: BiasWalk,
    /// Per bias state (accelerometers x, y, z then rates): the random-walk
    /// variance added since the start.
    bias_walk_added: [f64; 6],
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
            bias_walk_added: [0.0; 6],
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
        self.strapdown = Strapdown::new(initial, model.dt);
        self.config = config;
        self.earth = LocalEarth::at(&initial.position);
        self.reference = LocalEarth::at(&reference);
        self.steps = 0;
        self.rejected_samples = 0;
        self.held_tool_axis = false;
        self.linearization_attitude = None;
        self.bias_walk = BiasWalk::EveryStep;
        self.bias_walk_added = [0.0; 6];
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
        let lp = LinearizationPoint {
            c_bn,
            velocity_n: state.velocity,
            position: state.position,
            specific_force_n: match self.config.specific_force {
                SpecificForceInModel::MeasuredSample => c_bn * sample.specific_force,
                SpecificForceInModel::GravityAtRest => -gravity_n(&state.position),
            },
        };
        if !self.earth.is_near(&state.position) {
            self.earth = LocalEarth::at(&state.position);
        }
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

    /// Sets this step's bias random walk in `q` ([`BiasWalk`]); keeps the
    /// total added per bias.
    fn scale_bias_walk(&mut self, q: &mut SVector<T, N>) {
        if N != STATES_WITH_BIASES {
            return;
        }
        let biases = &self.config.model.biases;
        let states = biases.accel.iter().chain(biases.gyro.iter());
        for (k, bias) in states.enumerate() {
            let i = ACCEL_BIAS + k; // the rate biases follow the accelerometers'
            let constant = self.bias_walk == BiasWalk::InstabilityAsRateNoise
                && (i == GYRO_BIAS || i == GYRO_BIAS + 2);
            let walk = if constant {
                0.0
            } else {
                bias.variance_per_step
            };
            q[i] = T::of(walk);
            self.bias_walk_added[k] += walk;
        }
    }

    /// How the bias random walk is added from the next step on
    /// ([`BiasWalk`]). Switching a filter that has run to
    /// [`BiasWalk::InstabilityAsRateNoise`] adds sigma^2 of the instability
    /// to the gyro bias variances: the estimate has absorbed the
    /// instability's value of the alignment, which from now on is not part
    /// of the constant it stands for. A fresh filter's initial variance
    /// already holds it.
    pub fn set_bias_walk(&mut self, walk: BiasWalk) {
        let switching = walk == BiasWalk::InstabilityAsRateNoise && self.bias_walk != walk;
        if switching && self.steps > 0 && N == STATES_WITH_BIASES {
            for axis in [0, 2] {
                let sigma = self.config.model.biases.gyro[axis].instability_sigma;
                let i = GYRO_BIAS + axis;
                self.filter.p[(i, i)] += T::of(sigma * sigma);
            }
        }
        self.bias_walk = walk;
    }

    /// The gyros' instability as white rate noise (x and z body axes,
    /// [`BiasWalk::InstabilityAsRateNoise`]): C_b^n diag(S_x, 0, S_z) C_n^b
    /// dt on the attitude error, S = 2 sigma^2 tau.
    fn add_gyro_instability_noise(&mut self, c_bn: &Matrix3<f64>) {
        if self.bias_walk != BiasWalk::InstabilityAsRateNoise || N != STATES_WITH_BIASES {
            return;
        }
        let gyro = &self.config.model.biases.gyro;
        let dt = self.config.model.dt;
        // The sum of the two gyro axes' outer products (columns x and z of
        // C_b^n): a third of the multiplies of C D C^T.
        let (x, z) = (c_bn.column(0), c_bn.column(2));
        let q = x * x.transpose() * (gyro[0].instability_density * dt)
            + z * z.transpose() * (gyro[2].instability_density * dt);
        self.add_attitude_noise(&q);
    }

    /// The time update when the tool-axis rate is held: the rate fed to the
    /// mechanization about the tool axis t is the frame's at the computed
    /// attitude, t . (C~^T omega_in), so the computed tool turns about t
    /// exactly as the frame does, like the still true tool: the attitude
    /// error about t does not move, phi' = -(I - t t^T)(omega_in x phi) -
    /// (I - t t^T) C_b^n (b + e) (derivation section 4f). The transition is
    /// M = Phi - e w^T with e = (t, 0, ...) and w = Phi^T e - e (the
    /// tool-axis attitude row of Phi, less the identity), so that
    /// M P M^T = Phi P Phi^T - z e^T - e z^T + s e e^T, z = Phi P w,
    /// s = w^T P w: the structured time update plus a rank-2 correction of
    /// the three attitude rows and columns (~2 N^2 multiplies, not a second
    /// N^3 product). Without it the model expects the earth rate to turn a
    /// heading error into a drift about the tool axis that the held rate
    /// cancels, sees none at a station, and reads that as heading
    /// information it does not have. The process noise is held out of that
    /// row too, (I - e e^T) Q (I - e e^T) (derivation section 4i): no gyro
    /// senses the tool axis, so its angle random walk does not turn the
    /// held roll; added there, it kept the station toolface sigma at about
    /// twice its error after connections had taught the accelerometer bias
    /// across gravity.
    fn predict_with_held_tool_axis(
        &mut self,
        phi: &AugmentedTransition<T, N>,
        q: &SVector<T, N>,
        c_bn: &Matrix3<f64>,
    ) {
        let tool_axis = Vector3::new(c_bn[(0, 1)], c_bn[(1, 1)], c_bn[(2, 1)]);
        predict_holding_axis(&mut self.filter, phi, q, &tool_axis);
    }

    /// Feeds the estimated navigation errors back into the mechanization
    /// (closed loop) and zeroes them in the filter; returns them.
    fn feed_back(&mut self) -> [f64; NAV_STATES] {
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
        for i in 0..NAV_STATES {
            self.filter.x[i] = T::zero();
        }
        correction
    }

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

    /// Replaces the attitude-error covariance (rad^2, nav frame) and clears
    /// its cross-covariances with every other state: an attitude from
    /// outside the probe's own sensors (a tie-in survey) is independent of
    /// their errors. `p_phi` must be symmetric positive semi-definite.
    pub fn set_attitude_error_covariance(&mut self, p_phi: &Matrix3<f64>) {
        let p = &mut self.filter.p;
        for i in ATT..ATT + 3 {
            for j in 0..N {
                p[(i, j)] = T::zero();
                p[(j, i)] = T::zero();
            }
        }
        for i in 0..3 {
            for j in 0..3 {
                p[(ATT + i, ATT + j)] = T::of(p_phi[(i, j)]);
            }
        }
        self.filter.cross.forget_states(ATT, 3);
    }

    /// Adds `q` (rad^2, nav frame, symmetric positive semi-definite) to the
    /// attitude-error covariance: process noise that is not isotropic, such
    /// as the drilling environment's (the vibration turns the tool about
    /// its cross axes, the orienter about its own axis; derivation section
    /// 4d), added after the step's own time update.
    pub fn add_attitude_noise(&mut self, q: &Matrix3<f64>) {
        let p = &mut self.filter.p;
        for i in 0..3 {
            for j in 0..3 {
                p[(ATT + i, ATT + j)] += T::of(q[(i, j)]);
            }
        }
    }

    /// Ends the alignment: no more zero-velocity or zero-position updates,
    /// and F21 takes the measured specific force (the tool may now move).
    /// The filter goes on propagating, so the estimated biases keep being
    /// compensated and the covariance grows as the errors do; from here the
    /// gyro biases are constants and their instability rate noise
    /// ([`BiasWalk::InstabilityAsRateNoise`]): navigation lasts hours.
    pub fn start_navigation(&mut self) {
        self.config.zero_velocity_variance = None;
        self.config.zero_position_variance = None;
        self.config.specific_force = SpecificForceInModel::MeasuredSample;
        self.set_bias_walk(BiasWalk::InstabilityAsRateNoise);
    }

    /// Linearises F21 (the velocity error's f^n x phi) at the gravity
    /// reaction instead of the measured specific force (`true`), or back
    /// at the measured one: while drilling the measured force is mostly
    /// vibration (~0.74 g per sample), which the mechanization integrates
    /// as noise; linearised at it the filter would read that noise, through
    /// the constraints, as azimuth information (derivation section 4d).
    pub fn linearize_at_gravity(&mut self, at_gravity: bool) {
        self.config.specific_force = if at_gravity {
            SpecificForceInModel::GravityAtRest
        } else {
            SpecificForceInModel::MeasuredSample
        };
    }

    /// Turns the solution about the vertical by `angle` (rad, exact, not a
    /// small-angle correction) and makes the heading error independent of
    /// everything else with variance `variance` (rad^2): a heading given
    /// from outside the probe's sensors (a tie-in survey's azimuth), which
    /// replaces the probe's own. A turn about the vertical keeps the
    /// inclination and toolface, and the tilt errors' covariance with the
    /// sensor states (the levelling's own accelerometer biases) is kept.
    pub fn set_heading(&mut self, angle: f64, variance: f64) {
        let mut state = *self.strapdown.state();
        let turn = nalgebra::UnitQuaternion::from_axis_angle(&Vector3::z_axis(), angle);
        state.attitude = turn * state.attitude;
        self.strapdown.reset(state);
        let p = &mut self.filter.p;
        for j in 0..N {
            p[(ATT + 2, j)] = T::zero();
            p[(j, ATT + 2)] = T::zero();
        }
        p[(ATT + 2, ATT + 2)] = T::of(variance);
        self.filter.x[ATT + 2] = T::zero();
        self.filter.cross.forget_states(ATT + 2, 1);
    }

    /// Turns the solution about the tool axis so that its roll is `roll`
    /// (rad), exactly (not a small-angle correction), keeping pitch and
    /// heading: a toolface found far from the filter's while drilling
    /// (`aid_sources::DrillingToolface`). The caller adds the new roll's
    /// uncertainty ([`add_attitude_noise`](Self::add_attitude_noise)).
    pub fn set_roll(&mut self, roll: f64) {
        let mut state = *self.strapdown.state();
        let mut euler = euler_from_quat(&state.attitude);
        euler.roll = roll;
        state.attitude = quat_from_euler(&euler);
        self.strapdown.reset(state);
    }

    /// The accelerometer-bias estimate (m/s^2, body axes) and its
    /// covariance now, to put back later; `None` in the 33-state form,
    /// which has no bias states.
    pub fn accel_bias(&self) -> Option<AccelBiasSnapshot> {
        if N != STATES_WITH_BIASES {
            return None;
        }
        let x = &self.filter.x;
        Some(AccelBiasSnapshot {
            estimate: Vector3::from_fn(|i, _| x[ACCEL_BIAS + i].as_f64()),
            covariance: Matrix3::from_fn(|i, j| {
                self.filter.p[(ACCEL_BIAS + i, ACCEL_BIAS + j)].as_f64()
            }),
            walk_added: [
                self.bias_walk_added[0],
                self.bias_walk_added[1],
                self.bias_walk_added[2],
            ],
        })
    }

    /// Puts back an accelerometer-bias estimate and covariance taken
    /// earlier ([`accel_bias`](Self::accel_bias)), grown by the random walk
    /// the filter has added since ([`BiasWalk`]) up to the instability's
    /// largest change, 2 sigma^2, with no correlation to
    /// the other states (which keeps P positive semi-definite: a principal
    /// block and a PSD block). The probe's stations use it: what the filter
    /// learns of the accelerometers while drilling is the bias plus the
    /// vibration's rectified share, which is gone at rest (derivation
    /// section 4f).
    pub fn restore_accel_bias(&mut self, snapshot: &AccelBiasSnapshot) {
        if N != STATES_WITH_BIASES {
            return;
        }
        self.filter.cross.forget_states(ACCEL_BIAS, 3);
        let p = &mut self.filter.p;
        for i in ACCEL_BIAS..ACCEL_BIAS + 3 {
            for j in 0..N {
                p[(i, j)] = T::zero();
                p[(j, i)] = T::zero();
            }
        }
        for i in 0..3 {
            self.filter.x[ACCEL_BIAS + i] = T::of(snapshot.estimate[i]);
            for j in 0..3 {
                p[(ACCEL_BIAS + i, ACCEL_BIAS + j)] = T::of(snapshot.covariance[(i, j)]);
            }
            // The instability changes by at most 2 sigma^2 in variance
            // over any time (stationary Gauss-Markov: 2 sigma^2 (1 -
            // exp(-T/tau))); the walk over an hour of drilling adds 72.
            let sigma = self.config.model.biases.accel[i].instability_sigma;
            // (max and min, not clamp: clamp's check of its bounds panics
            // with the floats formatted, 24 KiB of the probe's flash)
            let walk = (self.bias_walk_added[i] - snapshot.walk_added[i])
                .max(0.0)
                .min(2.0 * sigma * sigma);
            p[(ACCEL_BIAS + i, ACCEL_BIAS + i)] += T::of(walk);
        }
    }

    /// Linearises the error model of the following steps (Phi, the held
    /// tool axis, the gyro instability's noise) at the attitude computed
    /// now (`true`; kept while called with `true` again), or again at each
    /// step's computed attitude (`false`). For a tool that is still (a
    /// station): its true attitude does not change, but the estimate does,
    /// by every zero-velocity update's correction, and a Jacobian that
    /// follows that jitter sees the tool-axis accelerometer bias from
    /// directions the tool never took (derivation section 4i: the
    /// first-estimates Jacobian of Huang, Mourikis and Roumeliotis, 2008).
    /// A first estimate is only good while the estimate stays near it: a
    /// station re-finds its heading by degrees (a quiet gyro's rate
    /// gyrocompass, or the SCC1300's heading sigma of ~7 deg being read
    /// from its horizontal earth rate and the tilt it drives), and a model
    /// left at the old heading (the held axis, the biases' directions) then
    /// drove it away (100 deg in one simulated station) or, re-taken at
    /// each degree, saw the tool-axis accelerometer bias from new
    /// directions again. The heading is not what the first estimate is
    /// for: the point's heading follows the estimate's (about the vertical,
    /// once it lags by more than [`MAX_LINEARIZATION_HEADING_LAG_RAD`]),
    /// and the navigation-frame attitude and velocity errors' covariance is
    /// turned with it ([`follow_heading`](Self::follow_heading), derivation
    /// section 4e), while its tilt and roll stay the first estimate's. The
    /// point is taken again only once the estimate has turned more than
    /// [`MAX_LINEARIZATION_TURN_RAD`] from it otherwise (a re-levelling).
    pub fn fix_linearization(&mut self, fixed: bool) {
        let current = self.strapdown.state().attitude;
        self.linearization_attitude = match self.linearization_attitude {
            _ if !fixed => None,
            None => Some(current),
            Some(at) => {
                let at = self.follow_heading(at, &current);
                // |q1 . q2| = cos(angle / 2): no trigonometry per step
                if at.coords.dot(&current.coords).abs() >= COS_HALF_MAX_LINEARIZATION_TURN {
                    Some(at)
                } else {
                    Some(current)
                }
            }
        };
    }

    /// The fixed point `at` turned about the navigation frame's vertical
    /// to the heading of `current`, once it lags by more than
    /// [`MAX_LINEARIZATION_HEADING_LAG_RAD`], with the covariance of the
    /// navigation-frame errors (attitude and velocity) turned by the same
    /// rotation R_z: P <- T P T^T, T = R_z on those two blocks and 1 on the
    /// rest (the body-frame biases and AR states, and the position, whose
    /// past does not turn with a new heading). So the model's C_b^n and the
    /// covariance the filter holds in navigation axes stay in one frame: a
    /// still tool's errors are then the same statement about the body
    /// whatever heading the estimate has found, and the zero-velocity
    /// updates do not see a bias from a direction the tool never took
    /// (derivation section 4e). The rotation is the twist about the
    /// vertical of current at^-1 (swing-twist: (w, 0, 0, k) normalised; no
    /// trigonometry).
    fn follow_heading(
        &mut self,
        at: UnitQuaternion<f64>,
        current: &UnitQuaternion<f64>,
    ) -> UnitQuaternion<f64> {
        let turn = current * at.inverse();
        let (w, k) = (turn.w, turn.k);
        let twist_sq = w * w + k * k;
        // sin^2(twist / 2) = k^2 / (w^2 + k^2); also a turn of 180 deg
        // about a horizontal axis (twist_sq = 0, k = 0) stays here
        if k * k <= SIN_SQ_HALF_MAX_HEADING_LAG * twist_sq {
            return at;
        }
        let norm = libm::sqrt(twist_sq);
        let twist = UnitQuaternion::new_unchecked(Quaternion::new(w / norm, 0.0, 0.0, k / norm));
        let r = twist.to_rotation_matrix().into_inner().map(T::of);
        let p = &mut self.filter.p;
        for first in [ATT, VEL] {
            let rows = r * p.fixed_view::<3, N>(first, 0);
            p.fixed_view_mut::<3, N>(first, 0).copy_from(&rows);
        }
        for first in [ATT, VEL] {
            let columns = p.fixed_view::<N, 3>(0, first) * r.transpose();
            p.fixed_view_mut::<N, 3>(0, first).copy_from(&columns);
        }
        // exactly symmetric again (the two products round differently)
        let half = T::of(0.5);
        for first in [ATT, VEL] {
            for i in first..first + 3 {
                for j in 0..N {
                    let v = (p[(i, j)] + p[(j, i)]) * half;
                    p[(i, j)] = v;
                    p[(j, i)] = v;
                }
            }
        }
        twist * at
    }

    /// The attitude the error model is linearised at: the fixed one
    /// ([`fix_linearization`](Self::fix_linearization)) or the current
    /// estimate. An aiding row that depends on the attitude (the station's
    /// rate gyrocompass, `aid_sources::EarthRate`) takes it too, so that
    /// the model's Jacobians all sit at one point (derivation section 4e).
    pub fn linearization_attitude(&self) -> UnitQuaternion<f64> {
        self.linearization_attitude
            .unwrap_or(self.strapdown.state().attitude)
    }

    /// Whether the tool-axis rate fed to the following steps is held at the
    /// frame's rate (`ToolAxisSource::AtRest`) rather than measured: the
    /// time update then leaves the attitude error about the tool axis
    /// where it is ([`predict_with_held_tool_axis`](Self::predict_with_held_tool_axis)).
    pub fn hold_tool_axis(&mut self, held: bool) {
        self.held_tool_axis = held;
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

    /// Covariance of the attitude error phi (nav frame), rad^2.
    pub fn attitude_error_covariance(&self) -> Matrix3<f64> {
        self.filter
            .p
            .fixed_view::<3, 3>(ATT, ATT)
            .map(|v| v.as_f64())
    }

    /// Standard deviations of roll, pitch and heading (rad; NaN where the
    /// variance is not valid, see [`KalmanFilter::std_dev`]), through the
    /// Jacobian of the project's Euler convention at the current attitude.
    pub fn euler_std(&self) -> Vector3<f64> {
        let j = euler_error_jacobian(&dcm_from_quat(&self.state().attitude));
        let p = j * self.attitude_error_covariance() * j.transpose();
        // A negative or NaN variance stays NaN: never a confident 0.
        Vector3::new(p[(0, 0)], p[(1, 1)], p[(2, 2)]).map(std_dev_of)
    }
}

/// Adds to `p0` what levelling with biased accelerometers puts into the
/// tilt: phi_h = M b with M = (1/g) [row E of C_b^n; -row N of C_b^n]
/// (derivation section 3b), so P(phi_h) += M S M^T and P(phi_h, b) = M S,
/// S the accelerometer bias block. With the levelling noise N already on
/// the tilt diagonal this is [I M; 0 I] blockdiag(N, S) [I M; 0 I]^T:
/// positive semi-definite by construction.
fn add_levelling_bias_correlation<T: FilterScalar, const N: usize>(
    p0: &mut SMatrix<T, N, N>,
    initial: &NavState,
) {
    let c_bn = initial.attitude.to_rotation_matrix().into_inner();
    let g = normal_gravity(initial.position.lat, initial.position.height);
    let m = Matrix3::from_fn(|i, j| match i {
        0 => c_bn[(1, j)] / g,
        1 => -c_bn[(0, j)] / g,
        _ => 0.0,
    });
    let s = p0
        .fixed_view::<3, 3>(ACCEL_BIAS, ACCEL_BIAS)
        .map(|v| v.as_f64());
    let cross = m * s;
    let tilt = cross * m.transpose();
    for i in 0..3 {
        for j in 0..3 {
            p0[(ATT + i, ATT + j)] += T::of(tilt[(i, j)]);
            p0[(ATT + i, ACCEL_BIAS + j)] = T::of(cross[(i, j)]);
            p0[(ACCEL_BIAS + j, ATT + i)] = T::of(cross[(i, j)]);
        }
    }
}

/// `filter`'s time update with the attitude error about the unit vector
/// `axis` (nav frame) held where it was: transition M = Phi - e w^T, e =
/// (axis, 0, ...), w = Phi^T e - e ([`FineAlignment::hold_tool_axis`]),
/// and process noise (I - e e^T) Q (I - e e^T) (`q` diagonal). The
/// structured Phi P Phi^T + Q plus the rank-2 correction
/// -z e^T - e z^T + s e e^T with z = Phi P w + Q e and
/// s = w^T P w + e^T Q e.
pub fn predict_holding_axis<T: FilterScalar, const N: usize>(
    filter: &mut KalmanFilter<T, N>,
    phi: &AugmentedTransition<T, N>,
    q: &SVector<T, N>,
    axis: &Vector3<f64>,
) {
    let t: [T; 3] = core::array::from_fn(|i| T::of(axis[i]));
    // w: the axis's attitude row of Phi (navigation block and the
    // rate-error couplings) less e.
    let mut w = SVector::<T, N>::zeros();
    for j in 0..NAV_STATES {
        let mut r = T::zero();
        for (i, ti) in t.iter().enumerate() {
            r += *ti * phi.nav[(ATT + i, j)];
        }
        w[j] = r;
    }
    for (i, ti) in t.iter().enumerate() {
        w[ATT + i] -= *ti;
    }
    if phi.coupled {
        for axis in 0..3 {
            let mut g = T::zero();
            for (i, ti) in t.iter().enumerate() {
                g += *ti * phi.c_bn_dt[(i, axis)];
            }
            w[newest_ar_state(GYRO_AR, axis)] = -g;
            if N == STATES_WITH_BIASES {
                w[GYRO_BIAS + axis] = -g;
            }
        }
    }
    let mut z = SVector::<T, N>::zeros();
    for (j, wj) in w.iter().enumerate() {
        if *wj != T::zero() {
            for i in 0..N {
                z[i] += filter.p[(i, j)] * *wj;
            }
        }
    }
    let mut s = w.dot(&z);
    let wx = w.dot(&filter.x);
    // The snapshots' cross-covariances take the same transition M = Phi -
    // e w^T: Phi G in `predict`, then the held rows less t (w^T G).
    let mut wg = [T::zero(); SNAPSHOTS * LINKED];
    for (wgc, column) in wg.iter_mut().zip(filter.cross.columns_mut()) {
        // (w's slice, not nalgebra's strided iterator: the same sum in the
        // same order, without a stride per element)
        *wgc = w
            .as_slice()
            .iter()
            .zip(column.iter())
            .fold(T::zero(), |acc, (a, b)| acc + *a * *b);
    }
    filter.predict(phi, q);
    for (wgc, column) in wg.iter().zip(filter.cross.columns_mut()) {
        for (k, tk) in t.iter().enumerate() {
            column[ATT + k] -= *tk * *wgc;
        }
    }
    phi.apply_to_vector(&mut z);
    // The held row's process noise is zero as well: x' = M x + (I - e e^T)
    // n (the held component is t . phi_k itself, with no sensor behind
    // it), so Q enters as (I - e e^T) Q (I - e e^T) = Q - (Q e) e^T -
    // e (Q e)^T + (e^T Q e) e e^T. With Q diagonal, Q e is t scaled by
    // the attitude entries of q: folded into z and s below.
    for (k, tk) in t.iter().enumerate() {
        let qe = q[ATT + k] * *tk;
        z[ATT + k] += qe;
        s += *tk * qe;
    }
    let p = &mut filter.p;
    for (k, tk) in t.iter().enumerate() {
        for i in 0..N {
            p[(i, ATT + k)] -= z[i] * *tk;
        }
    }
    for (k, tk) in t.iter().enumerate() {
        for j in 0..N {
            p[(ATT + k, j)] -= *tk * z[j];
        }
        for (l, tl) in t.iter().enumerate() {
            p[(ATT + k, ATT + l)] += s * *tk * *tl;
        }
        filter.x[ATT + k] -= *tk * wx;
    }
}

#[cfg(test)]
#[path = "fine_alignment_tests.rs"]
mod tests;
