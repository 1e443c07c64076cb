//! What a static probe's measurements can determine: the observability of
//! the navigation errors, optionally with constant sensor-bias states, under
//! zero-velocity and zero-position updates, for one toolface or a sequence
//! of toolfaces (a piece-wise constant system, analysed with the stripped
//! observability matrix). The matrices, their ranks and the per-state
//! report are [`matrices`]; this module builds the static probe's models
//! and names the states.
pub mod matrices;

use matrices::{
    dynamic, observability_matrix, rank, stripped_observability_matrix, stripping_condition_holds,
    ObservabilityReport,
};
use mwd_core::conventions::{dcm_from_euler, Euler, DEG};
use mwd_core::earth::{gravity_n, Position};
use mwd_core::error_model::{navigation_error_dynamics, LinearizationPoint, NAV_STATES, POS, VEL};
use nalgebra::{DMatrix, Vector3};

/// Names of the navigation-error states, then of the bias states.
pub const STATE_NAMES: [&str; 15] = [
    "attitude N",
    "attitude E",
    "attitude D (azimuth)",
    "velocity N",
    "velocity E",
    "velocity D",
    "position N",
    "position E",
    "position D",
    "accel bias x",
    "accel bias y",
    "accel bias z",
    "gyro bias x",
    "gyro bias y (derived rate)",
    "gyro bias z",
];

/// Which measurements the filter gets.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Measurements {
    pub zero_velocity: bool,
    pub zero_position: bool,
}

impl Measurements {
    /// By name: `zupt` (zero velocity), `zpu` (zero position) or `both`.
    pub fn from_name(name: &str) -> Option<Self> {
        let (zero_velocity, zero_position) = match name {
            "zupt" => (true, false),
            "zpu" => (false, true),
            "both" => (true, true),
            _ => return None,
        };
        Some(Self {
            zero_velocity,
            zero_position,
        })
    }
}

/// The continuous error model of a tool at rest with attitude `e`: F of
/// the 9 navigation errors (the core's), plus, with `biases`, six constant
/// bias states driving them (accelerometer bias into velocity through
/// C_b^n, rate bias into attitude through -C_b^n, as in the filter).
pub fn static_model(e: &Euler, position: Position, biases: bool) -> DMatrix<f64> {
    let c_bn = dcm_from_euler(e);
    let lp = LinearizationPoint {
        c_bn,
        velocity_n: Vector3::zeros(),
        position,
        specific_force_n: -gravity_n(&position),
    };
    let f9 = dynamic(&navigation_error_dynamics::<f64>(&lp));
    if !biases {
        return f9;
    }
    let n = NAV_STATES + 6;
    let mut f = DMatrix::zeros(n, n);
    f.view_mut((0, 0), (NAV_STATES, NAV_STATES)).copy_from(&f9);
    for r in 0..3 {
        for c in 0..3 {
            f[(VEL + r, NAV_STATES + c)] = c_bn[(r, c)];
            f[(r, NAV_STATES + 3 + c)] = -c_bn[(r, c)];
        }
    }
    f
}

/// The measurement matrix: velocity and/or position errors, each row
/// divided by its noise (0.01 m/s, 0.01 m) so singular values compare.
pub fn measurement_matrix(states: usize, m: Measurements) -> DMatrix<f64> {
    let mut rows = Vec::new();
    if m.zero_velocity {
        rows.extend((0..3).map(|i| (VEL + i, 1.0 / 0.01)));
    }
    if m.zero_position {
        rows.extend((0..3).map(|i| (POS + i, 1.0 / 0.01)));
    }
    let mut h = DMatrix::zeros(rows.len(), states);
    for (r, (state, weight)) in rows.into_iter().enumerate() {
        h[(r, state)] = weight;
    }
    h
}

/// The analysis of one scenario.
pub struct Analysis {
    pub states: usize,
    pub segment_ranks: Vec<usize>,
    pub stripped_rank: usize,
    pub stripping_condition: bool,
    pub report: ObservabilityReport,
}

/// Observability over toolface segments: the tool at `start` rolled by
/// each of `toolface_offsets` (rad) in turn.
pub fn analyse(
    start: &Euler,
    position: Position,
    toolface_offsets: &[f64],
    biases: bool,
    measurements: Measurements,
) -> Analysis {
    let segments: Vec<(DMatrix<f64>, DMatrix<f64>)> = toolface_offsets
        .iter()
        .map(|offset| {
            let e = Euler::new(start.roll + offset, start.pitch, start.heading);
            let f = static_model(&e, position, biases);
            let h = measurement_matrix(f.nrows(), measurements);
            (f, h)
        })
        .collect();
    let states = segments.first().map_or(0, |(f, _)| f.nrows());
    let stripped = stripped_observability_matrix(&segments);
    // States scaled to what they typically are: 1 mrad, 1 cm/s, 1 cm,
    // 1 mg, 2 deg/h, so that the report compares like with like.
    let mut scale = vec![1e-3, 1e-3, 1e-3, 0.01, 0.01, 0.01, 0.01, 0.01, 0.01];
    if biases {
        scale.extend([9.8e-3; 3]);
        scale.extend([2.0 * DEG / 3600.0; 3]);
    }
    Analysis {
        states,
        segment_ranks: segments
            .iter()
            .map(|(f, h)| rank(&observability_matrix(f, h)))
            .collect(),
        stripped_rank: rank(&stripped),
        stripping_condition: stripping_condition_holds(&segments),
        report: ObservabilityReport::new(&stripped, &scale, 1e-9),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const BOTH: Measurements = Measurements {
        zero_velocity: true,
        zero_position: true,
    };

    #[test]
    fn measurements_by_name() {
        assert_eq!(Measurements::from_name("both"), Some(BOTH));
        let zupt = Measurements::from_name("zupt").unwrap();
        assert!(zupt.zero_velocity && !zupt.zero_position);
        let zpu = Measurements::from_name("zpu").unwrap();
        assert!(!zpu.zero_velocity && zpu.zero_position);
        assert_eq!(Measurements::from_name("ZUPT"), None);
    }

    /// At rest, ZUPT + zero position cannot tell a horizontal accelerometer
    /// bias from tilt, nor the east gyro bias from azimuth: three of the 15
    /// directions are unobservable at one toolface.
    #[test]
    fn one_toolface_leaves_bias_and_attitude_entangled() {
        let e = Euler::new(0.3, 0.1, 0.5);
        let a = analyse(&e, Position::paper_site(), &[0.0], true, BOTH);
        assert_eq!(a.states, 15);
        assert_eq!(a.stripped_rank, 12, "{:?}", a.report.singular_values);
        // Azimuth is touched by the unobservable subspace.
        assert!(a.report.unobservable_share[2] > 0.01);
        // Without bias states, the 9 navigation errors are all observable.
        let nav = analyse(&e, Position::paper_site(), &[0.0], false, BOTH);
        assert_eq!(nav.stripped_rank, 9);
    }

    /// Toolface indexing (rotations about the tool axis) separates the
    /// cross-axis biases from the attitude errors: more directions become
    /// observable than at one toolface.
    #[test]
    fn toolface_indexing_adds_observable_directions() {
        let e = Euler::new(0.3, 0.1, 0.5);
        let one = analyse(&e, Position::paper_site(), &[0.0], true, BOTH);
        let quarter = std::f64::consts::FRAC_PI_2;
        let offsets = [0.0, quarter, 2.0 * quarter, 3.0 * quarter];
        let four = analyse(&e, Position::paper_site(), &offsets, true, BOTH);
        assert!(
            four.stripped_rank > one.stripped_rank,
            "{} vs {}",
            four.stripped_rank,
            one.stripped_rank
        );
    }
}
