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
    is_model_size, navigation_error_dynamics_with, EarthTerms, LinearizationPoint, SensorBiases,
    ACCEL_AR, ACCEL_BIAS, AR_ORDER, ATT, GYRO_AR, GYRO_BIAS, NAV_STATES, STATES,
    STATES_WITH_BIASES, VEL,
};
use crate::ar::{Ar4, ACCEL_DEFAULTS, GYRO_DEFAULTS};
use crate::kalman::{FilterScalar, Transition};
use crate::sensor_noise::ImuNoise;
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
            nav_per_step[super::POS + i] = position * dt;
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
        let dt = 0.05;
        Self {
            accel: ACCEL_DEFAULTS,
            gyro: GYRO_DEFAULTS,
            biases: SensorBiases::from_noise(&ImuNoise::scc1300(), dt),
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
        self.transition_with(&EarthTerms::at(&lp.position), lp)
    }

    /// The same with the geodetic scalars given (cached by the caller).
    pub fn transition_with<T: FilterScalar, const N: usize>(
        &self,
        earth: &EarthTerms,
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
        const { assert!(is_model_size(N), "the augmented model has 33 or 39 states") };
        let mut p = SMatrix::<T, N, N>::zeros();
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
        p
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

    /// Shifts one AR block of rows of `m` by its companion matrix.
    fn shift_ar_rows<const C: usize>(
        m: &mut SMatrix<T, N, C>,
        first: usize,
        last_row: &[T; AR_ORDER],
    ) {
        for col in 0..C {
            let mut newest = T::zero();
            for (j, a) in last_row.iter().enumerate() {
                newest += *a * m[(first + j, col)];
            }
            for j in 0..AR_ORDER - 1 {
                m[(first + j, col)] = m[(first + j + 1, col)];
            }
            m[(first + AR_ORDER - 1, col)] = newest;
        }
    }

    /// `m <- Phi m` for any number of columns, touching only the non-zero
    /// blocks: ~9*9*C + 2*9*C + 6*4*C multiplies (+ 2*9*C with the biases)
    /// instead of N*N*C. The bias rows are identity rows: left as they are.
    fn apply<const C: usize>(&self, m: &mut SMatrix<T, N, C>) {
        // Navigation rows first: they need the AR rows before their shift.
        // (F is dense in motion, and nearly so at rest through the sample's
        // specific force: a dense 9 x 9 product beats skipping zeros.)
        let mut nav_rows: SMatrix<T, 9, C> = self.nav * m.fixed_rows::<9>(0);
        if self.coupled {
            for axis in 0..3 {
                let fa = super::newest_ar_state(ACCEL_AR, axis);
                let wa = super::newest_ar_state(GYRO_AR, axis);
                for i in 0..3 {
                    let g = self.c_bn_dt[(i, axis)];
                    for col in 0..C {
                        nav_rows[(VEL + i, col)] += g * m[(fa, col)];
                        nav_rows[(ATT + i, col)] -= g * m[(wa, col)];
                    }
                    if Self::HAS_BIASES {
                        let (ba, bw) = (ACCEL_BIAS + axis, GYRO_BIAS + axis);
                        for col in 0..C {
                            nav_rows[(VEL + i, col)] += g * m[(ba, col)];
                            nav_rows[(ATT + i, col)] -= g * m[(bw, col)];
                        }
                    }
                }
            }
        }
        for axis in 0..3 {
            Self::shift_ar_rows(m, ACCEL_AR + axis * AR_ORDER, &self.accel_last_rows[axis]);
            Self::shift_ar_rows(m, GYRO_AR + axis * AR_ORDER, &self.gyro_last_rows[axis]);
        }
        m.fixed_rows_mut::<9>(0).copy_from(&nav_rows);
    }
}

impl<T: FilterScalar, const N: usize> Transition<T, N> for AugmentedTransition<T, N> {
    fn apply_to_matrix(&self, m: &mut SMatrix<T, N, N>) {
        self.apply(m);
    }
    fn apply_to_vector(&self, x: &mut SVector<T, N>) {
        self.apply(x);
    }
}
