//! A navigating cycle (module docs of `navigator`, items 3 and 4): the
//! filter without the alignment's zero updates, the roll fed from the
//! accelerometers while the tool moves and held while it is still or
//! drilling, a station's zero-velocity update while it is still, the
//! moving tool's constraints otherwise, and the drilling environment's
//! noise and toolface updates (`drilling.rs`).

use super::drilling::{
    drilling_attitude_noise, vibration_onset_factor, DRILLING_JITTER_LIMIT_M_S2,
};
use super::state::{square, Navigator};
use super::stations::SURVEY_SETTLE_EPOCHS;
use crate::attitude::ToolAxisRate;
use crate::fine_alignment::{StepNoise, StepReport};
use crate::kalman::FilterScalar;
use crate::mechanization::{ImuSample, ProbeInput, ToolAxisSource};
use crate::probe_sample::ProbeSample;
use crate::protocol::frame::nav_flags;
use crate::timing::SAMPLE_INTERVAL_S;
use nalgebra::Vector3;

/// A navigating cycle's sample for the mechanization, and how its
/// tool-axis rate was found.
struct CycleInput {
    imu: ImuSample,
    /// Where the tool-axis rate came from, and what it came to.
    source: ToolAxisSource,
    tool_axis: ToolAxisRate,
    /// The navigation frame's rate in body axes it was taken against.
    frame_rate: Vector3<f64>,
}

impl<T: FilterScalar> Navigator<T> {
    /// A navigating sample; `still` as the detector judged it, `extra` the
    /// step's noise for what was not measured. Returns whether the probe
    /// was still and the sample used (a zero-velocity cycle).
    pub(super) fn navigation_sample(
        &mut self,
        sample: &ProbeSample,
        missing_gyro: Option<usize>,
        still: bool,
        extra: StepNoise,
    ) -> bool {
        let jitter = f64::from(self.still.statistics().lateral_jitter);
        let drilling = !still && jitter > DRILLING_JITTER_LIMIT_M_S2;
        let input = self.tool_axis_input(sample, still, drilling);
        // No updates past the longest station (see
        // `MAX_STATION_SAMPLES`): free navigation until it moves.
        let update = still && !self.station_capped;
        // The accelerometer biases are learned at rest only (derivation
        // sections 4f, 4l): moving, the constraints would read the
        // vibration's rectified force as bias.
        self.filter.learn_accel_bias(still);
        let report = self.navigation_step(&input.imu, still, drilling, update, jitter, extra);
        if report.sample_used && !update && !self.covariance_invalid {
            self.constrain_moving_tool();
        }
        if drilling && report.sample_used && !self.covariance_invalid {
            self.add_to_toolface_block(sample);
        } else {
            self.toolface_block.clear();
        }
        if still && !self.was_still {
            self.first_still_after_moving(sample);
        }
        if !still && !drilling && self.was_still && report.sample_used {
            self.first_move_after_still(sample);
        }
        if let (true, Some(turn)) = (drilling, self.last_roll_turn) {
            self.first_drilling_after_roll(turn);
        }
        self.keep_undetermined_heading_apart();
        self.remember_roll(&input, still);
        self.still_gyro = (update && missing_gyro.is_none()).then_some(sample.gyro);
        self.held = Some(input.imu);
        if still {
            self.flags |= nav_flags::STILL;
        }
        if report.zero_velocity.accepted > 0 {
            self.flags |= nav_flags::ZUPT_APPLIED;
            self.coasting = false;
        }
        still && report.sample_used
    }

    /// The cycle's sample with its tool-axis rate: from the accelerometer
    /// roll while the tool moves, held (the frame's rate) while it is still
    /// or drilling.
    fn tool_axis_input(&mut self, sample: &ProbeSample, still: bool, drilling: bool) -> CycleInput {
        // Drilling: the roll is held (the accelerometer roll is
        // vibration), and the roll estimator starts again after it:
        // a difference across the drilling would add the roll
        // change a second time on top of what the filter already
        // corrected through the constraints. Still: held too, as in
        // the fine alignment (`ToolAxisSource::AtRest`: a single
        // sample's roll carries its 0.3 deg of noise).
        if drilling {
            self.input = ProbeInput::new();
        }
        let source = if drilling || still {
            ToolAxisSource::AtRest
        } else {
            ToolAxisSource::AccelerometerRoll
        };
        let frame_rate = self.filter.frame_rate_in_body();
        let (imu, tool_axis) =
            self.input
                .imu_sample(&frame_rate, sample, source, SAMPLE_INTERVAL_S);
        self.filter.hold_tool_axis(source == ToolAxisSource::AtRest);
        if tool_axis == ToolAxisRate::Unavailable || drilling {
            self.flags |= nav_flags::TOOL_AXIS_RATE_INVALID;
        }
        CycleInput {
            imu,
            source,
            tool_axis,
            frame_rate,
        }
    }

    /// The filter's step: a zero-velocity update when `update`, the
    /// vibration's velocity and attitude noise when `drilling`, the error
    /// model's force always gravity's reaction, and its attitude fixed once
    /// a station has settled.
    fn navigation_step(
        &mut self,
        imu: &ImuSample,
        still: bool,
        drilling: bool,
        update: bool,
        jitter: f64,
        extra: StepNoise,
    ) -> StepReport {
        self.filter
            .set_zero_velocity(update.then_some(self.station_zupt_variance));
        let mut extra = extra;
        self.drilling_cycles = if drilling {
            self.drilling_cycles.saturating_add(1)
        } else {
            0
        };
        if drilling {
            // The measured lateral jitter is the vibration's force
            // noise per sample: white, a velocity random walk.
            let onset = vibration_onset_factor(self.drilling_cycles);
            extra.velocity += square(jitter * SAMPLE_INTERVAL_S) * onset;
        }
        // F21's force is gravity's reaction in every navigating cycle,
        // turning at rest too: the sample's force rotated by the computed
        // attitude carries the roll's error across the tool (the roll held
        // through the still detector's delay at a turn's start), and
        // [f^n x] phi then couples the heading error into the velocity
        // along the tool axis, a term the true error dynamics do not have;
        // the moving tool's constraints read heading from it (derivation
        // section 4h, seventh item). A string's true acceleration along the
        // hole (tripping, the drilling ramps) is a few hundredths of g for
        // seconds, and the heading error it would couple is left out with it.
        self.filter.linearize_at_gravity(true);
        // A still tool's attitude does not change: once the
        // station's first block has re-levelled it, the error model
        // stays linearised there instead of following each ZUPT's
        // correction (derivation section 4i). So past the longest
        // station while the detector still sees a still tool: there
        // the moving tool's constraints replace the ZUPTs, and a model
        // that followed the estimate's heading noise (the vertical
        // gyro's white noise, sample by sample) saw the constraints
        // from ever new directions and read the tilt apart from the
        // tool-axis accelerometer bias that it cannot see: the pitch
        // drifted by ~15 mdeg/h past its sigma (derivation section 5c).
        let settled = still
            && (self.station_capped
                || self
                    .station
                    .as_ref()
                    .is_some_and(|s| s.epochs >= SURVEY_SETTLE_EPOCHS));
        self.filter.fix_linearization(settled);
        let report = self.filter.step_with(imu, &extra);
        if drilling {
            self.filter
                .add_attitude_noise(&drilling_attitude_noise(self.filter.state()));
        }
        report
    }

    /// What the next cycle's roll checks need to know of this one: the
    /// roll's turn when it followed the accelerometers, and whether the
    /// tool was still.
    fn remember_roll(&mut self, input: &CycleInput, still: bool) {
        self.last_roll_turn = match (input.source, input.tool_axis) {
            (ToolAxisSource::AccelerometerRoll, ToolAxisRate::Valid(rate)) => {
                Some((rate - input.frame_rate.y) * SAMPLE_INTERVAL_S)
            }
            _ => None,
        };
        self.was_still = still;
    }
}
