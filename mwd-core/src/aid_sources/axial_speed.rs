//! A bound on the speed along the tool axis while the string moves: the
//! non-holonomic constraint's third component (docs/filter-derivation.md
//! section 4d). The tool moves along its axis at the rate of penetration
//! (10-30 m/h, < 0.01 m/s) or, picking up off bottom at a connection, at
//! most at tripping speed; the probe does not know which, so the bound's
//! sigma is the larger, [`AXIAL_SPEED_VARIANCE`]. It keeps the along-axis
//! velocity error bounded, which the cross-axis constraint cannot.
//!
//! The row is the cross-axis one of `super::non_holonomic` for body axis y:
//! dv_b,y = r_y . dv + (v_n x r_y) . phi, z = the computed v_b,y.

use crate::error_model::{ATT, VEL};
use crate::kalman::{FilterScalar, Measurement, ScalarMeasurement, SparseRow};
use crate::mechanization::NavState;
use nalgebra::Vector3;

/// The tool axis: body y.
const TOOL_AXIS: usize = 1;

/// Variance ((m/s)^2) of the speed along the tool axis: 0.5 m/s, the
/// tripping speed `BhaCrossMotion::DRILLING` takes for the misalignment
/// leak, fifty times a fast rate of penetration.
pub const AXIAL_SPEED_VARIANCE: f64 = 0.25;

/// The bound at one solution: one scalar.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxialSpeed<T> {
    /// Computed velocity along the tool axis (m/s).
    pub axial_velocity: T,
    pub attitude_row: [T; 3],
    pub velocity_row: [T; 3],
    pub variance: T,
}

impl<T: FilterScalar> AxialSpeed<T> {
    pub fn at(state: &NavState, variance: T) -> Self {
        let c_bn = state.attitude.to_rotation_matrix().into_inner();
        let axis: Vector3<f64> = c_bn.column(TOOL_AXIS).into_owned();
        let v = state.velocity;
        let to_t = |w: Vector3<f64>| -> [T; 3] { core::array::from_fn(|i| T::of(w[i])) };
        Self {
            axial_velocity: T::of(axis.dot(&v)),
            attitude_row: to_t(v.cross(&axis)),
            velocity_row: to_t(axis),
            variance,
        }
    }
}

impl<T: FilterScalar> Measurement<T> for AxialSpeed<T> {
    fn len(&self) -> usize {
        1
    }
    fn scalar(&self, k: usize) -> Option<ScalarMeasurement<T>> {
        if k != 0 {
            return None;
        }
        let mut h = SparseRow::empty();
        for i in 0..3 {
            h.push(ATT + i, self.attitude_row[i]);
            h.push(VEL + i, self.velocity_row[i]);
        }
        Some(ScalarMeasurement {
            z: self.axial_velocity,
            h,
            r: self.variance,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::aid_sources::NonHolonomic;
    use crate::conventions::{quat_from_euler, Euler};
    use crate::earth::Position;

    /// The same row as the cross-axis constraint's, for the tool axis:
    /// checked against NonHolonomic's rows on an attitude rotated so that
    /// its body x is this one's body y.
    #[test]
    fn the_row_is_the_cross_axis_row_of_the_tool_axis() {
        let mut state = NavState::at_rest(
            quat_from_euler(&Euler::new(0.4, -0.1, 2.0)),
            Position::paper_site(),
        );
        state.velocity = Vector3::new(0.3, -0.2, 0.05);
        let a = AxialSpeed::<f64>::at(&state, 1.0);
        let c = state.attitude.to_rotation_matrix().into_inner();
        // Columns (y, x, z): NonHolonomic's axis 0 is then body y.
        let swapped = nalgebra::Matrix3::from_columns(&[c.column(1), c.column(0), c.column(2)]);
        let n = NonHolonomic::<f64>::new(&swapped, &state.velocity, 1.0);
        assert!((a.axial_velocity - n.cross_velocity_b[0]).abs() < 1e-15);
        for i in 0..3 {
            assert!((a.attitude_row[i] - n.attitude_row[0][i]).abs() < 1e-15);
            assert!((a.velocity_row[i] - n.velocity_row[0][i]).abs() < 1e-15);
        }
        assert!(a.scalar(1).is_none());
    }
}
