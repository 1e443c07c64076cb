//! One angle of the attitude measured from outside the filter's own
//! sensors (a drilling block's toolface, a reference azimuth, a tie-in's
//! inclination or toolface): a scalar on the attitude-error states alone,
//! the angle's computed minus measured value against its row of the
//! drilling-angle Jacobian (`conventions::angles_and_jacobian`).

use crate::error_model::ATT;
use crate::kalman::{FilterScalar, ScalarMeasurement, SparseRow};

/// The scalar measurement of one attitude angle: `z` its computed minus
/// measured value (rad), `row` its derivative with respect to the attitude
/// error phi, `r` the measured angle's variance (rad^2).
pub(crate) fn attitude_angle_scalar<T: FilterScalar>(
    z: T,
    row: &[T; 3],
    r: T,
) -> ScalarMeasurement<T> {
    let mut h = SparseRow::empty();
    for (i, v) in row.iter().enumerate() {
        h.push(ATT + i, *v);
    }
    ScalarMeasurement { z, h, r }
}
