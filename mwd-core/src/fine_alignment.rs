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

use crate::attitude::quat_from_rotation_vector;
use crate::conventions::{euler_from_quat, wrap_pi};
use crate::earth::{gravity_n, normal_gravity, Position};
use crate::error_model::{
    AugmentedModel, AugmentedTransition, EarthTerms, LinearizationPoint, ProcessNoise, ACCEL_BIAS,
    ATT, NAV_STATES, POS, STATES, STATES_WITH_BIASES, VEL,
};
use crate::kalman::{FilterScalar, KalmanFilter, UpdateReport};
use crate::measurement::{ZeroPosition, ZeroVelocity};
use crate::mechanization::{ImuSample, NavState, Strapdown};
use nalgebra::{Matrix3, SMatrix, SVector, UnitQuaternion, Vector3};

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

/// Settings of the fine alignment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FineAlignmentConfig {
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

impl FineAlignmentConfig {
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
    config: FineAlignmentConfig,
    q: SVector<T, N>,
    /// Geodetic terms of F, refreshed when the solution has moved.
    earth: EarthTerms,
    /// Radii at the reference position, for the zero-position update.
    reference_terms: EarthTerms,
    steps: u32,
    rejected_samples: u32,
}

impl<T: FilterScalar, const N: usize> FineAlignment<T, N> {
    /// Starts from a coarse alignment `initial` (attitude, zero velocity,
    /// known position) and the known position `reference` of the tool.
    pub fn new(initial: NavState, reference: Position, config: FineAlignmentConfig) -> Self {
        let model = &config.model;
        let mut p0: SMatrix<T, N, N> = model.initial_covariance(&config.initial_nav_variance);
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
            add_levelling_bias_correlation(&mut p0, &initial);
        }
        let mut q: SVector<T, N> = model.process_noise(&config.process_noise);
        for i in NAV_STATES..STATES {
            q[i] *= T::of(config.ar_noise_scale);
        }
        let mut filter = KalmanFilter::new(p0);
        filter.gate = config.gate.map(T::of);
        Self {
            strapdown: Strapdown::new(initial, model.dt),
            filter,
            config,
            q,
            earth: EarthTerms::at(&initial.position),
            reference_terms: EarthTerms::at(&reference),
            steps: 0,
            rejected_samples: 0,
        }
    }

    /// One sample: mechanization, time update, measurement updates,
    /// feedback and reset of the navigation errors.
    pub fn step(&mut self, sample: &ImuSample) -> StepReport {
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
        let c_bn = state.attitude.to_rotation_matrix().into_inner();
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
            self.earth = EarthTerms::at(&state.position);
        }
        let phi: AugmentedTransition<T, N> = self.config.model.transition_with(&self.earth, &lp);
        self.filter.predict(&phi, &self.q);

        let zero_velocity = match self.config.zero_velocity_variance {
            Some(r) => self
                .filter
                .update(&ZeroVelocity::new(&state.velocity, T::of(r))),
            None => UpdateReport::default(),
        };
        let zero_position = match self.config.zero_position_variance {
            Some(r) => self.filter.update(&ZeroPosition::with_earth_terms(
                &state.position,
                &self.reference_terms,
                T::of(r),
            )),
            None => UpdateReport::default(),
        };

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
        self.steps = self.steps.saturating_add(1);
        StepReport {
            sample_used: true,
            zero_velocity,
            zero_position,
            correction,
        }
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

    /// Covariance of the attitude error phi (nav frame), rad^2.
    pub fn attitude_error_covariance(&self) -> Matrix3<f64> {
        self.filter
            .p
            .fixed_view::<3, 3>(ATT, ATT)
            .map(|v| v.as_f64())
    }

    /// Standard deviations of roll, pitch and heading (rad), through the
    /// Jacobian of the project's Euler convention at the current attitude.
    pub fn euler_std(&self) -> Vector3<f64> {
        let j = euler_error_jacobian(&self.state().attitude);
        let p = j * self.attitude_error_covariance() * j.transpose();
        Vector3::new(p[(0, 0)], p[(1, 1)], p[(2, 2)]).map(|v| libm::sqrt(v.max(0.0)))
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

/// d(roll, pitch, heading of the computed attitude) / d(phi), where the
/// computed attitude is the true one with error phi (q_computed =
/// q(-phi) q_true): central differences of the conventions module's own
/// Euler extraction, so this never re-derives the angle convention.
pub fn euler_error_jacobian(attitude: &UnitQuaternion<f64>) -> Matrix3<f64> {
    let h = 1e-6;
    let euler = |phi: &Vector3<f64>| {
        let e = euler_from_quat(&(quat_from_rotation_vector(&-phi) * attitude));
        Vector3::new(e.roll, e.pitch, e.heading)
    };
    let mut j = Matrix3::zeros();
    for k in 0..3 {
        let mut d = Vector3::zeros();
        d[k] = h;
        let diff = euler(&d) - euler(&-d);
        for i in 0..3 {
            j[(i, k)] = wrap_pi(diff[i]) / (2.0 * h);
        }
    }
    j
}
