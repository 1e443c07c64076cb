//! The fine alignment's settings: how the AR states and the tilt start,
//! which specific force linearises the model, the process and measurement
//! noise ([`FineAlignmentConfig`]: the paper's or scaled to the sensors'
//! budget), and how the bias states walk ([`BiasWalk`]).

use crate::conventions::DEG;
use crate::earth::{normal_gravity, EARTH_RATE};
use crate::error_model::{
    is_model_size, AugmentedModel, ProcessNoise, ACCEL_BIAS, ATT, NAV_STATES, STATES,
    STATES_WITH_BIASES,
};
use crate::kalman::FilterScalar;
use crate::mechanization::NavState;
use crate::sensor_noise::ImuNoise;
use nalgebra::{Matrix3, SMatrix};

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

/// Adds to `p0` what levelling with biased accelerometers puts into the
/// tilt: phi_h = M b with M = (1/g) [row E of C_b^n; -row N of C_b^n]
/// (derivation section 3b), so P(phi_h) += M S M^T and P(phi_h, b) = M S,
/// S the accelerometer bias block. With the levelling noise N already on
/// the tilt diagonal this is [I M; 0 I] blockdiag(N, S) [I M; 0 I]^T:
/// positive semi-definite by construction.
pub(super) fn add_levelling_bias_correlation<T: FilterScalar, const N: usize>(
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
