//! The two rotation schemes: the IMU's orientation in the vehicle frame over
//! time. The paper names them (four dwell positions for the single-axis
//! backup, a 16-phase sequence for the dual-axis master, after Yuan et al.
//! 2012 [ref. 5] and Tucker and Levinson 2000 [ref. 6]) but gives neither
//! the order, the rates nor the dwell times: those below are ours.
//!
//! * Backup: about the vertical (IMU z) axis only, dwells at 0, 90, 180 and
//!   270 deg, one turn forward and one back. A constant body drift or bias b projects to C b, and the four
//!   dwells' C sum to zero in their horizontal columns: the horizontal
//!   sensor errors average out, the z gyro's (the azimuth drift) never does.
//! * Master: sixteen 180 deg flips, alternately about the IMU's z and x
//!   axes, in four groups (z+ x+ z+ x+, then x- z- x- z-, z- x- z- x-,
//!   x+ z+ x+ z+: each group reverses the previous one's sense or order, the
//!   symmetry of the published 16-phase sequences that also cancels the
//!   rotation-induced errors of scale factor and misalignment). Each group
//!   visits the four orientations I, Rz, Ry, Rx (180 deg), whose diagonals
//!   sum to zero: every gyro drift and accelerometer bias averages out.
//!
//! Each phase is a rotation at a constant rate followed by a dwell.

use nalgebra::{Matrix3, Rotation3, Vector3};
use std::f64::consts::PI;

/// A rotation scheme: the IMU-to-vehicle rotation at time `t` (s).
pub trait RotationScheme {
    fn orientation(&self, t: f64) -> Matrix3<f64>;
    /// Length of one full cycle (s).
    fn cycle(&self) -> f64;
}

/// Timing shared by both schemes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Timing {
    /// Rotation rate (rad/s).
    pub rate: f64,
    /// Dwell after each rotation (s).
    pub dwell: f64,
}

impl Timing {
    /// Ours: 10 deg/s and a dwell of 60 s, so a backup phase lasts 69 s
    /// and a master flip phase 78 s. Short dwells keep the backup's modulated
    /// accelerometer bias (40 ug) from building more than ~2 cm/s of velocity
    /// swing per dwell.
    pub fn ours() -> Self {
        Self {
            rate: 10f64.to_radians(),
            dwell: 60.0,
        }
    }
}

fn about(axis: Vector3<f64>, angle: f64) -> Matrix3<f64> {
    Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(axis), angle).into_inner()
}

/// One phase: start orientation, axis (IMU frame), signed angle; the
/// rotation takes |angle| / rate, then the dwell.
#[derive(Debug, Clone, Copy)]
struct Phase {
    start: Matrix3<f64>,
    axis: Vector3<f64>,
    angle: f64,
    begins: f64,
}

/// A scheme as its phases over one cycle.
#[derive(Debug, Clone)]
pub struct PhasedScheme {
    phases: Vec<Phase>,
    timing: Timing,
    cycle: f64,
}

impl PhasedScheme {
    fn new(steps: &[(Vector3<f64>, f64)], timing: Timing) -> Self {
        let mut phases = Vec::with_capacity(steps.len());
        let (mut c, mut t) = (Matrix3::identity(), 0.0);
        for &(axis, angle) in steps {
            phases.push(Phase {
                start: c,
                axis,
                angle,
                begins: t,
            });
            c *= about(axis, angle);
            t += angle.abs() / timing.rate + timing.dwell;
        }
        Self {
            phases,
            timing,
            cycle: t,
        }
    }

    /// The backup's four-dwell single-axis scheme: dwells at 0, 90, 180,
    /// 270 deg about z, turning +90 deg between them for one turn, then
    /// back the same way (-90 deg steps). The turns sweep every angle
    /// equally often, so the transits average out too; an order such as
    /// 0 -> 180 -> 90 -> 270 sweeps some arcs twice and leaves ~4 % of the
    /// horizontal errors un-averaged.
    pub fn single_axis_four_dwell(timing: Timing) -> Self {
        let z = Vector3::z();
        let quarter = PI / 2.0;
        let mut steps = [(z, quarter); 8];
        for step in &mut steps[4..] {
            step.1 = -quarter;
        }
        Self::new(&steps, timing)
    }

    /// The master's 16-phase dual-axis scheme (see the module notes).
    pub fn dual_axis_sixteen_phase(timing: Timing) -> Self {
        let (x, z) = (Vector3::x(), Vector3::z());
        let group = |first: Vector3<f64>, second: Vector3<f64>, sense: f64| {
            [
                (first, sense * PI),
                (second, sense * PI),
                (first, sense * PI),
                (second, sense * PI),
            ]
        };
        let steps: Vec<(Vector3<f64>, f64)> = [
            group(z, x, 1.0),
            group(x, z, -1.0),
            group(z, x, -1.0),
            group(x, z, 1.0),
        ]
        .concat();
        Self::new(&steps, timing)
    }
}

impl RotationScheme for PhasedScheme {
    fn orientation(&self, t: f64) -> Matrix3<f64> {
        let t = t.rem_euclid(self.cycle);
        // phases are few (4 or 16): a linear search is cheaper than a bisection
        let phase = self
            .phases
            .iter()
            .rev()
            .find(|p| p.begins <= t)
            .or(self.phases.first());
        let Some(phase) = phase else {
            return Matrix3::identity();
        };
        if phase.angle == 0.0 {
            return phase.start;
        }
        let turned = ((t - phase.begins) * self.timing.rate).min(phase.angle.abs());
        phase.start * about(phase.axis, turned * phase.angle.signum())
    }

    fn cycle(&self) -> f64 {
        self.cycle
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Mean of C over one cycle by the midpoint rule.
    fn cycle_mean(s: &impl RotationScheme) -> Matrix3<f64> {
        let n = 20_000;
        let dt = s.cycle() / n as f64;
        (0..n)
            .map(|k| s.orientation((k as f64 + 0.5) * dt))
            .sum::<Matrix3<f64>>()
            / n as f64
    }

    #[test]
    fn master_averages_out_every_axis() {
        let s = PhasedScheme::dual_axis_sixteen_phase(Timing::ours());
        assert!(cycle_mean(&s).amax() < 1e-3, "{}", cycle_mean(&s));
        assert!((s.orientation(s.cycle()) - Matrix3::identity()).amax() < 1e-12);
    }

    #[test]
    fn backup_averages_out_all_but_its_vertical_axis() {
        let s = PhasedScheme::single_axis_four_dwell(Timing::ours());
        let mean = cycle_mean(&s);
        assert!(mean.fixed_view::<3, 2>(0, 0).amax() < 1e-3, "{mean}");
        assert!((mean[(2, 2)] - 1.0).abs() < 1e-12);
        assert!((s.orientation(s.cycle() - 1e-9) - Matrix3::identity()).amax() < 1e-6);
    }
}
