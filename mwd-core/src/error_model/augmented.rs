//! The 33-state AR-augmented model (39 with sensor biases) and its
//! structured discrete transition.
//!
//! Discrete transition (errata 2-3; derivation sections 3 and 3b):
//! ```text
//! Phi = [ I + F dt   Cf   Cw   Cf   Cw ]   Cf: dv rows <- +C_b^n dt (newest accel AR
//!       [ 0          A_f  0    0    0  ]       states; accel bias states)
//!       [ 0          0    A_w  0    0  ]   Cw: phi rows <- -C_b^n dt (newest rate AR
//!       [ 0          0    0    I    0  ]       states; rate bias states)
//!       [ 0          0    0    0    I  ]   A_f, A_w: blockdiag of three AR(4) companions
//! ```
//! The last two block rows and columns (random-constant biases) exist only
//! in the 39-state form: the state size `N` (33 or 39, checked at compile
//! time) chooses. The AR blocks are already discrete at the sample rate, so
//! they are not multiplied by dt. With [`Coupling::BlockDiagonalAsPublished`],
//! every Cf = Cw = 0 (the paper's eq. 43): the AR states then never reach
//! the measurements.

use super::{
    is_model_size, navigation_error_dynamics_with, LinearizationPoint, SensorBiases, ACCEL_AR,
    ACCEL_BIAS, AR_ORDER, ATT, GYRO_AR, GYRO_BIAS, NAV_STATES, POS, STATES, STATES_WITH_BIASES,
    VEL,
};
use crate::ar::{Ar4, ACCEL_DEFAULTS, GYRO_DEFAULTS};
use crate::earth::LocalEarth;
use crate::kalman::{FilterScalar, Transition};
use crate::sensor_noise::ImuNoise;
use crate::timing::SAMPLE_INTERVAL_S;
use nalgebra::{Matrix3, SMatrix, SVector};

/// Whether the coloured sensor errors drive the navigation errors.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Coupling {
    /// Accelerometer AR output into dv through C_b^n, rate AR output into
    /// phi through -C_b^n (the physically right model).
    SensorErrorsDriveNavigation,
    /// The paper's eq. 43 as printed: AR blocks decoupled from the rest.
    BlockDiagonalAsPublished,
}

/// White process noise on the navigation-error states, per step (the AR
/// states get their own innovation variances from their models).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProcessNoise {
    /// Variance added to each navigation-error state per step, in the
    /// states' units squared (rad^2, (m/s)^2, m^2).
    pub nav_per_step: [f64; NAV_STATES],
}

impl ProcessNoise {
    /// From continuous white-noise densities: angular random walk (rad^2/s),
    /// velocity random walk ((m/s)^2/s) and position (m^2/s), times dt.
    pub fn from_densities(attitude: f64, velocity: f64, position: f64, dt: f64) -> Self {
        let mut nav_per_step = [0.0; NAV_STATES];
        for i in 0..3 {
            nav_per_step[ATT + i] = attitude * dt;
            nav_per_step[VEL + i] = velocity * dt;
            nav_per_step[POS + i] = position * dt;
        }
        Self { nav_per_step }
    }
}

/// The augmented model: sensor AR models, bias statistics, sample
/// interval, coupling. The filter's state size (33 or 39) decides whether
/// the bias states are part of it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AugmentedModel {
    /// Accelerometer error models, body x, y, z.
    pub accel: [Ar4; 3],
    /// Rate error models, body x, y (accelerometer-derived), z.
    pub gyro: [Ar4; 3],
    /// Bias states of the 39-state form (unused with 33 states).
    pub biases: SensorBiases,
    pub coupling: Coupling,
    /// Sample interval (s); the AR models must be fitted at this rate.
    pub dt: f64,
}

impl AugmentedModel {
    /// The paper's AR(4) models (Tables 4-5) at 20 Hz, coupled; bias
    /// statistics from the SCC1300 budget (`sensor_noise`).
    pub fn paper() -> Self {
        let dt = SAMPLE_INTERVAL_S;
        Self {
            accel: ACCEL_DEFAULTS,
            gyro: GYRO_DEFAULTS,
            biases: SensorBiases::from_noise(&ImuNoise::scc1300(), dt),
            coupling: Coupling::SensorErrorsDriveNavigation,
            dt,
        }
    }

    /// The model of an error budget `noise` at 20 Hz, coupled: its AR(4)
    /// models and bias statistics. `paper()` is this with the SCC1300
    /// budget. An axis without coloured noise gets a white AR model
    /// (zero coefficients) of a millionth of its white noise's variance
    /// per sample: the white noise itself is the process noise's
    /// (`FineAlignmentConfig::physical`), and the AR states keep a
    /// positive variance, which the covariance's health check asks of
    /// every state (`KalmanFilter::covariance_is_healthy`).
    pub fn from_noise(noise: &ImuNoise) -> Self {
        let dt = SAMPLE_INTERVAL_S;
        let ar = |axis: &crate::sensor_noise::AxisNoise| {
            let floor = (axis.white_density * axis.white_density / dt * 1e-6).max(1e-30);
            axis.coloured.unwrap_or(Ar4::new([0.0; AR_ORDER], floor))
        };
        Self {
            accel: noise.accel.each_ref().map(ar),
            gyro: noise.gyro.each_ref().map(ar),
            biases: SensorBiases::from_noise(noise, dt),
            coupling: Coupling::SensorErrorsDriveNavigation,
            dt,
        }
    }

    /// The discrete transition at a linearisation point, for `N` = 33
    /// ([`STATES`]) or 39 ([`STATES_WITH_BIASES`]) states.
    pub fn transition<T: FilterScalar, const N: usize>(
        &self,
        lp: &LinearizationPoint,
    ) -> AugmentedTransition<T, N> {
        self.transition_with(&LocalEarth::at(&lp.position), lp)
    }

    /// The same with the geodetic scalars given (cached by the caller).
    pub fn transition_with<T: FilterScalar, const N: usize>(
        &self,
        earth: &LocalEarth,
        lp: &LinearizationPoint,
    ) -> AugmentedTransition<T, N> {
        const { assert!(is_model_size(N), "the augmented model has 33 or 39 states") };
        let f = navigation_error_dynamics_with::<T>(earth, lp);
        let nav = SMatrix::<T, 9, 9>::identity() + f * T::of(self.dt); // eq. 15
        let last_row = |m: &Ar4| -> [T; AR_ORDER] {
            core::array::from_fn(|j| T::of(-m.coefficients[AR_ORDER - 1 - j]))
        };
        AugmentedTransition {
            nav,
            c_bn_dt: (lp.c_bn * self.dt).map(T::of),
            coupled: self.coupling == Coupling::SensorErrorsDriveNavigation,
            accel_last_rows: [
                last_row(&self.accel[0]),
                last_row(&self.accel[1]),
                last_row(&self.accel[2]),
            ],
            gyro_last_rows: [
                last_row(&self.gyro[0]),
                last_row(&self.gyro[1]),
                last_row(&self.gyro[2]),
            ],
        }
    }

    /// Diagonal discrete process noise: the navigation white noise, each
    /// AR model's innovation variance on its newest state, and (39 states)
    /// each bias's random-walk variance per step.
    pub fn process_noise<T: FilterScalar, const N: usize>(
        &self,
        noise: &ProcessNoise,
    ) -> SVector<T, N> {
        const { assert!(is_model_size(N), "the augmented model has 33 or 39 states") };
        let mut q = SVector::<T, N>::zeros();
        for (i, v) in noise.nav_per_step.iter().enumerate() {
            q[i] = T::of(*v);
        }
        for axis in 0..3 {
            q[super::newest_ar_state(ACCEL_AR, axis)] = T::of(self.accel[axis].noise_variance);
            q[super::newest_ar_state(GYRO_AR, axis)] = T::of(self.gyro[axis].noise_variance);
            if N == STATES_WITH_BIASES {
                q[ACCEL_BIAS + axis] = T::of(self.biases.accel[axis].variance_per_step);
                q[GYRO_BIAS + axis] = T::of(self.biases.gyro[axis].variance_per_step);
            }
        }
        q
    }

    /// Initial covariance: diagonal for the navigation errors, each AR
    /// block at its stationary covariance (discrete Lyapunov), so the filter
    /// starts with the sensor errors it will actually meet, and (39 states)
    /// each bias at its initial variance. A non-stationary AR model gets a
    /// zero block.
    pub fn initial_covariance<T: FilterScalar, const N: usize>(
        &self,
        nav_diag: &[f64; NAV_STATES],
    ) -> SMatrix<T, N, N> {
        let mut p = SMatrix::<T, N, N>::zeros();
        self.write_initial_covariance(nav_diag, &mut p);
        p
    }

    /// The same written into `p` (overwritten whole): on the probe a 39 x
    /// 39 matrix is 6 KiB of stack per temporary copy, so the filter is
    /// (re)initialised in place.
    pub fn write_initial_covariance<T: FilterScalar, const N: usize>(
        &self,
        nav_diag: &[f64; NAV_STATES],
        p: &mut SMatrix<T, N, N>,
    ) {
        const { assert!(is_model_size(N), "the augmented model has 33 or 39 states") };
        p.fill(T::zero());
        for (i, v) in nav_diag.iter().enumerate() {
            p[(i, i)] = T::of(*v);
        }
        let blocks = self
            .accel
            .iter()
            .map(|m| (ACCEL_AR, m))
            .chain(self.gyro.iter().map(|m| (GYRO_AR, m)));
        for (n, (first, model)) in blocks.enumerate() {
            let start = first + (n % 3) * AR_ORDER;
            if let Some(s) = model.stationary_state_covariance() {
                p.fixed_view_mut::<AR_ORDER, AR_ORDER>(start, start)
                    .copy_from(&s.map(T::of));
            }
        }
        if N == STATES_WITH_BIASES {
            for axis in 0..3 {
                let (a, g) = (self.biases.accel[axis], self.biases.gyro[axis]);
                p[(ACCEL_BIAS + axis, ACCEL_BIAS + axis)] =
                    T::of(a.initial_sigma * a.initial_sigma);
                p[(GYRO_BIAS + axis, GYRO_BIAS + axis)] = T::of(g.initial_sigma * g.initial_sigma);
            }
        }
    }
}

/// The structured discrete transition of the 33- or 39-state model.
#[derive(Debug, Clone, PartialEq)]
pub struct AugmentedTransition<T: FilterScalar, const N: usize = STATES> {
    /// I + F dt of the navigation errors.
    pub nav: SMatrix<T, 9, 9>,
    /// C_b^n dt, the coupling gain.
    pub c_bn_dt: Matrix3<T>,
    pub coupled: bool,
    /// Companion last rows `[-a4 -a3 -a2 -a1]` per accelerometer axis.
    pub accel_last_rows: [[T; AR_ORDER]; 3],
    /// Companion last rows per rate axis.
    pub gyro_last_rows: [[T; AR_ORDER]; 3],
}

impl<T: FilterScalar, const N: usize> AugmentedTransition<T, N> {
    /// Whether the six bias states are part of the state.
    const HAS_BIASES: bool = N == STATES_WITH_BIASES;

    /// The same transition as a full matrix (tests, benchmarks, analysis).
    pub fn to_dense(&self) -> SMatrix<T, N, N> {
        let mut phi = SMatrix::<T, N, N>::zeros();
        phi.fixed_view_mut::<9, 9>(0, 0).copy_from(&self.nav);
        for axis in 0..3 {
            for (first, rows) in [
                (ACCEL_AR, &self.accel_last_rows),
                (GYRO_AR, &self.gyro_last_rows),
            ] {
                let b = first + axis * AR_ORDER;
                for j in 0..AR_ORDER - 1 {
                    phi[(b + j, b + j + 1)] = T::one();
                }
                for j in 0..AR_ORDER {
                    phi[(b + AR_ORDER - 1, b + j)] = rows[axis][j];
                }
            }
        }
        if Self::HAS_BIASES {
            // Random constants (plus random walk in Q): identity blocks.
            for i in ACCEL_BIAS..STATES_WITH_BIASES {
                phi[(i, i)] = T::one();
            }
        }
        if self.coupled {
            for axis in 0..3 {
                let fa = super::newest_ar_state(ACCEL_AR, axis);
                let wa = super::newest_ar_state(GYRO_AR, axis);
                for i in 0..3 {
                    phi[(VEL + i, fa)] = self.c_bn_dt[(i, axis)];
                    phi[(ATT + i, wa)] = -self.c_bn_dt[(i, axis)];
                    if Self::HAS_BIASES {
                        phi[(VEL + i, ACCEL_BIAS + axis)] = self.c_bn_dt[(i, axis)];
                        phi[(ATT + i, GYRO_BIAS + axis)] = -self.c_bn_dt[(i, axis)];
                    }
                }
            }
        }
        phi
    }

    /// Whether every entry of `nav` outside [`NAV_NONZERO`] is zero, as in
    /// every transition the model builds. A hand-made `nav` without that
    /// structure gets the dense 9 x 9 product instead.
    fn nav_is_structured(&self) -> bool {
        (0..NAV_STATES)
            .all(|i| (0..NAV_STATES).all(|j| NAV_NONZERO[i][j] || self.nav[(i, j)] == T::zero()))
    }

    /// Row `i` of `nav` times the navigation part of column `x`, over the
    /// entries that can be non-zero (all of them unless `STRUCTURED`), in
    /// column order: the dense product's sum without its zero terms.
    #[inline(always)]
    fn nav_row<const STRUCTURED: bool>(&self, i: usize, x: &[T; N]) -> T {
        let mut acc = T::zero();
        for j in 0..NAV_STATES {
            if !STRUCTURED || NAV_NONZERO[i][j] {
                acc += self.nav[(i, j)] * x[j];
            }
        }
        acc
    }

    /// Shifts the AR block of rows starting at `first` of one column by its
    /// companion matrix.
    #[inline(always)]
    fn shift_ar_block(x: &mut [T; N], first: usize, last_row: &[T; AR_ORDER]) {
        let mut newest = T::zero();
        for (j, a) in last_row.iter().enumerate() {
            newest += *a * x[first + j];
        }
        for j in 0..AR_ORDER - 1 {
            x[first + j] = x[first + j + 1];
        }
        x[first + AR_ORDER - 1] = newest;
    }

    /// `x <- Phi x` for one column `x` (length `N`).
    #[inline(always)]
    fn apply_column<const STRUCTURED: bool>(&self, x: &mut [T; N]) {
        // Navigation rows first: they need the AR rows before their shift.
        let mut nav = [T::zero(); NAV_STATES];
        for (i, v) in nav.iter_mut().enumerate() {
            *v = self.nav_row::<STRUCTURED>(i, x);
        }
        if self.coupled {
            for axis in 0..3 {
                let fa = x[super::newest_ar_state(ACCEL_AR, axis)];
                let wa = x[super::newest_ar_state(GYRO_AR, axis)];
                let (ba, bw) = if Self::HAS_BIASES {
                    (x[ACCEL_BIAS + axis], x[GYRO_BIAS + axis])
                } else {
                    (T::zero(), T::zero())
                };
                for i in 0..3 {
                    let g = self.c_bn_dt[(i, axis)];
                    nav[VEL + i] += g * fa;
                    nav[ATT + i] -= g * wa;
                    if Self::HAS_BIASES {
                        nav[VEL + i] += g * ba;
                        nav[ATT + i] -= g * bw;
                    }
                }
            }
        }
        // The bias rows are identity rows: left as they are.
        for axis in 0..3 {
            Self::shift_ar_block(x, ACCEL_AR + axis * AR_ORDER, &self.accel_last_rows[axis]);
            Self::shift_ar_block(x, GYRO_AR + axis * AR_ORDER, &self.gyro_last_rows[axis]);
        }
        x[..NAV_STATES].copy_from_slice(&nav);
    }

    /// `m <- Phi m` for any number of columns, column by column, touching
    /// only the non-zero blocks and, in the navigation block, only the
    /// entries that can be non-zero: 47 of the 9 x 9 ([`NAV_NONZERO`]),
    /// 2*9 coupling (+ 2*9 with the biases) and 6*4 AR multiplies per
    /// column instead of N.
    fn apply<const C: usize>(&self, m: &mut SMatrix<T, N, C>) {
        if self.nav_is_structured() {
            for x in m.data.0.iter_mut() {
                self.apply_column::<true>(x);
            }
        } else {
            for x in m.data.0.iter_mut() {
                self.apply_column::<false>(x);
            }
        }
    }

    /// `m <- Phi m` where only the lower triangle (row >= column) of the
    /// result is wanted. Column `c >= 9` of it has no navigation rows there:
    /// only the AR blocks reaching row `c` are shifted (the bias rows are
    /// identity rows), and only rows from the block's first one down are
    /// read. The upper triangle is left partly stale.
    fn apply_lower(&self, m: &mut SMatrix<T, N, N>, structured: bool) {
        for (c, x) in m.data.0.iter_mut().enumerate() {
            if c < NAV_STATES {
                if structured {
                    self.apply_column::<true>(x);
                } else {
                    self.apply_column::<false>(x);
                }
                continue;
            }
            for axis in 0..3 {
                let first = ACCEL_AR + axis * AR_ORDER;
                if first + AR_ORDER > c {
                    Self::shift_ar_block(x, first, &self.accel_last_rows[axis]);
                }
                let first = GYRO_AR + axis * AR_ORDER;
                if first + AR_ORDER > c {
                    Self::shift_ar_block(x, first, &self.gyro_last_rows[axis]);
                }
            }
        }
    }

    /// `m <- m Phi^T` by column operations (column `i` of the result
    /// combines the columns of `m` with row `i` of Phi), for a structured
    /// `nav`; the AR columns only from the first row of their block down,
    /// the part [`apply_lower`](Self::apply_lower) reads afterwards (the
    /// rows above are left stale). Phi (P Phi^T) needs no transpose of P.
    fn right_transposed_for_lower<const COUPLED: bool>(&self, m: &mut SMatrix<T, N, N>) {
        let cols = &mut m.data.0;
        // The navigation columns read the old columns: formed aside first.
        let mut nav = [[T::zero(); N]; NAV_STATES];
        self.nav_column::<0, COUPLED>(cols, &mut nav[0]);
        self.nav_column::<1, COUPLED>(cols, &mut nav[1]);
        self.nav_column::<2, COUPLED>(cols, &mut nav[2]);
        self.nav_column::<3, COUPLED>(cols, &mut nav[3]);
        self.nav_column::<4, COUPLED>(cols, &mut nav[4]);
        self.nav_column::<5, COUPLED>(cols, &mut nav[5]);
        self.nav_column::<6, COUPLED>(cols, &mut nav[6]);
        self.nav_column::<7, COUPLED>(cols, &mut nav[7]);
        self.nav_column::<8, COUPLED>(cols, &mut nav[8]);
        for axis in 0..3 {
            let first = ACCEL_AR + axis * AR_ORDER;
            Self::shift_ar_columns(cols, first, &self.accel_last_rows[axis]);
            let first = GYRO_AR + axis * AR_ORDER;
            Self::shift_ar_columns(cols, first, &self.gyro_last_rows[axis]);
        }
        // The bias columns (identity rows of Phi) stay as they are.
        cols[..NAV_STATES].copy_from_slice(&nav);
    }

    /// Column `I` of `m Phi^T`: row `I` of the structured `nav` and of the
    /// coupling (+C_b^n dt on the accelerometer AR and bias columns for the
    /// velocity rows, -C_b^n dt on the rate ones for the attitude rows).
    #[inline(always)]
    fn nav_column<const I: usize, const COUPLED: bool>(
        &self,
        cols: &[[T; N]; N],
        out: &mut [T; N],
    ) {
        let coef: [T; NAV_STATES] = core::array::from_fn(|j| self.nav[(I, j)]);
        let couples = COUPLED && I < POS;
        let (ar, bias, sign) = if I >= VEL {
            (ACCEL_AR, ACCEL_BIAS, T::one())
        } else {
            (GYRO_AR, GYRO_BIAS, -T::one())
        };
        let row = I % 3;
        let g: [T; 3] = core::array::from_fn(|axis| sign * self.c_bn_dt[(row, axis)]);
        for (e, o) in out.iter_mut().enumerate() {
            let mut acc = T::zero();
            for (j, c) in coef.iter().enumerate() {
                if NAV_NONZERO[I][j] {
                    acc += *c * cols[j][e];
                }
            }
            if couples {
                for (axis, ga) in g.iter().enumerate() {
                    acc += *ga * cols[super::newest_ar_state(ar, axis)][e];
                    if Self::HAS_BIASES {
                        acc += *ga * cols[bias + axis][e];
                    }
                }
            }
            *o = acc;
        }
    }

    /// The AR block of columns starting at `first` of `m Phi^T`: the
    /// columns shift by one and the newest is the companion's last row
    /// applied to the old ones; rows from `first` down only.
    #[inline(always)]
    fn shift_ar_columns(cols: &mut [[T; N]; N], first: usize, last_row: &[T; AR_ORDER]) {
        if let [c0, c1, c2, c3] = &mut cols[first..first + AR_ORDER] {
            let [a0, a1, a2, a3] = *last_row;
            for e in first..N {
                let newest = a0 * c0[e] + a1 * c1[e] + a2 * c2[e] + a3 * c3[e];
                c0[e] = c1[e];
                c1[e] = c2[e];
                c2[e] = c3[e];
                c3[e] = newest;
            }
        }
    }

    /// `p <- Phi p Phi^T`, lower triangle (see [`Transition::propagate_lower`]).
    fn propagate_lower(&self, p: &mut SMatrix<T, N, N>) {
        if !self.nav_is_structured() {
            self.apply(p);
            p.transpose_mut();
            self.apply_lower(p, false);
        } else {
            if self.coupled {
                self.right_transposed_for_lower::<true>(p);
            } else {
                self.right_transposed_for_lower::<false>(p);
            }
            self.apply_lower(p, true);
        }
    }
}

/// Where I + F dt can be non-zero (`navigation_error_dynamics_with`,
/// derivation section 2), by row and column; everything else is zero for
/// any linearisation point. Per block:
/// phi <- phi: I - [w_in x] dt, full; phi <- dv: only (N,E), (E,N), (D,E)
/// (d omega_en / dv); phi <- dp: no dpE column, no (E,N);
/// dv <- phi: [f x] dt, zero diagonal; dv <- dv: full; dv <- dp: no dpE
/// column; dp <- phi: zero; dp <- dv: I dt; dp <- dp: I + F33 dt with
/// rows (1 0 x), (x x x), (0 0 1).
#[rustfmt::skip]
const NAV_NONZERO: [[bool; NAV_STATES]; NAV_STATES] = {
    const X: bool = true;
    const O: bool = false;
    [
        // phiN phiE phiD dvN dvE dvD dpN dpE dpD
        [X, X, X,  O, X, O,  X, O, X], // phiN
        [X, X, X,  X, O, O,  O, O, X], // phiE
        [X, X, X,  O, X, O,  X, O, X], // phiD
        [O, X, X,  X, X, X,  X, O, X], // dvN
        [X, O, X,  X, X, X,  X, O, X], // dvE
        [X, X, O,  X, X, X,  X, O, X], // dvD
        [O, O, O,  X, O, O,  X, O, X], // dpN
        [O, O, O,  O, X, O,  X, X, X], // dpE
        [O, O, O,  O, O, X,  O, O, X], // dpD
    ]
};

impl<T: FilterScalar, const N: usize> Transition<T, N> for AugmentedTransition<T, N> {
    fn apply_to_matrix(&self, m: &mut SMatrix<T, N, N>) {
        self.apply(m);
    }
    fn propagate_lower(&self, p: &mut SMatrix<T, N, N>) {
        AugmentedTransition::propagate_lower(self, p);
    }
    fn apply_to_vector(&self, x: &mut SVector<T, N>) {
        self.apply(x);
    }
    /// In place, with one look at `nav`'s structure for all of them (the
    /// probe's drilling cycle keeps up to nine such columns).
    fn apply_to_columns<'a>(&self, columns: impl Iterator<Item = &'a mut [T; N]>)
    where
        T: 'a,
    {
        if self.nav_is_structured() {
            columns.for_each(|x| self.apply_column::<true>(x));
        } else {
            columns.for_each(|x| self.apply_column::<false>(x));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::earth::{gravity_n, Position};
    use nalgebra::Vector3;

    fn moving_point() -> LinearizationPoint {
        let position = Position::new(0.7, 0.3, 150.0);
        LinearizationPoint {
            c_bn: nalgebra::Rotation3::from_euler_angles(0.2, -0.4, 2.1).into_inner(),
            velocity_n: Vector3::new(2.0, -3.0, 0.7),
            position,
            specific_force_n: -gravity_n(&position) + Vector3::new(0.3, -0.1, 0.2),
        }
    }

    /// A symmetric positive definite test matrix with entries of mixed size.
    fn covariance<const N: usize>() -> SMatrix<f64, N, N> {
        let l =
            SMatrix::<f64, N, N>::from_fn(|i, j| libm::sin(1.0 + 3.7 * i as f64 + 0.9 * j as f64));
        l * l.transpose() + SMatrix::identity() * 1e-3
    }

    fn lower_rel_diff<const N: usize>(a: &SMatrix<f64, N, N>, b: &SMatrix<f64, N, N>) -> f64 {
        let mut worst = 0.0f64;
        for j in 0..N {
            for i in j..N {
                worst = worst.max((a[(i, j)] - b[(i, j)]).abs());
            }
        }
        worst / b.amax()
    }

    fn check_against_dense<const N: usize>(phi: &AugmentedTransition<f64, N>) {
        let dense = phi.to_dense();
        let p = covariance::<N>();
        let mut m = p;
        phi.apply(&mut m);
        assert!((m - dense * p).amax() <= 1e-14 * (dense * p).amax());
        let mut m = p;
        phi.propagate_lower(&mut m);
        let reference = dense * p * dense.transpose();
        assert!(lower_rel_diff(&m, &reference) < 1e-14);
        // in place on columns: the same bits as one vector at a time
        let mut columns: [[f64; N]; 3] = core::array::from_fn(|c| p.data.0[c * 5 % N]);
        let expected = columns.map(|c| {
            let mut v = SVector::<f64, N>::from(c);
            phi.apply_to_vector(&mut v);
            v
        });
        phi.apply_to_columns(columns.iter_mut());
        for (got, want) in columns.iter().zip(&expected) {
            assert_eq!(got.as_slice(), want.as_slice());
        }
    }

    #[test]
    fn the_paper_model_is_the_scc1300_budget_s() {
        assert_eq!(
            AugmentedModel::from_noise(&ImuNoise::scc1300()),
            AugmentedModel::paper()
        );
        // An axis without coloured noise: a white AR block of a millionth
        // of the white noise.
        let mut quiet = ImuNoise::scc1300();
        quiet.gyro[0].coloured = None;
        let model = AugmentedModel::from_noise(&quiet);
        let white = quiet.gyro[0].white_density.powi(2) / SAMPLE_INTERVAL_S;
        assert!((model.gyro[0].noise_variance / white - 1e-6).abs() < 1e-12);
        assert_eq!(model.gyro[0].coefficients, [0.0; AR_ORDER]);
        assert_eq!(model.gyro[2], AugmentedModel::paper().gyro[2]);
    }

    #[test]
    fn model_transitions_have_the_assumed_navigation_structure() {
        let model = AugmentedModel::paper();
        let phi = model.transition::<f64, STATES>(&moving_point());
        assert!(phi.nav_is_structured());
        // Every entry the structure allows is in use somewhere: the table
        // is not looser than the model.
        for (i, row) in NAV_NONZERO.iter().enumerate() {
            for (j, allowed) in row.iter().enumerate() {
                assert_eq!(*allowed, phi.nav[(i, j)] != 0.0, "({i}, {j})");
            }
        }
    }

    #[test]
    fn structured_products_match_dense_coupled_and_not_33_and_39_states() {
        for coupling in [
            Coupling::SensorErrorsDriveNavigation,
            Coupling::BlockDiagonalAsPublished,
        ] {
            let mut model = AugmentedModel::paper();
            model.coupling = coupling;
            check_against_dense(&model.transition::<f64, STATES>(&moving_point()));
            check_against_dense(&model.transition::<f64, STATES_WITH_BIASES>(&moving_point()));
        }
    }

    #[test]
    fn a_hand_made_dense_navigation_block_gets_the_dense_product() {
        let model = AugmentedModel::paper();
        let mut phi = model.transition::<f64, STATES>(&moving_point());
        phi.nav = SMatrix::from_fn(|i, j| 0.1 * libm::cos(2.0 * i as f64 + j as f64));
        assert!(!phi.nav_is_structured());
        check_against_dense(&phi);
        let mut phi = model.transition::<f64, STATES_WITH_BIASES>(&moving_point());
        phi.nav[(POS + 2, ATT)] = 0.5; // one entry outside the structure
        assert!(!phi.nav_is_structured());
        check_against_dense(&phi);
    }
}
