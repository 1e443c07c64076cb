//! Trajectories of a probe that stays at one place (surface and downhole
//! alignment scenarios): static, toolface indexing and constant-rate
//! rotations. Each gives the attitude and the body's rate relative to the
//! navigation frame at any time.
use core::f64::consts::{FRAC_PI_2, PI};
use mwd_core::conventions::{dcm_from_euler, Euler};
use mwd_core::earth::Position;
use nalgebra::{Matrix3, Vector3};

/// How the tool moves about its fixed centre.
#[derive(Clone, Debug, PartialEq)]
pub enum Motion {
    /// At rest.
    Static,
    /// Toolface indexing: dwell, turn the tool about its axis by `step` at
    /// `turn_rate`, dwell again, `steps` times (the first dwell at the
    /// starting toolface).
    ToolfaceSteps {
        /// Rotation per step about the tool axis (rad, sign = direction).
        step: f64,
        /// Rate of each turn (rad/s, positive).
        turn_rate: f64,
        /// Time at rest at each toolface (s).
        dwell: f64,
        /// Number of turns.
        steps: usize,
    },
    /// Constant body rate omega_nb^b (rad/s) relative to the navigation frame.
    ConstantRate { body_rate: Vector3<f64> },
    /// A six-position calibration tumble: `dwell` seconds with each body
    /// axis up and then down, in the order of [`SIX_POSITIONS`], at the
    /// starting heading. The probe jumps between positions (only the dwell
    /// data matter to the calibration).
    SixPosition { dwell: f64 },
}

/// The six positions (code as `host-sim calibrate` reads it, roll, pitch):
/// 1 +x up, 2 x down, 3 +y up, 4 y down, 5 +z up, 6 z down.
pub const SIX_POSITIONS: [(u8, f64, f64); 6] = [
    (1, -FRAC_PI_2, 0.0),
    (2, FRAC_PI_2, 0.0),
    (3, 0.0, FRAC_PI_2),
    (4, 0.0, -FRAC_PI_2),
    (5, 0.0, 0.0),
    (6, PI, 0.0),
];

/// A trajectory: where, the attitude at t = 0, and how it moves.
#[derive(Clone, Debug, PartialEq)]
pub struct Trajectory {
    pub position: Position,
    pub start: Euler,
    pub motion: Motion,
}

impl Trajectory {
    /// The paper's static test (section 4) at its place, with a given attitude.
    pub fn paper_static(start: Euler) -> Self {
        Self {
            position: Position::paper_site(),
            start,
            motion: Motion::Static,
        }
    }

    /// Duration of the scripted part of the motion (s); static trajectories
    /// have none and run as long as asked.
    pub fn scripted_duration(&self) -> f64 {
        match &self.motion {
            Motion::ToolfaceSteps {
                step,
                turn_rate,
                dwell,
                steps,
            } => (*steps as f64) * (step.abs() / turn_rate + dwell) + dwell,
            Motion::SixPosition { dwell } => 6.0 * dwell,
            _ => 0.0,
        }
    }

    /// The six-position entry at time t: the last instant of a dwell still
    /// belongs to it, so each sample interval lies in one position.
    fn six_position(&self, t: f64) -> Option<(u8, f64, f64)> {
        let Motion::SixPosition { dwell } = self.motion else {
            return None;
        };
        let valid = dwell > 0.0; // false for NaN too
        if !valid {
            return None;
        }
        let index = ((t - 1e-9).max(0.0) / dwell).floor() as usize;
        Some(SIX_POSITIONS[index.min(5)])
    }

    /// The calibration position code (1-6) at time t, for six-position runs.
    pub fn position_code(&self, t: f64) -> Option<u8> {
        self.six_position(t).map(|(code, _, _)| code)
    }

    /// Roll added by toolface indexing at time t, and its rate.
    fn indexing(&self, t: f64) -> (f64, f64) {
        let Motion::ToolfaceSteps {
            step,
            turn_rate,
            dwell,
            steps,
        } = &self.motion
        else {
            return (0.0, 0.0);
        };
        let turning = *turn_rate > 0.0; // false for NaN too
        if !turning {
            return (0.0, 0.0);
        }
        let turn_time = step.abs() / turn_rate;
        let period = dwell + turn_time;
        let mut angle = 0.0;
        let mut rate = 0.0;
        let elapsed_steps = (t / period).floor().max(0.0) as usize;
        let done = elapsed_steps.min(*steps);
        angle += done as f64 * step;
        if elapsed_steps < *steps {
            let within = t - elapsed_steps as f64 * period;
            if within > *dwell {
                angle += step.signum() * turn_rate * (within - dwell);
                rate = step.signum() * turn_rate;
            }
        }
        (angle, rate)
    }

    /// C_b^n at time t.
    pub fn attitude(&self, t: f64) -> Matrix3<f64> {
        match &self.motion {
            Motion::Static => dcm_from_euler(&self.start),
            Motion::SixPosition { .. } => {
                let (_, roll, pitch) = self.six_position(t).unwrap_or((0, 0.0, 0.0));
                dcm_from_euler(&Euler::new(roll, pitch, self.start.heading))
            }
            Motion::ToolfaceSteps { .. } => {
                let (angle, _) = self.indexing(t);
                dcm_from_euler(&Euler::new(
                    self.start.roll + angle,
                    self.start.pitch,
                    self.start.heading,
                ))
            }
            Motion::ConstantRate { body_rate } => {
                dcm_from_euler(&self.start)
                    * mwd_core::attitude::dcm_from_rotation_vector(&(body_rate * t))
            }
        }
    }

    /// The body's rate relative to the navigation frame, omega_nb^b (rad/s).
    pub fn body_rate(&self, t: f64) -> Vector3<f64> {
        match &self.motion {
            Motion::Static | Motion::SixPosition { .. } => Vector3::zeros(),
            // Roll is the innermost Euler rotation, about the tool axis (y).
            Motion::ToolfaceSteps { .. } => Vector3::new(0.0, self.indexing(t).1, 0.0),
            Motion::ConstantRate { body_rate } => *body_rate,
        }
    }

    /// Euler angles at time t.
    pub fn euler(&self, t: f64) -> Euler {
        mwd_core::conventions::euler_from_dcm(&self.attitude(t))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn toolface_steps_turn_by_the_step_and_rest_between() {
        let traj = Trajectory {
            position: Position::paper_site(),
            start: Euler::new(0.0, -0.2, 0.5),
            motion: Motion::ToolfaceSteps {
                step: core::f64::consts::PI,
                turn_rate: 0.5,
                dwell: 10.0,
                steps: 1,
            },
        };
        let turn = core::f64::consts::PI / 0.5;
        assert!((traj.scripted_duration() - (20.0 + turn)).abs() < 1e-12);
        assert_eq!(traj.body_rate(5.0), Vector3::zeros());
        assert!((traj.body_rate(11.0).y - 0.5).abs() < 1e-12);
        let end = traj.euler(30.0);
        assert!(
            (mwd_core::conventions::wrap_pi(end.roll) - core::f64::consts::PI).abs() < 1e-9
                || (mwd_core::conventions::wrap_pi(end.roll) + core::f64::consts::PI).abs() < 1e-9
        );
        assert!((end.heading - 0.5).abs() < 1e-9 && (end.pitch + 0.2).abs() < 1e-9);
    }

    #[test]
    fn six_positions_put_each_axis_up_and_down() {
        let traj = Trajectory {
            position: Position::paper_site(),
            start: Euler::new(0.0, 0.0, 0.4),
            motion: Motion::SixPosition { dwell: 10.0 },
        };
        assert_eq!(traj.scripted_duration(), 60.0);
        // Body axis that points up (-down) in each dwell, and its code.
        let up = [
            (1, 0, 1.0),
            (2, 0, -1.0),
            (3, 1, 1.0),
            (4, 1, -1.0),
            (5, 2, 1.0),
            (6, 2, -1.0),
        ];
        for (k, (code, axis, sign)) in up.into_iter().enumerate() {
            for t in [k as f64 * 10.0 + 0.05, (k + 1) as f64 * 10.0] {
                assert_eq!(traj.position_code(t), Some(code), "t = {t}");
                let mut b = Vector3::zeros();
                b[axis] = sign;
                let n = traj.attitude(t) * b;
                assert!((n.z + 1.0).abs() < 1e-12, "code {code}: {n:?}");
            }
        }
        assert_eq!(
            Trajectory::paper_static(Euler::default()).position_code(1.0),
            None
        );
    }

    #[test]
    fn constant_rate_rotation_matches_its_rate() {
        let traj = Trajectory {
            position: Position::paper_site(),
            start: Euler::new(0.1, 0.2, 0.3),
            motion: Motion::ConstantRate {
                body_rate: Vector3::new(0.01, -0.02, 0.03),
            },
        };
        // C^T dC/dt = [omega x] for a body-frame rotation.
        let h = 1e-5;
        let dc = (traj.attitude(2.0 + h) - traj.attitude(2.0 - h)) / (2.0 * h);
        let s = traj.attitude(2.0).transpose() * dc;
        let w = Vector3::new(s[(2, 1)], s[(0, 2)], s[(1, 0)]);
        assert!((w - traj.body_rate(2.0)).norm() < 1e-8);
    }
}
