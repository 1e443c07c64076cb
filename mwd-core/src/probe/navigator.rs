//! The probe's navigation, run by its main loop (lower priority than
//! acquisition):
//! raw samples in, navigation-solution frames out. The probe must first be
//! still:
//! 1. coarse alignment: the first 5 s of samples are averaged, levelled and
//!    gyrocompassed (`crate::alignment`);
//! 2. fine alignment: the 39-state filter (33 AR-augmented states of the
//!    paper plus six sensor biases) with zero-velocity and zero-position
//!    updates, closed loop, until 60 s (the paper's test length), with the
//!    settings scaled to the SCC1300's error budget
//!    (`FineAlignmentConfig::physical`, the same the host's `paper mgwd`
//!    runs);
//! 3. navigation: the same filter without the zero updates, so the
//!    mechanization runs on (bias estimates still compensated through the
//!    filter's dynamics) and the reported uncertainties grow honestly.
//!
//! Every sample first goes through the probe's calibration (the host's
//! six-position result, [`crate::calibration`]). The host replays the same
//! raw frames through this same code and must get the probe's solutions
//! bit for bit.

use super::raw::body_sample;
use crate::alignment::{gyrocompass, level_segment, AlignmentConfig, SegmentSums, StaticSegment};
use crate::attitude::ToolAxisRate;
use crate::calibration::ProbeCalibration;
use crate::conventions::{euler_from_quat, quat_from_euler, Euler};
use crate::earth::Position;
use crate::error_model::{AugmentedModel, POS, STATES_WITH_BIASES, VEL};
use crate::fine_alignment::{FineAlignment, FineAlignmentConfig};
use crate::mechanization::{NavState, ProbeInput, ToolAxisSource};
use crate::probe_sample::ProbeSample;
use crate::protocol::frame::nav_flags;
use crate::protocol::frame::nav_mode;
use crate::protocol::{NavSolution, RawSample};
use crate::sensor_noise::ImuNoise;
use crate::timing::{ALIGNMENT_SAMPLES, FINE_ALIGNMENT_SAMPLES, SAMPLE_INTERVAL_S};
use nalgebra::UnitQuaternion;

/// The probe's filter: f32 (the M4F's FPU), 39 states.
type Filter = FineAlignment<f32, STATES_WITH_BIASES>;

/// The filter's settings for a still probe at `position` whose coarse
/// alignment has 1-sigma `coarse_sigma` (roll, pitch, heading; rad).
fn filter_config(
    position: &Position,
    coarse_sigma: &[f64; 3],
) -> FineAlignmentConfig<STATES_WITH_BIASES> {
    FineAlignmentConfig::physical(
        AugmentedModel::paper(),
        &ImuNoise::scc1300(),
        coarse_sigma,
        position.lat,
    )
}

enum Phase {
    /// Summing still samples.
    Coarse(SegmentSums),
    /// The filter with zero updates; `samples` taken so far.
    Fine { samples: u32 },
    /// The filter without zero updates.
    Navigating,
}

/// The probe's navigation, one raw sample at a time.
pub struct Navigator {
    position: Position,
    calibration: ProbeCalibration,
    phase: Phase,
    /// Idle until the coarse alignment ends, then restarted in place from
    /// it: the filter is the probe's largest object (6 KiB of covariance),
    /// and every move of it would be another copy on the stack.
    filter: Filter,
    /// The mechanization's input (the tool-axis rate's estimator).
    input: ProbeInput,
    /// 1-sigma of roll, pitch, heading from the coarse alignment (rad),
    /// reported until the filter has its own. An infinite heading sigma
    /// (no heading found) stays in the frames afterwards: the filter then
    /// runs from its best guess with its largest prior, but its small-angle
    /// azimuth sigma would not cover the error.
    coarse_std: [f32; 3],
    flags: u16,
}

impl Navigator {
    /// A navigator for a probe at `position` with uncalibrated sensors.
    pub fn new(position: Position) -> Self {
        Self::with_calibration(position, ProbeCalibration::default())
    }

    /// A navigator that corrects every sample with `calibration`.
    pub fn with_calibration(position: Position, calibration: ProbeCalibration) -> Self {
        let idle = NavState::at_rest(UnitQuaternion::identity(), position);
        Self {
            position,
            calibration,
            phase: Phase::Coarse(SegmentSums::default()),
            filter: Filter::new(idle, position, filter_config(&position, &[0.0; 3])),
            input: ProbeInput::new(),
            coarse_std: [f32::NAN; 3],
            flags: 0,
        }
    }

    /// Takes one raw sample and returns the solution after it.
    pub fn step(&mut self, raw: &RawSample) -> NavSolution {
        let sample = body_sample(raw, &self.calibration);
        self.flags = if sample.is_none() {
            nav_flags::SENSOR_DEGRADED
        } else {
            0
        };
        // A sample without valid data: the alignment waits, the navigation
        // coasts (the state is left as it is and flagged).
        if let Some(sample) = sample {
            self.use_sample(&sample);
        }
        self.solution(raw)
    }

    fn use_sample(&mut self, sample: &ProbeSample) {
        let mut coarse_done = None;
        let mut fine_done = false;
        let filter = &mut self.filter;
        match &mut self.phase {
            Phase::Coarse(sums) => {
                sums.add(sample);
                if sums.samples() >= ALIGNMENT_SAMPLES as usize {
                    coarse_done = Some(sums.segment());
                }
            }
            Phase::Fine { samples } => {
                let (imu, _) = self.input.imu_sample(
                    &filter.frame_rate_in_body(),
                    sample,
                    ToolAxisSource::AtRest,
                    SAMPLE_INTERVAL_S,
                );
                let report = filter.step(&imu);
                if report.zero_velocity.accepted > 0 {
                    self.flags |= nav_flags::ZUPT_APPLIED;
                }
                *samples += 1;
                fine_done = *samples >= FINE_ALIGNMENT_SAMPLES;
            }
            Phase::Navigating => {
                let (imu, tool_axis) = self.input.imu_sample(
                    &filter.frame_rate_in_body(),
                    sample,
                    ToolAxisSource::AccelerometerRoll,
                    SAMPLE_INTERVAL_S,
                );
                if tool_axis == ToolAxisRate::Unavailable {
                    self.flags |= nav_flags::TOOL_AXIS_RATE_INVALID;
                }
                filter.step(&imu);
            }
        }
        if let Some(segment) = coarse_done {
            self.finish_coarse_alignment(&segment);
        }
        if fine_done {
            self.filter.start_navigation();
            // The roll-derived tool-axis rate starts from this sample on.
            self.input = ProbeInput::new();
            self.phase = Phase::Navigating;
        }
    }

    fn finish_coarse_alignment(&mut self, segment: &StaticSegment) {
        let config = AlignmentConfig::probe(self.position.lat);
        let (roll, pitch, roll_pitch_std) = match level_segment(segment, &config) {
            Ok(l) => (l.roll.value, l.pitch.value, [l.roll.sigma, l.pitch.sigma]),
            Err(_) => (0.0, 0.0, [f64::NAN; 2]),
        };
        // Without a usable heading the solution runs on with heading 0 and
        // says so through its (infinite) standard deviation; the filter
        // starts it with its largest prior (30 deg, see `physical`).
        let (heading, heading_std) = match gyrocompass(core::slice::from_ref(segment), &config) {
            Ok(h) if h.determined => (h.heading.value, h.heading.sigma),
            Ok(h) => (h.heading.value, f64::INFINITY),
            Err(_) => (0.0, f64::INFINITY),
        };
        let sigma = [roll_pitch_std[0], roll_pitch_std[1], heading_std];
        self.coarse_std = sigma.map(|s| s as f32);
        // A levelling that failed leaves no tilt sigma: the filter then
        // starts from a 10 deg one.
        let filter_sigma = sigma.map(|s| if s.is_nan() { 10f64.to_radians() } else { s });
        let attitude = quat_from_euler(&Euler::new(roll, pitch, heading));
        self.filter.restart(
            NavState::at_rest(attitude, self.position),
            self.position,
            filter_config(&self.position, &filter_sigma),
        );
        self.phase = Phase::Fine { samples: 0 };
    }

    fn solution(&self, raw: &RawSample) -> NavSolution {
        let mut solution = NavSolution {
            time_us: raw.time_us,
            sample_counter: raw.sample_counter,
            mode: nav_mode::COARSE_ALIGNMENT,
            flags: self.flags,
            latitude: self.position.lat,
            longitude: self.position.lon,
            height: self.position.height as f32,
            attitude_std: self.coarse_std,
            // No filter yet: velocity and position uncertainty unknown.
            velocity_std: [f32::NAN; 3],
            position_std_ned: [f32::NAN; 3],
            ..NavSolution::default()
        };
        solution.mode = match self.phase {
            Phase::Coarse(_) => return solution,
            Phase::Fine { .. } => nav_mode::FINE_ALIGNMENT,
            Phase::Navigating => nav_mode::NAVIGATING,
        };
        let filter = &self.filter;
        let state = filter.state();
        let e = euler_from_quat(&state.attitude);
        solution.attitude = [e.roll, e.pitch, e.heading].map(|a| a as f32);
        let v = state.velocity;
        solution.velocity_ned = [v.x, v.y, v.z].map(|v| v as f32);
        solution.latitude = state.position.lat;
        solution.longitude = state.position.lon;
        solution.height = state.position.height as f32;
        let std = filter.euler_std();
        let heading_std = if self.coarse_std[2].is_finite() {
            std.z as f32
        } else {
            f32::INFINITY
        };
        solution.attitude_std = [std.x as f32, std.y as f32, heading_std];
        let kalman = filter.filter();
        solution.velocity_std = core::array::from_fn(|i| kalman.std_dev(VEL + i));
        solution.position_std_ned = core::array::from_fn(|i| kalman.std_dev(POS + i));
        solution
    }

    /// True once the coarse alignment is done.
    pub fn is_aligned(&self) -> bool {
        !matches!(self.phase, Phase::Coarse(_))
    }

    /// True once the fine alignment is done too.
    pub fn is_navigating(&self) -> bool {
        matches!(self.phase, Phase::Navigating)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::calibration::TriadCalibration;
    use crate::protocol::frame::raw_flags;
    use crate::protocol::RawPart;
    use crate::sensor_units::{m_s2_to_accel_count, PART_MOUNTINGS, STANDARD_GRAVITY_M_S2};

    /// A still probe feeling `force` (body axes, m/s^2), no rotation (the
    /// hil-mock generator's static probe, which has no earth rate).
    fn still_sample(n: u32, force: [f32; 3]) -> RawSample {
        let parts = PART_MOUNTINGS.map(|mounting| RawPart {
            accel: mounting.body_to_sensor(force).map(m_s2_to_accel_count),
            flags: raw_flags::GYRO_VALID | raw_flags::ACCEL_VALID,
            ..RawPart::default()
        });
        RawSample {
            time_us: u64::from(n) * 50_000,
            sample_counter: n,
            parts,
        }
    }

    /// Level: gravity's reaction on body +z.
    fn level_sample(n: u32) -> RawSample {
        still_sample(n, [0.0, 0.0, STANDARD_GRAVITY_M_S2])
    }

    const ALL_ALIGNMENT: u32 = ALIGNMENT_SAMPLES + FINE_ALIGNMENT_SAMPLES;

    #[test]
    fn coarse_then_fine_alignment_then_navigation_on_a_still_level_probe() {
        let mut navigator = Navigator::new(Position::paper_site());
        for n in 0..ALIGNMENT_SAMPLES - 1 {
            let s = navigator.step(&level_sample(n));
            assert_eq!((s.mode, s.flags), (nav_mode::COARSE_ALIGNMENT, 0));
            assert!(s.velocity_std[0].is_nan());
        }
        // A sample with an invalid part is flagged and does not count.
        let mut bad = level_sample(99);
        bad.parts[1].flags = 0;
        let s = navigator.step(&bad);
        assert_eq!(s.flags, nav_flags::SENSOR_DEGRADED);
        assert!(!navigator.is_aligned());

        // The coarse alignment ends: the filter takes over.
        let first = navigator.step(&level_sample(100));
        assert!(navigator.is_aligned() && !navigator.is_navigating());
        assert_eq!(first.mode, nav_mode::FINE_ALIGNMENT);
        assert!(first.attitude_std[0] > 0.0 && first.attitude_std[1] > 0.0);
        let mut last = first;
        for n in 101..=ALL_ALIGNMENT {
            last = navigator.step(&level_sample(n));
            assert_eq!(last.sample_counter, n);
            assert!(last.attitude[0].abs() < 1e-3 && last.attitude[1].abs() < 1e-3);
            if n < ALL_ALIGNMENT {
                assert_eq!(last.mode, nav_mode::FINE_ALIGNMENT, "sample {n}");
                assert_eq!(last.flags, nav_flags::ZUPT_APPLIED, "sample {n}");
            }
        }
        // After 60 s the probe navigates; the zero updates are over.
        assert!(navigator.is_navigating());
        assert_eq!(last.mode, nav_mode::NAVIGATING);
        // No earth rate in these samples: the heading stays unknown, and
        // the frames say so rather than quoting the filter's small-angle
        // azimuth sigma.
        assert!(last.attitude_std[2].is_infinite(), "{last:?}");
        // The fine alignment converged in velocity and position; the tilt
        // sigmas stay at the floor the accelerometer bias sets (at rest
        // tilt and bias are inseparable: sigma_tilt >= sigma_b / g,
        // docs/filter-derivation.md section 3b), a little above it as the
        // bias random walk grows.
        let floor = (AugmentedModel::paper().biases.accel[0].initial_sigma
            / f64::from(STANDARD_GRAVITY_M_S2)) as f32;
        for axis in 0..2 {
            let sigma = last.attitude_std[axis];
            assert!(
                sigma >= 0.99 * floor && sigma < 1.5 * first.attitude_std[axis],
                "floor {floor}: {first:?} -> {last:?}"
            );
        }
        for i in 0..3 {
            assert!(
                last.velocity_std[i] < 0.2 * first.velocity_std[i],
                "{last:?}"
            );
            assert!(
                last.position_std_ned[i] < 0.2 * first.position_std_ned[i],
                "{last:?}"
            );
        }

        // Navigating without zero updates, the uncertainties grow.
        let mut later = last;
        for n in ALL_ALIGNMENT + 1..ALL_ALIGNMENT + 200 {
            later = navigator.step(&level_sample(n));
            assert_eq!(later.mode, nav_mode::NAVIGATING);
            assert_eq!(later.flags & nav_flags::ZUPT_APPLIED, 0);
        }
        assert!(
            later.velocity_std[0] > 2.0 * last.velocity_std[0],
            "{later:?}"
        );
        assert!(
            later.position_std_ned[0] > last.position_std_ned[0],
            "{later:?}"
        );
    }

    #[test]
    fn the_calibration_removes_an_accelerometer_bias_before_alignment() {
        // 10 counts (~0.15 m/s^2) of bias on body x tilt an uncalibrated
        // probe by ~0.9 deg in roll; the calibration takes it out.
        let bias = 10.0 * STANDARD_GRAVITY_M_S2 / 650.0;
        let biased = |n| still_sample(n, [bias, 0.0, STANDARD_GRAVITY_M_S2]);
        let triad = TriadCalibration {
            bias: [f64::from(bias), 0.0, 0.0],
            ..TriadCalibration::IDENTITY
        };
        let calibration = ProbeCalibration {
            accel: [triad; 2],
            ..ProbeCalibration::default()
        };
        let mut plain = Navigator::new(Position::paper_site());
        let mut calibrated = Navigator::with_calibration(Position::paper_site(), calibration);
        let (mut a, mut b) = (NavSolution::default(), NavSolution::default());
        for n in 0..=ALIGNMENT_SAMPLES {
            a = plain.step(&biased(n));
            b = calibrated.step(&biased(n));
        }
        let tilt = (bias / STANDARD_GRAVITY_M_S2).atan();
        assert!((a.attitude[0].abs() - tilt).abs() < 0.05 * tilt, "{a:?}");
        assert!(b.attitude[0].abs() < 0.02 * tilt, "{b:?}");
    }
}
