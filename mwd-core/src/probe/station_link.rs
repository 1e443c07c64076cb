//! How a station's errors are tied to the previous station's: the link the
//! survey needs to correlate the stations' azimuth errors (host-sim's
//! `survey_error::probe_station`).
//!
//! Each station's azimuth is the filter's: the heading carried through the
//! drilling from the station before, pulled toward the rate gyrocompass by
//! the station's earth-rate updates, which read the heading through the x
//! and z gyro biases the filter carries from station to station too. So a
//! station's azimuth error is not a scalar Markov chain: the bias
//! estimates' errors tie stations several apart (measured on the 1000 m
//! lateral with the high-end MEMS grade: 0.26 / 0.16 at 2 / 4 stations
//! apart where a chain in the azimuth alone gives 0.07 / 0.01,
//! docs/lateral-study.md). The link carries the three error states
//! `z = (azimuth, x gyro bias, z gyro bias)` instead: `cov(z_k)` and
//! `cov(z_k, z_(k-1))`, from which the survey runs the chain
//! `z_k = A_k z_(k-1) + w_k`, `A_k = cov(z_k, z_(k-1)) cov(z_(k-1))^-1`.
//!
//! The filter keeps `cov(x, z_(k-1))` from the previous station's survey
//! on (`kalman::CrossCovariances`). A station sends the survey of the
//! older of its last two checkpoints (`Station::to_send`), so each
//! checkpoint starts a snapshot of its own and the one sent becomes the
//! next station's "previous": three snapshots during a station, one while
//! drilling.

use crate::error_model::{ATT, GYRO_BIAS};
use crate::kalman::{FilterScalar, SparseRow, LINKED};
use nalgebra::Matrix3;

/// The snapshot of the previous station's sent survey.
pub(super) const PREVIOUS: usize = 0;
/// The station's last checkpoint.
pub(super) const CHECKPOINT: usize = 1;
/// The checkpoint before it (what the station sends).
pub(super) const SETTLED: usize = 2;

/// A station survey's link to the previous station's (module docs). Units:
/// rad for the azimuth, rad/s for the biases; f32 as the station frame's
/// sigmas (the biases' variances, ~1e-12, are far inside its range).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StationLink {
    /// The station this link belongs to.
    pub station: u16,
    /// The station it links back to; 0 when none (the first station after
    /// a start, or after the covariance was invalid).
    pub previous: u16,
    /// cov(z_k), symmetric, row-major (`[0][0]` is the survey's azimuth
    /// variance).
    pub covariance: [[f32; LINKED]; LINKED],
    /// cov(z_k, z_previous): row = this station's state, column = the
    /// previous one's; `None` when there is no previous.
    pub cross_previous: Option<[[f32; LINKED]; LINKED]>,
}

/// The rows of `z = L x`: the azimuth row of the station's angle Jacobian
/// (`super::station`) on the attitude error, and the x and z gyro biases.
pub(super) fn link_rows<T: FilterScalar>(jacobian: &Matrix3<f64>) -> [SparseRow<T>; LINKED] {
    let mut azimuth = SparseRow::empty();
    for i in 0..3 {
        azimuth.push(ATT + i, T::of(jacobian[(1, i)]));
    }
    [
        azimuth,
        SparseRow::select(GYRO_BIAS),
        SparseRow::select(GYRO_BIAS + 2),
    ]
}

/// `L P L^T` from the sparse rows.
pub(super) fn link_covariance<T: FilterScalar, const N: usize>(
    p: &nalgebra::SMatrix<T, N, N>,
    l: &[SparseRow<T>; LINKED],
) -> [[f32; LINKED]; LINKED] {
    core::array::from_fn(|r| {
        core::array::from_fn(|c| {
            let mut sum = T::zero();
            for (i, a) in l[r].entries() {
                for (j, b) in l[c].entries() {
                    sum += a * b * p[(i, j)];
                }
            }
            sum.as_f64() as f32
        })
    })
}
