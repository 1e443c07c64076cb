//! The difference measurement (eq. 21-24): backup output minus master
//! output, east and north velocity and latitude and longitude. The lever arm
//! between the two systems is ignored, as in the paper. Both the reduced
//! and the full model keep the velocity and position differences at the
//! same indices, so one type serves both filters.

use super::index::{DV_E, DV_N, D_LAT, D_LON};
use crate::kalman::{FilterScalar, Measurement, ScalarMeasurement, SparseRow};

/// z = (dv_E12, dv_N12, dL_12, dlambda_12) (eq. 23) with its noise.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DifferenceMeasurement<T> {
    /// Backup minus master east and north velocity (m/s), eq. 22.
    pub dv_east: T,
    pub dv_north: T,
    /// Backup minus master latitude and longitude (rad), eq. 21.
    pub d_lat: T,
    pub d_lon: T,
    /// Noise variance of each velocity difference ((m/s)^2).
    pub velocity_variance: T,
    /// Noise variance of each latitude and longitude difference (rad^2).
    pub position_variance: T,
}

impl<T: FilterScalar> Measurement<T> for DifferenceMeasurement<T> {
    fn len(&self) -> usize {
        4
    }

    /// The rows of H_r (eq. 24 as corrected by erratum RINS-4): each scalar
    /// selects one velocity or position difference state.
    fn scalar(&self, k: usize) -> Option<ScalarMeasurement<T>> {
        let (z, state, r) = match k {
            0 => (self.dv_east, DV_E, self.velocity_variance),
            1 => (self.dv_north, DV_N, self.velocity_variance),
            2 => (self.d_lat, D_LAT, self.position_variance),
            3 => (self.d_lon, D_LON, self.position_variance),
            _ => return None,
        };
        Some(ScalarMeasurement {
            z,
            h: SparseRow::select(state),
            r,
        })
    }
}

/// H_r of eq. 24 (corrected, erratum RINS-4) as a matrix, for the
/// observability analysis.
pub fn measurement_matrix<T: FilterScalar, const N: usize>() -> nalgebra::SMatrix<T, 4, N> {
    let mut h = nalgebra::SMatrix::zeros();
    for (row, state) in [DV_E, DV_N, D_LAT, D_LON].into_iter().enumerate() {
        h[(row, state)] = T::one();
    }
    h
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kalman::KalmanFilter;
    use nalgebra::SVector;

    #[test]
    fn rows_match_the_matrix_and_update_the_filter() {
        let m = DifferenceMeasurement {
            dv_east: 0.1,
            dv_north: -0.2,
            d_lat: 1e-7,
            d_lon: -2e-7,
            velocity_variance: 1e-4,
            position_variance: 1e-14,
        };
        let h = measurement_matrix::<f64, 8>();
        for k in 0..4 {
            let s = m.scalar(k).unwrap();
            let (i, c) = s.h.entries().next().unwrap();
            assert_eq!(h[(k, i)], c);
        }
        assert!(m.scalar(4).is_none());
        let mut kf = KalmanFilter::<f64, 8>::from_diagonal(&SVector::repeat(1.0));
        let report = kf.update(&m);
        assert_eq!(report.accepted, 4);
        assert!((kf.x[DV_E] - 0.1).abs() < 1e-3);
    }

    #[test]
    fn non_finite_data_is_refused() {
        let m = DifferenceMeasurement {
            dv_east: f64::NAN,
            dv_north: 0.0,
            d_lat: 0.0,
            d_lon: 0.0,
            velocity_variance: 1e-4,
            position_variance: 1e-14,
        };
        let mut kf = KalmanFilter::<f64, 8>::from_diagonal(&SVector::repeat(1.0));
        let report = kf.update(&m);
        assert_eq!((report.accepted, report.non_finite), (3, 1));
    }
}
