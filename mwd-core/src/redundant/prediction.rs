//! The backup's error prediction (eq. 28-32) and its compensation (eq. 33).
//!
//! The backup's own errors x_1 = (phi_1, dv_1, dp_1, eps_z) obey the same
//! model as the difference (A_1 = F_r, eq. 30). The paper starts the
//! prediction at x_1(t_0) = 0 (eq. 32); as printed that predicts nothing,
//! since Phi 0 = 0 forever (erratum RINS-6). The drift state must start at the
//! filter's estimate: x_1(t_0) = (0, ..., 0, eps_z_hat). The model is
//! linear, so the prediction is eps_z_hat times the response s(t) to a unit
//! drift, s(t_0) = e_8, s(t_k+1) = Phi_1 s(t_k): the response is propagated
//! from the start of navigation and scaled by the latest estimate, which
//! stays frozen once the master has failed (nothing updates it then).
//! Only the drift's systematic error is predicted, not the random walk
//! (the paper's remark after eq. 32).

use super::index::{DRIFT_Z, DV_E, DV_N, D_LAT, D_LON};
use super::model::REDUCED_STATES as N;
use crate::kalman::FilterScalar;
use nalgebra::{SMatrix, SVector};

/// The response of the backup's errors to a unit azimuth drift.
#[derive(Debug, Clone, PartialEq)]
pub struct DriftPrediction<T: FilterScalar> {
    response: SVector<T, N>,
}

impl<T: FilterScalar> Default for DriftPrediction<T> {
    fn default() -> Self {
        Self::new()
    }
}

impl<T: FilterScalar> DriftPrediction<T> {
    /// At the start of navigation: s = e_8.
    pub fn new() -> Self {
        let mut response = SVector::zeros();
        response[DRIFT_Z] = T::one();
        Self { response }
    }

    /// One step of eq. 31 with the backup's transition Phi_1 over it.
    pub fn propagate(&mut self, phi: &SMatrix<T, N, N>) {
        self.response = phi * self.response;
    }

    /// The predicted backup error x_1_hat for a drift estimate (rad/s).
    pub fn predicted(&self, drift_estimate: T) -> SVector<T, N> {
        self.response * drift_estimate
    }
}

/// The backup's navigation output (the quantities eq. 33 corrects).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BackupOutput {
    /// Latitude and longitude (rad).
    pub lat: f64,
    pub lon: f64,
    /// East and north velocity (m/s).
    pub v_east: f64,
    pub v_north: f64,
}

/// Eq. 33: the predicted errors subtracted from the output.
pub fn compensate<T: FilterScalar>(
    output: &BackupOutput,
    predicted: &SVector<T, N>,
) -> BackupOutput {
    BackupOutput {
        lat: output.lat - predicted[D_LAT].as_f64(),
        lon: output.lon - predicted[D_LON].as_f64(),
        v_east: output.v_east - predicted[DV_E].as_f64(),
        v_north: output.v_north - predicted[DV_N].as_f64(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::conventions::DEG;
    use crate::redundant::model::{reduced_dynamics, transition, Motion};
    use nalgebra::Matrix3;

    #[test]
    fn compensation_removes_a_predicted_drift_error_exactly() {
        // truth: a backup with only an azimuth drift, propagated by the same
        // model; the prediction with the exact drift cancels it.
        let m = Motion::uniform(30.0 * DEG, 0.0, 0.0, 0.0, 9.79);
        let f = reduced_dynamics::<f64>(&m, &Matrix3::identity());
        let phi = transition(&f, 10.0);
        let drift = 0.0003 * DEG / 3600.0;
        let mut truth = SVector::<f64, 8>::zeros();
        truth[DRIFT_Z] = drift;
        let mut p = DriftPrediction::<f64>::new();
        for _ in 0..(24 * 360) {
            truth = phi * truth;
            p.propagate(&phi);
        }
        let metres = truth[D_LON] * 6.4e6 * libm::cos(30.0 * DEG);
        assert!(metres.abs() > 10.0, "the drift must matter: {metres} m");
        let out = BackupOutput {
            lat: 0.5 + truth[D_LAT],
            lon: 2.0 + truth[D_LON],
            v_east: truth[DV_E],
            v_north: truth[DV_N],
        };
        let fixed = compensate(&out, &p.predicted(drift));
        assert!((fixed.lat - 0.5).abs() < 1e-15 && (fixed.lon - 2.0).abs() < 1e-15);
        assert!(fixed.v_east.abs() < 1e-12 && fixed.v_north.abs() < 1e-12);
    }
}
