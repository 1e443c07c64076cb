//! Error-state Kalman filter, fixed size, no heap, generic over the scalar
//! (f32 on the probe, f64 on the host; paper section 2.4).
//!
//! - Time update (eq. 17-18) through a [`Transition`], which applies the
//!   discrete transition Phi (eq. 15) to a matrix from the left and forms
//!   the lower triangle of Phi P Phi^T, mirrored so P stays exactly
//!   symmetric. The structured 33- and 39-state transition of
//!   `error_model` does that in a fraction of the dense cost;
//!   [`dense::DenseTransition`] is the textbook reference.
//! - Measurement update (eq. 19-21) one scalar at a time with a sparse
//!   measurement row, the Joseph covariance (eq. 21) expanded to
//!   P - k c^T - c k^T + s k k^T, computed on the upper triangle and
//!   mirrored so P stays exactly symmetric.
//! - Every scalar is checked before it touches the filter: non-finite data
//!   or a non-positive innovation variance is rejected, and an optional
//!   chi-square gate on the normalised innovation squared rejects outliers.

mod cross;
pub mod dense;
mod filter;
mod measurement;
mod numeric;
mod outcome;
mod scalar;
mod transition;

pub use cross::{CrossCovariances, LINKED, SNAPSHOTS};
pub use filter::{KalmanFilter, CORRELATION_SLACK};
pub use measurement::{Measurement, ScalarMeasurement, SparseRow, Stacked, MAX_ROW_NONZEROS};
pub use numeric::{std_dev_of, FilterScalar};
pub use outcome::{ScalarOutcome, UpdateReport};
pub use transition::Transition;
