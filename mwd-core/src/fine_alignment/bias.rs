//! The sensor-bias states (39-state form): their random walk step by step
//! ([`BiasWalk`]), the gyros' instability as rate noise in navigation, and
//! the accelerometer biases taken at rest and put back
//! ([`AccelBiasSnapshot`]).

use super::config::BiasWalk;
use super::filter::FineAlignment;
use crate::error_model::{ACCEL_BIAS, GYRO_BIAS, STATES_WITH_BIASES};
use crate::kalman::FilterScalar;
use nalgebra::{Matrix3, SVector, Vector3};

/// The accelerometer biases' estimate (m/s^2, body axes) and covariance
/// at one step ([`FineAlignment::accel_bias`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AccelBiasSnapshot {
    pub estimate: Vector3<f64>,
    pub covariance: Matrix3<f64>,
    /// The random-walk variance added per axis up to then.
    pub(super) walk_added: [f64; 3],
}

impl<T: FilterScalar, const N: usize> FineAlignment<T, N> {
    /// Sets this step's bias random walk in `q` ([`BiasWalk`]); keeps the
    /// total added per bias.
    pub(super) fn scale_bias_walk(&mut self, q: &mut SVector<T, N>) {
        if N != STATES_WITH_BIASES {
            return;
        }
        let biases = &self.config.model.biases;
        let states = biases.accel.iter().chain(biases.gyro.iter());
        for (k, bias) in states.enumerate() {
            let i = ACCEL_BIAS + k; // the rate biases follow the accelerometers'
            let constant = self.bias_walk == BiasWalk::InstabilityAsRateNoise
                && (i == GYRO_BIAS || i == GYRO_BIAS + 2);
            let walk = if constant {
                0.0
            } else {
                bias.variance_per_step
            };
            q[i] = T::of(walk);
            self.bias_walk_added[k] += walk;
        }
    }

    /// How the bias random walk is added from the next step on
    /// ([`BiasWalk`]). Switching a filter that has run to
    /// [`BiasWalk::InstabilityAsRateNoise`] adds sigma^2 of the instability
    /// to the gyro bias variances: the estimate has absorbed the
    /// instability's value of the alignment, which from now on is not part
    /// of the constant it stands for. A fresh filter's initial variance
    /// already holds it.
    pub fn set_bias_walk(&mut self, walk: BiasWalk) {
        let switching = walk == BiasWalk::InstabilityAsRateNoise && self.bias_walk != walk;
        if switching && self.steps > 0 && N == STATES_WITH_BIASES {
            for axis in [0, 2] {
                let sigma = self.config.model.biases.gyro[axis].instability_sigma;
                let i = GYRO_BIAS + axis;
                self.filter.p[(i, i)] += T::of(sigma * sigma);
            }
        }
        self.bias_walk = walk;
    }

    /// The gyros' instability as white rate noise (x and z body axes,
    /// [`BiasWalk::InstabilityAsRateNoise`]): C_b^n diag(S_x, 0, S_z) C_n^b
    /// dt on the attitude error, S = 2 sigma^2 tau.
    pub(super) fn add_gyro_instability_noise(&mut self, c_bn: &Matrix3<f64>) {
        if self.bias_walk != BiasWalk::InstabilityAsRateNoise || N != STATES_WITH_BIASES {
            return;
        }
        let gyro = &self.config.model.biases.gyro;
        let dt = self.config.model.dt;
        // The sum of the two gyro axes' outer products (columns x and z of
        // C_b^n): a third of the multiplies of C D C^T.
        let (x, z) = (c_bn.column(0), c_bn.column(2));
        let q = x * x.transpose() * (gyro[0].instability_density * dt)
            + z * z.transpose() * (gyro[2].instability_density * dt);
        self.add_attitude_noise(&q);
    }

    /// The accelerometer-bias estimate (m/s^2, body axes) and its
    /// covariance now, to put back later; `None` in the 33-state form,
    /// which has no bias states.
    pub fn accel_bias(&self) -> Option<AccelBiasSnapshot> {
        if N != STATES_WITH_BIASES {
            return None;
        }
        let x = &self.filter.x;
        Some(AccelBiasSnapshot {
            estimate: Vector3::from_fn(|i, _| x[ACCEL_BIAS + i].as_f64()),
            covariance: Matrix3::from_fn(|i, j| {
                self.filter.p[(ACCEL_BIAS + i, ACCEL_BIAS + j)].as_f64()
            }),
            walk_added: [
                self.bias_walk_added[0],
                self.bias_walk_added[1],
                self.bias_walk_added[2],
            ],
        })
    }

    /// Puts back an accelerometer-bias estimate and covariance taken
    /// earlier ([`accel_bias`](Self::accel_bias)), grown by the random walk
    /// the filter has added since ([`BiasWalk`]) up to the instability's
    /// largest change, 2 sigma^2, with no correlation to
    /// the other states (which keeps P positive semi-definite: a principal
    /// block and a PSD block). The probe's stations use it: what the filter
    /// learns of the accelerometers while drilling is the bias plus the
    /// vibration's rectified share, which is gone at rest (derivation
    /// section 4f).
    pub fn restore_accel_bias(&mut self, snapshot: &AccelBiasSnapshot) {
        if N != STATES_WITH_BIASES {
            return;
        }
        self.forget_states(ACCEL_BIAS, 3);
        let p = &mut self.filter.p;
        for i in 0..3 {
            self.filter.x[ACCEL_BIAS + i] = T::of(snapshot.estimate[i]);
            for j in 0..3 {
                p[(ACCEL_BIAS + i, ACCEL_BIAS + j)] = T::of(snapshot.covariance[(i, j)]);
            }
            // The instability changes by at most 2 sigma^2 in variance
            // over any time (stationary Gauss-Markov: 2 sigma^2 (1 -
            // exp(-T/tau))); the walk over an hour of drilling adds 72.
            let sigma = self.config.model.biases.accel[i].instability_sigma;
            // (max and min, not clamp: clamp's check of its bounds panics
            // with the floats formatted, 24 KiB of the probe's flash)
            let walk = (self.bias_walk_added[i] - snapshot.walk_added[i])
                .max(0.0)
                .min(2.0 * sigma * sigma);
            p[(ACCEL_BIAS + i, ACCEL_BIAS + i)] += T::of(walk);
        }
    }
}
