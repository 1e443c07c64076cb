//! Zero-velocity update (ZUPT, paper eq. 47, first three rows).

use crate::error_model::VEL;
use crate::kalman::{FilterScalar, Measurement, ScalarMeasurement, SparseRow};
use nalgebra::Vector3;

/// Zero-velocity update (ZUPT): the probe is at rest, so the computed NED
/// velocity is the velocity error (eq. 47, first three rows).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ZeroVelocity<T> {
    /// Computed velocity minus the reference (zero), NED, m/s.
    pub velocity_n: [T; 3],
    /// Noise variance of each component, (m/s)^2.
    pub variance: T,
}

impl<T: FilterScalar> ZeroVelocity<T> {
    pub fn new(computed_velocity_n: &Vector3<f64>, variance: T) -> Self {
        Self {
            velocity_n: core::array::from_fn(|i| T::of(computed_velocity_n[i])),
            variance,
        }
    }
}

impl<T: FilterScalar> Measurement<T> for ZeroVelocity<T> {
    fn len(&self) -> usize {
        3
    }
    fn scalar(&self, k: usize) -> Option<ScalarMeasurement<T>> {
        Some(ScalarMeasurement {
            z: *self.velocity_n.get(k)?,
            h: SparseRow::select(VEL + k),
            r: self.variance,
        })
    }
}
