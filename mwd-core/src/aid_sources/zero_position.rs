//! Zero-position update: the probe has not moved from a known position
//! (paper eq. 47, last three rows, in metres: see docs/paper-errata.md).

use crate::earth::{LocalEarth, Position};
use crate::error_model::POS;
use crate::kalman::{FilterScalar, Measurement, ScalarMeasurement, SparseRow};

/// Zero-position update: the probe has not moved from a known position,
/// so the computed position minus the reference is the position error, in
/// metres north, east, down (eq. 47, last three rows, in metres: erratum 6).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ZeroPosition<T> {
    /// Computed position minus the reference, NED metres.
    pub position_error_ned_m: [T; 3],
    /// Noise variance of each component, m^2.
    pub variance: T,
}

impl<T: FilterScalar> ZeroPosition<T> {
    /// The computed position's offset from the reference, whose local earth
    /// the caller keeps (no trigonometry in the 20 Hz cycle). The offset is
    /// formed in f64 (geodetic angles need it) and only the small metric
    /// offset is converted to the filter's scalar.
    pub fn new(computed: &Position, reference: &LocalEarth, variance: T) -> Self {
        let d = reference.offset_to(computed);
        Self {
            position_error_ned_m: core::array::from_fn(|i| T::of(d[i])),
            variance,
        }
    }
}

impl<T: FilterScalar> Measurement<T> for ZeroPosition<T> {
    fn len(&self) -> usize {
        3
    }
    fn scalar(&self, k: usize) -> Option<ScalarMeasurement<T>> {
        Some(ScalarMeasurement {
            z: *self.position_error_ned_m.get(k)?,
            h: SparseRow::select(POS + k),
            r: self.variance,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    #[test]
    fn the_measurement_is_the_offset_from_the_reference() {
        let reference = Position::paper_site();
        let offset = Vector3::new(12.0, -7.5, 3.25);
        let moved = reference.displaced(&offset);
        let update = ZeroPosition::<f64>::new(&moved, &LocalEarth::at(&reference), 2.0);
        for (k, expected) in offset.iter().enumerate() {
            let scalar = update.scalar(k).unwrap();
            assert!((scalar.z - expected).abs() < 1e-6, "{k}: {}", scalar.z);
            let mut entries = scalar.h.entries();
            assert_eq!(
                (entries.next(), entries.next()),
                (Some((POS + k, 1.0)), None)
            );
            assert_eq!(scalar.r, 2.0);
        }
        assert!(update.scalar(3).is_none());
    }
}
