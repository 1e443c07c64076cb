//! The time update with the tool-axis rate held at the frame's
//! (`ToolAxisSource::AtRest`): the attitude error about the tool axis
//! stays where it is (derivation sections 4f, 4i).

use super::filter::FineAlignment;
use crate::error_model::{
    newest_ar_state, AugmentedTransition, ATT, GYRO_AR, GYRO_BIAS, NAV_STATES, STATES_WITH_BIASES,
};
use crate::kalman::{FilterScalar, KalmanFilter, Transition, LINKED, SNAPSHOTS};
use nalgebra::{Matrix3, SVector, Vector3};

impl<T: FilterScalar, const N: usize> FineAlignment<T, N> {
    /// Whether the tool-axis rate fed to the following steps is held at the
    /// frame's rate (`ToolAxisSource::AtRest`) rather than measured: the
    /// time update then leaves the attitude error about the tool axis
    /// where it is ([`predict_with_held_tool_axis`](Self::predict_with_held_tool_axis)).
    pub fn hold_tool_axis(&mut self, held: bool) {
        self.held_tool_axis = held;
    }

    /// The time update when the tool-axis rate is held: the rate fed to the
    /// mechanization about the tool axis t is the frame's at the computed
    /// attitude, t . (C~^T omega_in), so the computed tool turns about t
    /// exactly as the frame does, like the still true tool: the attitude
    /// error about t does not move, phi' = -(I - t t^T)(omega_in x phi) -
    /// (I - t t^T) C_b^n (b + e) (derivation section 4f). The transition is
    /// M = Phi - e w^T with e = (t, 0, ...) and w = Phi^T e - e (the
    /// tool-axis attitude row of Phi, less the identity), so that
    /// M P M^T = Phi P Phi^T - z e^T - e z^T + s e e^T, z = Phi P w,
    /// s = w^T P w: the structured time update plus a rank-2 correction of
    /// the three attitude rows and columns (~2 N^2 multiplies, not a second
    /// N^3 product). Without it the model expects the earth rate to turn a
    /// heading error into a drift about the tool axis that the held rate
    /// cancels, sees none at a station, and reads that as heading
    /// information it does not have. The process noise is held out of that
    /// row too, (I - e e^T) Q (I - e e^T) (derivation section 4i): no gyro
    /// senses the tool axis, so its angle random walk does not turn the
    /// held roll; added there, it kept the station toolface sigma at about
    /// twice its error after connections had taught the accelerometer bias
    /// across gravity.
    pub(super) fn predict_with_held_tool_axis(
        &mut self,
        phi: &AugmentedTransition<T, N>,
        q: &SVector<T, N>,
        c_bn: &Matrix3<f64>,
    ) {
        let tool_axis = Vector3::new(c_bn[(0, 1)], c_bn[(1, 1)], c_bn[(2, 1)]);
        predict_holding_axis(&mut self.filter, phi, q, &tool_axis);
    }
}

/// `filter`'s time update with the attitude error about the unit vector
/// `axis` (nav frame) held where it was: transition M = Phi - e w^T, e =
/// (axis, 0, ...), w = Phi^T e - e ([`FineAlignment::hold_tool_axis`]),
/// and process noise (I - e e^T) Q (I - e e^T) (`q` diagonal). The
/// structured Phi P Phi^T + Q plus the rank-2 correction
/// -z e^T - e z^T + s e e^T with z = Phi P w + Q e and
/// s = w^T P w + e^T Q e.
pub fn predict_holding_axis<T: FilterScalar, const N: usize>(
    filter: &mut KalmanFilter<T, N>,
    phi: &AugmentedTransition<T, N>,
    q: &SVector<T, N>,
    axis: &Vector3<f64>,
) {
    let t: [T; 3] = core::array::from_fn(|i| T::of(axis[i]));
    // w: the axis's attitude row of Phi (navigation block and the
    // rate-error couplings) less e.
    let mut w = SVector::<T, N>::zeros();
    for j in 0..NAV_STATES {
        let mut r = T::zero();
        for (i, ti) in t.iter().enumerate() {
            r += *ti * phi.nav[(ATT + i, j)];
        }
        w[j] = r;
    }
    for (i, ti) in t.iter().enumerate() {
        w[ATT + i] -= *ti;
    }
    if phi.coupled {
        for axis in 0..3 {
            let mut g = T::zero();
            for (i, ti) in t.iter().enumerate() {
                g += *ti * phi.c_bn_dt[(i, axis)];
            }
            w[newest_ar_state(GYRO_AR, axis)] = -g;
            if N == STATES_WITH_BIASES {
                w[GYRO_BIAS + axis] = -g;
            }
        }
    }
    let mut z = SVector::<T, N>::zeros();
    for (j, wj) in w.iter().enumerate() {
        if *wj != T::zero() {
            for i in 0..N {
                z[i] += filter.p[(i, j)] * *wj;
            }
        }
    }
    let mut s = w.dot(&z);
    let wx = w.dot(&filter.x);
    // The snapshots' cross-covariances take the same transition M = Phi -
    // e w^T: Phi G in `predict`, then the held rows less t (w^T G).
    let mut wg = [T::zero(); SNAPSHOTS * LINKED];
    for (wgc, column) in wg.iter_mut().zip(filter.cross.columns_mut()) {
        // (w's slice, not nalgebra's strided iterator: the same sum in the
        // same order, without a stride per element)
        *wgc = w
            .as_slice()
            .iter()
            .zip(column.iter())
            .fold(T::zero(), |acc, (a, b)| acc + *a * *b);
    }
    filter.predict(phi, q);
    for (wgc, column) in wg.iter().zip(filter.cross.columns_mut()) {
        for (k, tk) in t.iter().enumerate() {
            column[ATT + k] -= *tk * *wgc;
        }
    }
    phi.apply_to_vector(&mut z);
    // The held row's process noise is zero as well: x' = M x + (I - e e^T)
    // n (the held component is t . phi_k itself, with no sensor behind
    // it), so Q enters as (I - e e^T) Q (I - e e^T) = Q - (Q e) e^T -
    // e (Q e)^T + (e^T Q e) e e^T. With Q diagonal, Q e is t scaled by
    // the attitude entries of q: folded into z and s below.
    for (k, tk) in t.iter().enumerate() {
        let qe = q[ATT + k] * *tk;
        z[ATT + k] += qe;
        s += *tk * qe;
    }
    let p = &mut filter.p;
    for (k, tk) in t.iter().enumerate() {
        for i in 0..N {
            p[(i, ATT + k)] -= z[i] * *tk;
        }
    }
    for (k, tk) in t.iter().enumerate() {
        for j in 0..N {
            p[(ATT + k, j)] -= *tk * z[j];
        }
        for (l, tl) in t.iter().enumerate() {
            p[(ATT + k, ATT + l)] += s * *tk * *tl;
        }
        filter.x[ATT + k] -= *tk * wx;
    }
}
