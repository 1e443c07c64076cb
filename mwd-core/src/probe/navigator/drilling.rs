//! The drilling environment (derivation section 4d): when the probe is
//! taken as drilling, the vibration's attitude and velocity noise, the
//! moving tool's constraints, the held roll's toolface updates and
//! re-rolls, and the roll's variance where the tool may have turned
//! unseen (at the changes between still, moving and drilling).

use super::state::{square, Filter, Navigator};
use crate::aid_sources::{
    AxialSpeed, DrillingToolface, ForceBlock, NonHolonomic, AXIAL_SPEED_VARIANCE,
    DRILLING_VARIANCE, TOOLFACE_BLOCK_SAMPLES,
};
use crate::conventions::{dcm_from_quat, euler_from_quat, DEG};
use crate::kalman::{FilterScalar, Stacked, UpdateReport};
use crate::mechanization::NavState;
use crate::probe_sample::ProbeSample;
use crate::sensor_noise::ImuNoise;
use crate::sensor_units::STANDARD_GRAVITY;
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
pub const DRILLING_JITTER_LIMIT_M_S2: f64 = STANDARD_GRAVITY * 0.017_452_406;

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
pub const SINGLE_SAMPLE_ROLL_SIGMA_RAD: f64 = 0.058 / STANDARD_GRAVITY;

impl<T: FilterScalar> Navigator<T> {
    /// Drilling mode starts afresh (a new attitude from an alignment or a
    /// tie-in): no drilling cycles, no roll turn remembered, an empty
    /// toolface block.
    pub(super) fn forget_drilling(&mut self) {
        self.drilling_cycles = 0;
        self.last_roll_turn = None;
        self.toolface_block.clear();
    }

    /// The moving tool's constraints, one update: drilling or moving in
    /// the hole, the tool moves along its axis (derivation sections 4b,
    /// 4d). Also still past the station's end (the longest station, or the
    /// gyros saw it turn): the detector cannot tell a tool at rest from one
    /// sliding smoothly, and these hold for both; free inertial navigation
    /// there grew velocity errors of tens of m/s in an hour of a quiet
    /// slide, far outside the error model's linear range. The rows'
    /// attitude terms (v_n x r_a) are dropped: linearised at the computed
    /// velocity, which while drilling is mostly vibration noise (the true
    /// speed, the rate of penetration, is < 0.01 m/s), they would read that
    /// noise as azimuth and tilt errors; the true speed's leak through an
    /// attitude error is in the constraint's noise (the misalignment part,
    /// 0.5 m/s x 1 deg; derivation section 4d).
    pub(super) fn constrain_moving_tool(&mut self) {
        // The rows' axes at the attitude the error model is linearised
        // at (the estimate's own but on a still tool past its station:
        // `navigation_step`), so that every Jacobian sits at one point
        // (derivation section 4e).
        let state = NavState {
            attitude: self.filter.linearization_attitude(),
            ..*self.filter.state()
        };
        let mut cross = NonHolonomic::at(&state, T::of(DRILLING_VARIANCE));
        cross.attitude_row = [[T::zero(); 3]; 2];
        let mut axial = AxialSpeed::at(&state, T::of(AXIAL_SPEED_VARIANCE));
        axial.attitude_row = [T::zero(); 3];
        // One update: the axial bound's value was computed
        // at the solution before the cross-axis correction,
        // which a feedback between two updates would have
        // moved under it (`kalman::Stacked`).
        self.filter.aid(&Stacked(cross, axial));
    }

    /// A drilling sample's force into the toolface block; a full block is
    /// one toolface update ([`aid_drilling_toolface`]).
    pub(super) fn add_to_toolface_block(&mut self, sample: &ProbeSample) {
        self.toolface_block.add(&sample.specific_force);
        if self.toolface_block.samples() >= TOOLFACE_BLOCK_SAMPLES {
            aid_drilling_toolface(&mut self.filter, &self.toolface_block, self.noise);
            self.toolface_block.clear();
        }
    }

    /// The first still cycle after the tool moved or drilled: no gyro
    /// senses the roll. Drilling held it, so the orienter's steps were not
    /// sensed; a turn at rest followed the accelerometer roll's
    /// differences, whose rate lags the turn by a sample, so the roll
    /// overshoots where the turn stops (0.25 deg at the orienter's 10
    /// deg/s, twelve times the roll sigma the turn's constraint updates
    /// left; a toolface-indexed connection's second dwell then read it as
    /// heading and tilt: derivation section 4h). The accelerometer roll
    /// shows how far off the roll is; that, with the sample's own roll
    /// noise, goes into the variance about the tool axis, and the
    /// station's zero-velocity updates re-level it.
    pub(super) fn first_still_after_moving(&mut self, sample: &ProbeSample) {
        let offset = roll_offset(self.filter.state(), sample);
        let variance = square(offset) + square(SINGLE_SAMPLE_ROLL_SIGMA_RAD);
        add_tool_axis_variance(&mut self.filter, variance);
    }

    /// The first moving cycle after a still period: the
    /// roll was held through the still detector's delay
    /// while the orienter may already have been turning the
    /// tool (0.5 deg in the simulated connections, 15 times
    /// the station's roll sigma), and from here the roll
    /// follows the accelerometer roll's differences, so its
    /// error stays that offset plus the difference of two
    /// samples' roll noise. Unmodelled, the velocity it
    /// makes went through the non-holonomic updates into
    /// the heading (up to 8 deg per connection in the
    /// drilling study; derivation section 4h).
    pub(super) fn first_move_after_still(&mut self, sample: &ProbeSample) {
        let offset = roll_offset(self.filter.state(), sample);
        let variance = square(offset) + 2.0 * square(SINGLE_SAMPLE_ROLL_SIGMA_RAD);
        add_tool_axis_variance(&mut self.filter, variance);
    }

    /// The first drilling cycle after the roll followed the
    /// accelerometers (by `turn`, rad, in the last cycle): the roll is
    /// held from here, and the vibration that made this a drilling cycle
    /// may have begun before the orienter's turn ended. The turn of
    /// one cycle is estimated by the last one's (noisy by
    /// the two samples' roll noise, which is added too).
    pub(super) fn first_drilling_after_roll(&mut self, turn: f64) {
        let variance = square(turn) + 2.0 * square(SINGLE_SAMPLE_ROLL_SIGMA_RAD);
        add_tool_axis_variance(&mut self.filter, variance);
    }

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
fn roll_offset(state: &NavState, sample: &ProbeSample) -> f64 {
    let levelling = crate::attitude::level(&sample.specific_force);
    if !levelling.roll_valid {
        return 0.0;
    }
    let roll = euler_from_quat(&state.attitude).roll;
    crate::conventions::wrap_pi(levelling.roll - roll)
}
