//! One cycle: the navigator's entry points (through [`NavigatorScalar`],
//! compiled in this crate), a raw sample's calibration, its way to the
//! phase the navigator is in, and a gap's coasting (module docs of
//! `navigator`: what the frames say).

use super::commands::Refusal;
use super::drilling::{
    add_tool_axis_variance, aid_drilling_toolface, drilling_attitude_noise, roll_offset,
    vibration_onset_factor, DRILLING_JITTER_LIMIT_M_S2, SINGLE_SAMPLE_ROLL_SIGMA_RAD,
};
use super::frame::VARIANCE_LIMIT;
use super::state::{square, Navigator, Phase};
use super::stations::SURVEY_SETTLE_EPOCHS;
use crate::aid_sources::{
    AxialSpeed, NonHolonomic, AXIAL_SPEED_VARIANCE, DRILLING_VARIANCE, TOOLFACE_BLOCK_SAMPLES,
};
use crate::attitude::ToolAxisRate;
use crate::conventions::DEG;
use crate::fine_alignment::StepNoise;
use crate::kalman::{FilterScalar, Stacked};
use crate::mechanization::{ProbeInput, ToolAxisSource};
use crate::probe::raw::{reading, Reading};
use crate::probe::tie_in::TieIn;
use crate::probe_sample::{ProbeSample, GYRO_AXES};
use crate::protocol::frame::nav_flags;
use crate::protocol::{NavSolution, RawSample};
use crate::timing::{ALIGNMENT_SAMPLES, FINE_ALIGNMENT_SAMPLES, SAMPLE_INTERVAL_S};

/// The rate (rad/s) a sample the probe did not measure may be off by: a
/// gap's held rate, or the missing gyro's stand-in in single-part mode.
/// 1 deg/s: the rate changes of a still or slowly turning tool over the
/// ~1-2 s a driver recovery takes; its variance goes into the attitude
/// process noise (docs/filter-derivation.md, "Sensor gaps").
pub const UNMEASURED_RATE_SIGMA: f64 = 1.0 * DEG;

/// The specific force (m/s^2) a held sample may be off by: 0.1 m/s^2,
/// about 10 mg, ten times the accelerometers' per-sample noise.
pub const UNMEASURED_FORCE_SIGMA: f64 = 0.1;

/// The navigator's public entry points that run its filter. Each forwards
/// to [`NavigatorScalar`], whose implementations below are compiled in this
/// crate (see there).
impl<T: NavigatorScalar> Navigator<T> {
    /// Takes one raw sample and returns the solution after it.
    pub fn step(&mut self, raw: &RawSample) -> NavSolution {
        T::step(self, raw)
    }

    /// Takes one calibrated body-frame sample of both parts (the host's
    /// studies of gyros other than the SCC1300, whose readings do not fit
    /// the SCC1300's raw counts: 18 LSB per deg/s would round a
    /// navigation-grade gyro's earth rate away) and returns the solution.
    pub fn step_sample(
        &mut self,
        time_us: u64,
        sample_counter: u32,
        sample: &ProbeSample,
    ) -> NavSolution {
        T::step_sample(self, time_us, sample_counter, sample)
    }

    /// Ties the navigation in to the parent well's survey at the window
    /// (`crate::probe::tie_in`, derivation section 4c).
    ///
    /// A probe that has levelled itself (navigating: called between steps
    /// as soon as [`is_navigating`](Self::is_navigating) first returns true)
    /// keeps its filter: the azimuth is replaced by the tie-in's (a turn
    /// about the vertical; the heading error is then the tie-in's alone),
    /// and the tie-in's inclination and toolface are fused with its own
    /// levelling as measurements
    /// ([`TieInTilt`](crate::probe::tie_in::TieInTilt)), so the levelled tilt keeps
    /// its correlation with the accelerometer biases it was levelled with.
    /// (Putting the tie-in's tilt in place of that, as independent, left the
    /// window station's toolface 4 times outside its sigma in the coverage
    /// study: the accelerometer bias went into the toolface unseen.)
    /// Before that (or with an invalid covariance) the filter starts again
    /// from the tie-in's attitude and sigmas, independent of the sensor
    /// states, with no zero updates. Drilling mode and stations start
    /// afresh.
    pub fn start_from_tie_in(&mut self, tie_in: &TieIn) {
        T::start_from_tie_in(self, tie_in)
    }

    /// Uplink "start surveying": ends the fine alignment now (see
    /// `commands`' notes). `Ok` when the probe navigates after it.
    pub fn start_surveying(&mut self) -> Result<(), Refusal> {
        T::start_surveying(self)
    }
}

/// A scalar the navigator's filter runs in: f32 on the probe, f64 in the
/// host's studies (`FilterScalar`). Its functions are the navigator's
/// entry points that run the filter, implemented below for each scalar:
/// Rust compiles a generic function in the crate that calls it, and the
/// firmware's own build of the f32 filter came out 27 KB larger and 3 %
/// slower per cycle than this crate's (docs/budgets.md). Implemented
/// (concretely, not generically) here, their code is this crate's.
/// Sealed: only f32 and f64.
pub trait NavigatorScalar: FilterScalar + sealed::Sealed {
    /// [`Navigator::step`].
    fn step(navigator: &mut Navigator<Self>, raw: &RawSample) -> NavSolution;
    /// [`Navigator::step_sample`].
    fn step_sample(
        navigator: &mut Navigator<Self>,
        time_us: u64,
        sample_counter: u32,
        sample: &ProbeSample,
    ) -> NavSolution;
    /// [`Navigator::start_from_tie_in`].
    fn start_from_tie_in(navigator: &mut Navigator<Self>, tie_in: &TieIn);
    /// [`Navigator::start_surveying`].
    fn start_surveying(navigator: &mut Navigator<Self>) -> Result<(), Refusal>;
}

mod sealed {
    pub trait Sealed {}
    impl Sealed for f32 {}
    impl Sealed for f64 {}
}

macro_rules! navigator_scalar {
    ($($scalar:ty),+) => {$(
        impl NavigatorScalar for $scalar {
            fn step(navigator: &mut Navigator<Self>, raw: &RawSample) -> NavSolution {
                navigator.step_raw(raw)
            }
            fn step_sample(
                navigator: &mut Navigator<Self>,
                time_us: u64,
                sample_counter: u32,
                sample: &ProbeSample,
            ) -> NavSolution {
                navigator.step_calibrated(time_us, sample_counter, sample)
            }
            fn start_from_tie_in(navigator: &mut Navigator<Self>, tie_in: &TieIn) {
                navigator.tie_in(tie_in)
            }
            fn start_surveying(navigator: &mut Navigator<Self>) -> Result<(), Refusal> {
                navigator.start_surveying_now()
            }
        }
    )+};
}

navigator_scalar!(f32, f64);

impl<T: FilterScalar> Navigator<T> {
    pub(super) fn step_raw(&mut self, raw: &RawSample) -> NavSolution {
        let reading = reading(raw, &self.calibration);
        self.step_reading(raw.time_us, raw.sample_counter, reading)
    }

    pub(super) fn step_calibrated(
        &mut self,
        time_us: u64,
        sample_counter: u32,
        sample: &ProbeSample,
    ) -> NavSolution {
        self.step_reading(time_us, sample_counter, Reading::Both(*sample))
    }

    fn step_reading(&mut self, time_us: u64, sample_counter: u32, reading: Reading) -> NavSolution {
        self.flags = 0;
        self.time_us = time_us;
        self.sample_counter = sample_counter;
        let still = match reading {
            Reading::Both(sample) => self.use_sample(&sample, None),
            Reading::Single {
                sample,
                missing_gyro,
            } => {
                self.flags |= nav_flags::SENSOR_DEGRADED | nav_flags::SINGLE_PART;
                self.use_sample(&sample, Some(missing_gyro))
            }
            // No valid data: the alignment waits, the filter coasts.
            Reading::Neither => {
                self.flags |= nav_flags::SENSOR_DEGRADED;
                self.coast();
                self.is_navigating().then_some(false)
            }
        };
        if self.is_aligned() && !self.covariance_invalid {
            let limit = T::of(f64::from(VARIANCE_LIMIT));
            self.covariance_invalid = !self.filter.filter().covariance_is_healthy(limit);
        }
        if let Some(still) = still {
            self.track_station(still);
            self.follow_commands(still);
        }
        // After the station's updates, which the frame reports; a station
        // finished above judges its own sigma against the limit.
        let attitude_std = self.attitude_std();
        if let Some(std) = &attitude_std {
            self.note_heading_loss(std.z);
        }
        self.solution(time_us, sample_counter, attitude_std)
    }

    /// `sample`, with the gyro of index `missing_gyro` (in `GYRO_AXES`)
    /// out when one part is. Returns, when navigating, whether the probe
    /// was still (a zero-velocity update was made).
    fn use_sample(&mut self, sample: &ProbeSample, missing_gyro: Option<usize>) -> Option<bool> {
        let mut sample = *sample;
        let mut coarse_done = None;
        let mut fine_done = false;
        let mut navigating_still = None;
        let gap_ended = self.missed > 0;
        self.missed = 0;
        if gap_ended {
            // The roll-derived tool-axis rate would difference rolls a gap
            // apart and count the held rate's turn twice: it starts again.
            self.input = ProbeInput::new();
        }
        // Judged on the sample as measured (before the missing gyro's
        // stand-in): with one part out a turn about its axis would not be
        // seen, so stillness is judged on full samples only. Judged in the
        // fine alignment too, so a probe still at its end navigates on as
        // still from the first cycle: before, the detector's 1.95 s delay
        // made those cycles "moving", whose roll follows the accelerometer
        // roll (~0.3 deg of noise per sample) while its sigma stayed the
        // levelling's 0.06 deg; the rate gyrocompass then read the
        // unmodelled roll error (a tilt of the vertical earth rate into
        // the x and z gyros) as heading and inclination: the window
        // station's inclination came out 0.085 deg RMS against a 0.047 deg
        // sigma with a navigation-grade gyro (docs/lateral-study.md).
        let still = match (&self.phase, missing_gyro) {
            (Phase::Fine { .. } | Phase::Navigating, None) => self.still.update(&sample),
            _ => {
                self.still.reset();
                false
            }
        };
        let filter = &mut self.filter;
        // The missing gyro's stand-in: the rate of a tool turning with the
        // navigation frame (a still tool), uncertain by
        // `UNMEASURED_RATE_SIGMA` each step.
        let extra = match missing_gyro {
            None => StepNoise::NONE,
            Some(k) => {
                let frame_rate = filter.frame_rate_in_body();
                sample.gyro[k] = frame_rate[GYRO_AXES[k]];
                StepNoise {
                    attitude: square(UNMEASURED_RATE_SIGMA * SAMPLE_INTERVAL_S),
                    velocity: 0.0,
                    skip_updates: false,
                }
            }
        };
        match &mut self.phase {
            Phase::Coarse(sums) => {
                self.coarse_single_part |= missing_gyro.is_some();
                sums.add(&sample);
                if sums.samples() >= ALIGNMENT_SAMPLES as usize {
                    coarse_done = Some(sums.segment());
                }
            }
            Phase::Fine { samples } => {
                let (imu, _) = self.input.imu_sample(
                    &filter.frame_rate_in_body(),
                    &sample,
                    ToolAxisSource::AtRest,
                    SAMPLE_INTERVAL_S,
                );
                let report = filter.step_with(&imu, &extra);
                self.held = Some(imu);
                if report.zero_velocity.accepted > 0 {
                    self.flags |= nav_flags::ZUPT_APPLIED;
                    self.coasting = false;
                }
                *samples += 1;
                fine_done = *samples >= FINE_ALIGNMENT_SAMPLES;
            }
            Phase::Navigating => {
                let jitter = f64::from(self.still.statistics().lateral_jitter);
                let drilling = !still && jitter > DRILLING_JITTER_LIMIT_M_S2;
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
                let frame_rate = filter.frame_rate_in_body();
                let (imu, tool_axis) =
                    self.input
                        .imu_sample(&frame_rate, &sample, source, SAMPLE_INTERVAL_S);
                filter.hold_tool_axis(source == ToolAxisSource::AtRest);
                if tool_axis == ToolAxisRate::Unavailable || drilling {
                    self.flags |= nav_flags::TOOL_AXIS_RATE_INVALID;
                }
                // No updates past the longest station (see
                // `MAX_STATION_SAMPLES`): free navigation until it moves.
                let update = still && !self.station_capped;
                filter.set_zero_velocity(update.then_some(self.station_zupt_variance));
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
                filter.linearize_at_gravity(drilling || still);
                // A still tool's attitude does not change: once the
                // station's first block has re-levelled it, the error model
                // stays linearised there instead of following each ZUPT's
                // correction (derivation section 4i).
                let settled = still
                    && self
                        .station
                        .as_ref()
                        .is_some_and(|s| s.epochs >= SURVEY_SETTLE_EPOCHS);
                filter.fix_linearization(settled);
                let report = filter.step_with(&imu, &extra);
                if drilling {
                    filter.add_attitude_noise(&drilling_attitude_noise(filter.state()));
                }
                if report.sample_used && !update && !self.covariance_invalid {
                    // Drilling or moving in the hole: the tool moves along
                    // its axis (derivation sections 4b, 4d). Also still
                    // past the station's end (the longest station, or the
                    // gyros saw it turn): the detector cannot tell a tool
                    // at rest from one sliding smoothly, and these hold
                    // for both; free inertial navigation there grew
                    // velocity errors of tens of m/s in an hour of a quiet
                    // slide, far outside the error model's linear range.
                    // The rows' attitude terms (v_n x r_a) are dropped:
                    // linearised at the computed velocity, which while
                    // drilling is mostly vibration noise (the true speed,
                    // the rate of penetration, is < 0.01 m/s), they would
                    // read that noise as azimuth and tilt errors; the true
                    // speed's leak through an attitude error is in the
                    // constraint's noise (the misalignment part, 0.5 m/s x
                    // 1 deg; derivation section 4d).
                    let state = filter.state();
                    let mut cross = NonHolonomic::at(state, T::of(DRILLING_VARIANCE));
                    cross.attitude_row = [[T::zero(); 3]; 2];
                    let mut axial = AxialSpeed::at(state, T::of(AXIAL_SPEED_VARIANCE));
                    axial.attitude_row = [T::zero(); 3];
                    // One update: the axial bound's value was computed
                    // at the solution before the cross-axis correction,
                    // which a feedback between two updates would have
                    // moved under it (`kalman::Stacked`).
                    filter.aid(&Stacked(cross, axial));
                }
                if drilling && report.sample_used && !self.covariance_invalid {
                    self.toolface_block.add(&sample.specific_force);
                    if self.toolface_block.samples() >= TOOLFACE_BLOCK_SAMPLES {
                        aid_drilling_toolface(filter, &self.toolface_block, self.noise);
                        self.toolface_block.clear();
                    }
                } else {
                    self.toolface_block.clear();
                }
                if still && self.drilled_since_station {
                    // The first still cycle after drilling: the roll was
                    // held through it, so the orienter's steps were not
                    // sensed. The accelerometer roll shows how far off the
                    // held roll is; that, with the sample's own roll noise,
                    // goes into the variance about the tool axis, and the
                    // station's zero-velocity updates re-level it.
                    let offset = roll_offset(filter.state(), &sample);
                    let variance = square(offset) + square(SINGLE_SAMPLE_ROLL_SIGMA_RAD);
                    add_tool_axis_variance(filter, variance);
                    // The accelerometer biases as the last station (at rest)
                    // left them: while drilling the filter read the
                    // vibration's rectified force as bias, and at rest
                    // that bias is inseparable from the tilt the station
                    // measures, so it would go straight into the toolface
                    // (seen in the simulated lateral: 0.10-0.15 deg of
                    // toolface error, the same sign in every seed, against
                    // 0.035-deg sigmas).
                    if let Some(snapshot) = &self.rest_accel_bias {
                        filter.restore_accel_bias(snapshot);
                    }
                    self.drilled_since_station = false;
                }
                if !still && !drilling && self.was_still && report.sample_used {
                    // The first moving cycle after a still period: the
                    // roll was held through the still detector's delay
                    // while the orienter may already have been turning the
                    // tool (0.5 deg in the simulated connections, 15 times
                    // the station's roll sigma), and from here the roll
                    // follows the accelerometer roll's differences, so its
                    // error stays that offset plus the difference of two
                    // samples' roll noise. Unmodelled, the velocity it
                    // makes went through the non-holonomic updates into
                    // the heading (up to 8 deg per connection in the
                    // drilling study; derivation section 4h).
                    let offset = roll_offset(filter.state(), &sample);
                    let variance = square(offset) + 2.0 * square(SINGLE_SAMPLE_ROLL_SIGMA_RAD);
                    add_tool_axis_variance(filter, variance);
                }
                if let (true, Some(turn)) = (drilling, self.last_roll_turn) {
                    // The first drilling cycle after the roll followed the
                    // accelerometers: the roll is held from here, and the
                    // vibration that made this a drilling cycle may have
                    // begun before the orienter's turn ended. The turn of
                    // one cycle is estimated by the last one's (noisy by
                    // the two samples' roll noise, which is added too).
                    let variance = square(turn) + 2.0 * square(SINGLE_SAMPLE_ROLL_SIGMA_RAD);
                    add_tool_axis_variance(filter, variance);
                }
                self.last_roll_turn = match (source, tool_axis) {
                    (ToolAxisSource::AccelerometerRoll, ToolAxisRate::Valid(rate)) => {
                        Some((rate - frame_rate.y) * SAMPLE_INTERVAL_S)
                    }
                    _ => None,
                };
                self.was_still = still;
                self.drilled_since_station |= drilling;
                if still && !self.drilled_since_station {
                    self.rest_accel_bias = filter.accel_bias();
                }
                self.still_gyro = (update && missing_gyro.is_none()).then_some(sample.gyro);
                self.held = Some(imu);
                if still {
                    self.flags |= nav_flags::STILL;
                }
                if report.zero_velocity.accepted > 0 {
                    self.flags |= nav_flags::ZUPT_APPLIED;
                    self.coasting = false;
                }
                navigating_still = Some(still && report.sample_used);
            }
        }
        if let Some(segment) = coarse_done {
            // A single part in the coarse alignment: its gyro alone cannot
            // gyrocompass.
            self.finish_coarse_alignment(&segment, !self.coarse_single_part);
        }
        if fine_done {
            self.enter_navigation();
        }
        navigating_still
    }

    /// A sample with no valid data: after the coarse alignment the filter
    /// propagates the last sample it took (held rates and force: exact for
    /// a steady turn), with the held values' possible error as process
    /// noise, fully correlated over the gap (the same held value every
    /// step: the k-th missed step adds (2k - 1) sigma^2 dt^2, so k steps
    /// hold (k sigma dt)^2), and no zero update.
    fn coast(&mut self) {
        let Some(held) = self.held else {
            return;
        };
        if matches!(self.phase, Phase::Coarse(_)) {
            return;
        }
        self.missed = self.missed.saturating_add(1);
        // A gap ends any still period: stillness was not seen (and the
        // step below makes no zero update).
        self.still.reset();
        let growth = f64::from(2 * self.missed.min(1 << 20) - 1);
        let extra = StepNoise {
            attitude: growth * square(UNMEASURED_RATE_SIGMA * SAMPLE_INTERVAL_S),
            velocity: growth * square(UNMEASURED_FORCE_SIGMA * SAMPLE_INTERVAL_S),
            skip_updates: true,
        };
        self.filter.step_with(&held, &extra);
        self.coasting = true;
    }
}
