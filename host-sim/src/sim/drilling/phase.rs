//! The pieces of a drilling schedule: what the rig is doing
//! ([`DrillState`]), its phases (still, drilling a stand with linear speed
//! ramps at both ends, the orienter's turn at a connection) with the MD,
//! speed and acceleration along the hole over each, the orienter's toolface
//! ramps, and the connections' still periods.
use rand::Rng;
use rand_chacha::ChaCha8Rng;

/// What the rig is doing.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DrillState {
    /// On bottom, the hole getting deeper (speed ramps included).
    Drilling,
    /// At a connection, the orienter turning the toolface.
    Connection,
    /// At rest (pumps off, connection or tie-on).
    Still,
}

impl DrillState {
    pub fn name(self) -> &'static str {
        match self {
            Self::Drilling => "drilling",
            Self::Connection => "connection",
            Self::Still => "still",
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum PhaseKind {
    Still,
    Turn,
    /// Drilling `length` m from the phase's MD, peak speed (m/s), ramp (s).
    Drill {
        length: f64,
        peak: f64,
        ramp: f64,
    },
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Phase {
    pub(super) t0: f64,
    pub(super) t1: f64,
    pub(super) md0: f64,
    pub(super) kind: PhaseKind,
}

impl Phase {
    /// (MD, speed, acceleration along the hole) at t in the phase.
    pub(super) fn kinematics(&self, t: f64) -> (f64, f64, f64) {
        let PhaseKind::Drill { length, peak, ramp } = self.kind else {
            return (self.md0, 0.0, 0.0);
        };
        let u = (t - self.t0).clamp(0.0, self.t1 - self.t0);
        let total = self.t1 - self.t0;
        if ramp <= 0.0 {
            return (self.md0 + peak * u, peak, 0.0);
        }
        if u < ramp {
            (
                self.md0 + peak * u * u / (2.0 * ramp),
                peak * u / ramp,
                peak / ramp,
            )
        } else if u < total - ramp {
            (self.md0 + peak * (0.5 * ramp + u - ramp), peak, 0.0)
        } else {
            let w = total - u;
            (
                self.md0 + length - peak * w * w / (2.0 * ramp),
                peak * w / ramp,
                -peak / ramp,
            )
        }
    }

    pub(super) fn state(&self) -> DrillState {
        match self.kind {
            PhaseKind::Still => DrillState::Still,
            PhaseKind::Turn => DrillState::Connection,
            PhaseKind::Drill { .. } => DrillState::Drilling,
        }
    }
}

/// A linear change of the toolface offset by `delta` over [t0, t1].
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Ramp {
    pub(super) t0: f64,
    pub(super) t1: f64,
    pub(super) delta: f64,
}

impl Ramp {
    pub(super) fn value(&self, t: f64) -> f64 {
        if t <= self.t0 {
            0.0
        } else if t >= self.t1 {
            self.delta
        } else {
            self.delta * (t - self.t0) / (self.t1 - self.t0)
        }
    }
}

/// An orienter step of `size` (rad) from the offset `offset` to the
/// section's toolface: back towards it when off it, either way at random
/// when on it. The driller holds the toolface the section needs; the steps
/// stay within +-(the larger step size) of it.
pub(super) fn toward_section(offset: f64, size: f64, rng: &mut ChaCha8Rng) -> f64 {
    let direction = if offset.abs() > 1e-12 {
        -offset.signum()
    } else if rng.random::<bool>() {
        1.0
    } else {
        -1.0
    };
    size * direction
}

/// A connection: the still period's times and the MD there.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Connection {
    pub still_start: f64,
    pub still_end: f64,
    pub md: f64,
}
