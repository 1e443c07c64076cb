//! The navigation work of the main loop (lower priority than acquisition):
//! raw samples in, navigation-solution frames out. First the probe must be
//! still: the first samples are averaged and coarse-aligned (levelling and
//! gyrocompassing from `mwd_core::alignment`), then the strapdown
//! mechanization runs on every sample. The fine alignment (issue 3's
//! Kalman filter) slots in between once it exists.
//!
//! Uses only mwd-core (f64 where the core keeps it): the host can replay
//! the same raw frames through the same code.

use mwd_core::alignment::{
    gyrocompass, level_segment, AlignmentConfig, StaticSegment, PROBE_GYROS,
};
use mwd_core::conventions::{euler_from_quat, quat_from_euler, Euler};
use mwd_core::earth::Position;
use mwd_core::mechanization::{NavState, ProbeInput, Strapdown};
use mwd_core::protocol::frame::{nav_flags, nav_mode, raw_flags};
use mwd_core::protocol::{NavSolution, RawSample};
use mwd_core::sensor_noise::ImuNoise;
use mwd_core::sensor_units::{accel_count_to_m_s2, gyro_count_to_rad_s, PART_MOUNTINGS};
use nalgebra::Vector3;

/// Sample interval of the probe (s).
pub const SAMPLE_INTERVAL_S: f64 = 0.05;
/// Still samples averaged for the coarse alignment: 5 s, as in the paper.
pub const ALIGNMENT_SAMPLES: u32 = 100;

/// Body-frame rates (x and z gyros) and specific force of one raw sample,
/// or `None` when a part's reading is not valid.
pub fn body_sample(raw: &RawSample) -> Option<(f64, f64, Vector3<f64>)> {
    let valid = raw_flags::GYRO_VALID | raw_flags::ACCEL_VALID;
    if raw.parts.iter().any(|p| p.flags & valid != valid) {
        return None;
    }
    let mut rate = [0.0f32; 3];
    let mut force = [0.0f32; 3];
    for (part, mounting) in raw.parts.iter().zip(PART_MOUNTINGS) {
        let gyro = mounting.gyro_axis();
        let value = gyro_count_to_rad_s(part.gyro_rate);
        rate[gyro.axis as usize] = if gyro.negative { -value } else { value };
        // Both parts' accelerometers see the same body force: average them.
        let body = mounting.sensor_to_body(part.accel.map(accel_count_to_m_s2));
        for (f, b) in force.iter_mut().zip(body) {
            *f += 0.5 * b;
        }
    }
    let force = Vector3::new(force[0], force[1], force[2]).cast::<f64>();
    Some((f64::from(rate[0]), f64::from(rate[2]), force))
}

enum Phase {
    /// Summing still samples.
    Aligning {
        force: Vector3<f64>,
        rate: Vector3<f64>,
        samples: u32,
    },
    Navigating {
        nav: Strapdown,
        input: ProbeInput,
    },
}

/// The probe's navigation, one raw sample at a time.
pub struct Navigator {
    position: Position,
    phase: Phase,
    /// 1-sigma of roll, pitch, heading from the alignment (rad).
    attitude_std: [f32; 3],
    flags: u16,
}

impl Navigator {
    pub fn new(position: Position) -> Self {
        Self {
            position,
            phase: Phase::Aligning {
                force: Vector3::zeros(),
                rate: Vector3::zeros(),
                samples: 0,
            },
            attitude_std: [f32::NAN; 3],
            flags: 0,
        }
    }

    /// Takes one raw sample and returns the solution after it.
    pub fn step(&mut self, raw: &RawSample) -> NavSolution {
        let body = body_sample(raw);
        self.flags = if body.is_none() {
            nav_flags::SENSOR_DEGRADED
        } else {
            0
        };
        let mut aligned = None;
        match (&mut self.phase, body) {
            (
                Phase::Aligning {
                    force,
                    rate,
                    samples,
                },
                Some((gx, gz, f)),
            ) => {
                *force += f;
                *rate += Vector3::new(gx, 0.0, gz);
                *samples += 1;
                if *samples >= ALIGNMENT_SAMPLES {
                    let n = f64::from(*samples);
                    aligned = Some(StaticSegment {
                        specific_force: *force / n,
                        rate: *rate / n,
                        samples: *samples as usize,
                    });
                }
            }
            (Phase::Navigating { nav, input }, Some((gx, gz, f))) => {
                let (sample, _) = input.sample(nav.state(), gx, gz, &f, SAMPLE_INTERVAL_S);
                nav.step(&sample);
            }
            // A sample without valid data: alignment waits, navigation
            // coasts (the state is left as it is and flagged).
            (_, None) => {}
        }
        if let Some(segment) = aligned {
            self.finish_alignment(&segment);
        }
        self.solution(raw)
    }

    fn finish_alignment(&mut self, segment: &StaticSegment) {
        let config = AlignmentConfig {
            latitude: self.position.lat,
            sample_interval: SAMPLE_INTERVAL_S,
            gyro_axes: PROBE_GYROS,
            noise: ImuNoise::scc1300(),
            heading_prior: None,
        };
        let (roll, pitch, roll_pitch_std) = match level_segment(segment, &config) {
            Ok(l) => (l.roll.value, l.pitch.value, [l.roll.sigma, l.pitch.sigma]),
            Err(_) => (0.0, 0.0, [f64::NAN; 2]),
        };
        // Without a usable heading the solution runs on with heading 0 and
        // says so through its (infinite) standard deviation.
        let (heading, heading_std) = match gyrocompass(core::slice::from_ref(segment), &config) {
            Ok(h) if h.determined => (h.heading.value, h.heading.sigma),
            Ok(h) => (h.heading.value, f64::INFINITY),
            Err(_) => (0.0, f64::INFINITY),
        };
        self.attitude_std = [roll_pitch_std[0], roll_pitch_std[1], heading_std].map(|s| s as f32);
        let attitude = quat_from_euler(&Euler::new(roll, pitch, heading));
        self.phase = Phase::Navigating {
            nav: Strapdown::new(
                NavState::at_rest(attitude, self.position),
                SAMPLE_INTERVAL_S,
            ),
            input: ProbeInput::new(),
        };
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
            attitude_std: self.attitude_std,
            // No filter yet: velocity and position uncertainty unknown.
            velocity_std: [f32::NAN; 3],
            position_std_ned: [f32::NAN; 3],
            ..NavSolution::default()
        };
        if let Phase::Navigating { nav, .. } = &self.phase {
            let state = nav.state();
            let e = euler_from_quat(&state.attitude);
            solution.mode = nav_mode::NAVIGATING;
            solution.attitude = [e.roll, e.pitch, e.heading].map(|a| a as f32);
            solution.velocity_ned =
                [state.velocity.x, state.velocity.y, state.velocity.z].map(|v| v as f32);
            solution.latitude = state.position.lat;
            solution.longitude = state.position.lon;
            solution.height = state.position.height as f32;
        }
        solution
    }

    pub fn is_aligned(&self) -> bool {
        matches!(self.phase, Phase::Navigating { .. })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mwd_core::protocol::RawPart;
    use mwd_core::sensor_units::{m_s2_to_accel_count, STANDARD_GRAVITY_M_S2};

    /// A still, level probe: gravity's reaction on body +z, no rotation
    /// (the hil-mock generator's static probe, which has no earth rate).
    fn level_sample(n: u32) -> RawSample {
        let parts = PART_MOUNTINGS.map(|mounting| RawPart {
            accel: mounting
                .body_to_sensor([0.0, 0.0, STANDARD_GRAVITY_M_S2])
                .map(m_s2_to_accel_count),
            flags: raw_flags::GYRO_VALID | raw_flags::ACCEL_VALID,
            ..RawPart::default()
        });
        RawSample {
            time_us: u64::from(n) * 50_000,
            sample_counter: n,
            parts,
        }
    }

    #[test]
    fn aligns_on_still_samples_then_navigates_level() {
        let mut navigator = Navigator::new(Position::paper_site());
        for n in 0..ALIGNMENT_SAMPLES - 1 {
            let s = navigator.step(&level_sample(n));
            assert_eq!((s.mode, s.flags), (nav_mode::COARSE_ALIGNMENT, 0));
        }
        // A sample with an invalid part is flagged and does not count.
        let mut bad = level_sample(99);
        bad.parts[1].flags = 0;
        let s = navigator.step(&bad);
        assert_eq!(s.flags, nav_flags::SENSOR_DEGRADED);
        assert!(!navigator.is_aligned());

        let s = navigator.step(&level_sample(100));
        assert!(navigator.is_aligned());
        assert_eq!(s.mode, nav_mode::NAVIGATING);
        assert!(s.attitude[0].abs() < 1e-3 && s.attitude[1].abs() < 1e-3);
        assert!(s.attitude_std[0] > 0.0 && s.attitude_std[1] > 0.0);
        for n in 101..140 {
            let s = navigator.step(&level_sample(n));
            assert_eq!(s.sample_counter, n);
            assert!(s.attitude[0].abs() < 1e-3 && s.attitude[1].abs() < 1e-3);
        }
    }
}
