//! The drilling environment (derivation section 4d): when the probe is
//! taken as drilling, the vibration's attitude and velocity noise, the
//! held roll's toolface updates and re-rolls, the non-holonomic update on
//! request, and the roll's variance where the tool may have turned unseen.

use super::state::{square, Filter, Navigator};
use crate::aid_sources::{DrillingToolface, ForceBlock, NonHolonomic, DRILLING_VARIANCE};
use crate::conventions::{dcm_from_quat, euler_from_quat, DEG};
use crate::kalman::{FilterScalar, UpdateReport};
use crate::mechanization::NavState;
use crate::probe_sample::ProbeSample;
use crate::sensor_noise::ImuNoise;
use crate::timing::SAMPLE_INTERVAL_S;
use nalgebra::{Matrix3, Vector3};

/// The lateral force jitter (m/s^2, `StillStatistics::lateral_jitter`)
/// above which the probe is taken as drilling (on bottom, vibrating):
/// g sin(1 deg). Above it a single sample's accelerometer roll is off by
/// more than 1 deg, and the roll-derived tool-axis rate (paper eq. 1-2)
/// would put that noise into the attitude every sample (and rectify it into
/// a vertical force: the force is rolled onto the vertical); the roll is
/// then held (`ToolAxisSource::AtRest`) and its possible change is process
/// noise ([`DRILLING_TOOLFACE_VARIANCE_PER_S`]). The SCC1300's own noise
/// is ~0.06 m/s^2 per sample; a 10 deg/s toolface turn adds 0.085 m/s^2
/// per sample to the differences; the moderate simulated vibration is
/// ~7 m/s^2 (docs/filter-derivation.md section 4d).
pub const DRILLING_JITTER_LIMIT_M_S2: f64 = 9.80665 * 0.017_452_406;

/// Angular vibration reaching a gyro sample while drilling (rad/s, 1-sigma
/// per sample, white): the drilling simulator's moderate level, 1 deg/s RMS
/// over 5-500 Hz through the part's assumed 50 Hz first-order low-pass,
/// which passes 0.1385 of the power (docs/drilling-simulation.md): 0.372
/// deg/s, an attitude random walk of 5.0 deg/sqrt(h) about the gyro axes.
pub const DRILLING_ANGULAR_SIGMA_RAD_S: f64 = 0.372 * DEG;

/// Variance rate (rad^2/s) of the toolface while the roll is held: the
/// orienter's steps while sliding, 10 deg once an hour (the simulator's
/// `sliding_toolface_step_deg`, `sliding_toolface_steps_per_hour`), taken
/// as a random walk of 100 deg^2/h about the tool axis.
pub const DRILLING_TOOLFACE_VARIANCE_PER_S: f64 = 100.0 * DEG * DEG / 3600.0;

/// One still sample's accelerometer roll noise (rad): the SCC1300's x
/// accelerometer noise, 0.058 m/s^2 per sample (paper Table 4), over g.
pub const SINGLE_SAMPLE_ROLL_SIGMA_RAD: f64 = 0.058 / 9.80665;

impl<T: FilterScalar> Navigator<T> {
    /// One non-holonomic update at the current solution (no velocity
    /// across the tool axis, `aid_sources::NonHolonomic`, with the drilling
    /// BHA's noise [`DRILLING_VARIANCE`]), for the caller that knows the
    /// tool is drilling; call it between steps (the next frame shows it).
    /// Only while navigating with a valid covariance; `None` otherwise.
    pub fn apply_non_holonomic(&mut self) -> Option<UpdateReport> {
        if !self.is_navigating() || self.covariance_invalid {
            return None;
        }
        let constraint = NonHolonomic::at(self.filter.state(), T::of(DRILLING_VARIANCE));
        Some(self.filter.aid(&constraint))
    }
}

/// How much the still detector's jitter (the RMS of the successive force
/// differences over its window, `StillStatistics::lateral_jitter`)
/// understates the vibration in the `k`-th drilling cycle after it began:
/// the window's WINDOW - 1 differences then hold k - 1 between vibrating
/// samples and one half-vibrating (the first one), k - 1/2 in all; the
/// variance is scaled up by their share. Unscaled, the first drilling
/// samples' vibration (0.36 m/s per sample at the moderate level) went
/// into the velocity with a twentieth of its variance, and the
/// non-holonomic updates turned it into heading through the velocity's
/// correlation with it (1.3 deg in 0.3 s in the simulated lateral;
/// derivation section 4h).
pub(super) fn vibration_onset_factor(k: u32) -> f64 {
    let differences = (crate::probe::still::WINDOW - 1) as f64;
    let vibrating = f64::from(k.max(1)) - 0.5;
    (differences / vibrating).max(1.0)
}
/// The drilling environment's attitude noise for one step, nav frame
/// (derivation section 4d): the angular vibration about the gyro axes
/// (body x and z: (I - t t^T) sigma^2 dt^2, t the tool axis) and the
/// orienter's unsensed toolface steps about the tool axis (t t^T q dt).
pub(super) fn drilling_attitude_noise(state: &NavState) -> Matrix3<f64> {
    let c_bn = dcm_from_quat(&state.attitude);
    let t: Vector3<f64> = c_bn.column(1).into_owned();
    let tt = t * t.transpose();
    let vibration = square(DRILLING_ANGULAR_SIGMA_RAD_S * SAMPLE_INTERVAL_S);
    (Matrix3::identity() - tt) * vibration
        + tt * (DRILLING_TOOLFACE_VARIANCE_PER_S * SAMPLE_INTERVAL_S)
}

/// A drilling toolface innovation beyond this many sigma (squared) is not
/// a small-angle error: the driller turned the toolface on bottom, and the
/// roll is set to the block's instead of updated towards it.
const GROSS_TOOLFACE_CHI2: f64 = 16.0;

/// The toolface of one block of drilling samples against the held roll
/// (`aid_sources::DrillingToolface`, derivation section 4g): an update, or
/// when the roll is grossly off (a toolface turned on bottom) the block's
/// roll with its variance about the tool axis.
pub(super) fn aid_drilling_toolface<T: FilterScalar>(
    filter: &mut Filter<T>,
    block: &ForceBlock,
    noise: &ImuNoise,
) {
    let budget = noise.accel[0];
    let bias_variance = square(budget.residual_bias) + square(budget.bias_instability);
    let Some(m) = DrillingToolface::<T>::at(filter.state(), block, bias_variance) else {
        return;
    };
    let h = Vector3::from(m.attitude_row.map(T::as_f64));
    let variance = m.variance.as_f64();
    let innovation_variance = h.dot(&(filter.attitude_error_covariance() * h)) + variance;
    if square(m.toolface_residual.as_f64()) > GROSS_TOOLFACE_CHI2 * innovation_variance {
        filter.set_roll(m.block_toolface);
        add_tool_axis_variance(filter, variance);
    } else {
        filter.aid(&m);
    }
}

/// Adds `variance` (rad^2) to the attitude error about the tool axis (the
/// roll): the roll the filter holds or follows may be off by more than its
/// covariance says (an orienter's turn not sensed, a re-roll).
pub(super) fn add_tool_axis_variance<T: FilterScalar>(filter: &mut Filter<T>, variance: f64) {
    let c_bn = dcm_from_quat(&filter.state().attitude);
    let t: Vector3<f64> = c_bn.column(1).into_owned();
    filter.add_attitude_noise(&(t * t.transpose() * variance));
}

/// The accelerometer roll of `sample` less the solution's roll (rad,
/// wrapped; 0 where the roll is not defined: tool near vertical).
pub(super) fn roll_offset(state: &NavState, sample: &ProbeSample) -> f64 {
    let levelling = crate::attitude::level(&sample.specific_force);
    if !levelling.roll_valid {
        return 0.0;
    }
    let roll = euler_from_quat(&state.attitude).roll;
    crate::conventions::wrap_pi(levelling.roll - roll)
}
