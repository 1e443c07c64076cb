//! The sensor-bias states (39-state form): their random walk step by step
//! ([`BiasWalk`]), the gyros' instability as rate noise in navigation, and
//! the accelerometer biases learned at rest only
//! ([`FineAlignment::learn_accel_bias`]).

use super::config::BiasWalk;
use super::filter::FineAlignment;
use crate::error_model::{ACCEL_BIAS, GYRO_BIAS, STATES_WITH_BIASES};
use crate::kalman::FilterScalar;
use nalgebra::{Matrix3, SVector};

impl<T: FilterScalar, const N: usize> FineAlignment<T, N> {
    /// Sets this step's bias random walk in `q` ([`BiasWalk`]), capped for
    /// the accelerometer biases while they are not learned.
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
            let mut walk = if constant {
                0.0
            } else {
                bias.variance_per_step
            };
            // An accelerometer bias the measurements do not update (a
            // moving tool, `learn_accel_bias`) is not seen either: its
            // walk is the instability's, which changes by at most 2
            // sigma^2 in variance over any time (a stationary
            // Gauss-Markov process: 2 sigma^2 (1 - exp(-T/tau))); the
            // walk over an hour of drilling would add 72.
            if k < 3 && !self.learns_accel_bias() {
                let most = 2.0 * bias.instability_sigma * bias.instability_sigma;
                walk = walk.min((most - self.accel_walk_unlearned[k]).max(0.0));
                self.accel_walk_unlearned[k] += walk;
            }
            q[i] = T::of(walk);
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

    /// Whether the measurements update the accelerometer biases (`true`,
    /// the default), or leave them as consider states (`false`,
    /// `KalmanFilter::consider`): estimate and variance held, their
    /// covariance with the rest kept right, the walk capped at the
    /// instability's 2 sigma^2 ([`scale_bias_walk`](Self::scale_bias_walk)).
    /// The probe's navigator learns them at rest only: while the tool moves
    /// the constraints read the vibration's rectified force as bias, which
    /// is gone at rest and there inseparable from the tilt a station
    /// measures, so it would go straight into the toolface (derivation
    /// section 4f). Until 2026-12-07 the navigator put back the estimate of
    /// the last still cycle instead, uncorrelated with the rest: that
    /// dropped what the stations had tied between the bias, the tilt and
    /// the gyro biases, and the next station counted it again (derivation
    /// section 4l).
    pub fn learn_accel_bias(&mut self, learn: bool) {
        if N != STATES_WITH_BIASES {
            return;
        }
        if learn {
            self.filter.consider = 0..0;
        } else if self.filter.consider.is_empty() {
            self.filter.consider = ACCEL_BIAS..ACCEL_BIAS + 3;
            self.accel_walk_unlearned = [0.0; 3];
        }
    }

    /// Whether the accelerometer biases are learned now
    /// ([`learn_accel_bias`](Self::learn_accel_bias)).
    pub fn learns_accel_bias(&self) -> bool {
        self.filter.consider.is_empty()
    }
}
