//! The 33-state AR-augmented model and its structured discrete transition.
//!
//! Discrete transition (errata 2-3; derivation section 3):
//! ```text
//! Phi = [ I + F dt   Cf   Cw ]     Cf: dv rows <- +C_b^n dt (newest accel AR states)
//!       [ 0          A_f  0  ]     Cw: phi rows <- -C_b^n dt (newest rate AR states)
//!       [ 0          0    A_w]     A_f, A_w: blockdiag of three AR(4) companions
//! ```
//! The AR blocks are already discrete at the sample rate, so they are not
//! multiplied by dt. With [`Coupling::BlockDiagonalAsPublished`], Cf = Cw = 0
//! (the paper's eq. 43): the AR states then never reach the measurements.

use super::{
    navigation_error_dynamics_with, EarthTerms, LinearizationPoint, ACCEL_AR, AR_ORDER, ATT,
    GYRO_AR, NAV_STATES, STATES, VEL,
};
use crate::ar::{Ar4, ACCEL_DEFAULTS, GYRO_DEFAULTS};
use crate::kalman::{FilterScalar, Transition};
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

/// The augmented model: sensor AR models, sample interval, coupling.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AugmentedModel {
    /// Accelerometer error models, body x, y, z.
    pub accel: [Ar4; 3],
    /// Rate error models, body x, y (accelerometer-derived), z.
    pub gyro: [Ar4; 3],
    pub coupling: Coupling,
    /// Sample interval (s); the AR models must be fitted at this rate.
    pub dt: f64,
}

impl AugmentedModel {
    /// The paper's AR(4) models (Tables 4-5) at 20 Hz, coupled.
    pub fn paper() -> Self {
        Self {
            accel: ACCEL_DEFAULTS,
            gyro: GYRO_DEFAULTS,
            coupling: Coupling::SensorErrorsDriveNavigation,
            dt: 0.05,
        }
    }

    /// The discrete transition at a linearisation point.
    pub fn transition<T: FilterScalar>(&self, lp: &LinearizationPoint) -> AugmentedTransition<T> {
        self.transition_with(&EarthTerms::at(&lp.position), lp)
    }

    /// The same with the geodetic scalars given (cached by the caller).
    pub fn transition_with<T: FilterScalar>(
        &self,
        earth: &EarthTerms,
        lp: &LinearizationPoint,
    ) -> AugmentedTransition<T> {
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

    /// Diagonal discrete process noise: the navigation white noise, and each
    /// AR model's innovation variance on its newest state.
    pub fn process_noise<T: FilterScalar>(&self, noise: &ProcessNoise) -> SVector<T, STATES> {
        let mut q = SVector::<T, STATES>::zeros();
        for (i, v) in noise.nav_per_step.iter().enumerate() {
            q[i] = T::of(*v);
        }
        for axis in 0..3 {
            q[super::newest_ar_state(ACCEL_AR, axis)] = T::of(self.accel[axis].noise_variance);
            q[super::newest_ar_state(GYRO_AR, axis)] = T::of(self.gyro[axis].noise_variance);
        }
        q
    }

    /// Initial covariance: diagonal for the navigation errors, and each AR
    /// block at its stationary covariance (discrete Lyapunov), so the filter
    /// starts with the sensor errors it will actually meet. A non-stationary
    /// AR model gets a zero block.
    pub fn initial_covariance<T: FilterScalar>(
        &self,
        nav_diag: &[f64; NAV_STATES],
    ) -> SMatrix<T, STATES, STATES> {
        let mut p = SMatrix::<T, STATES, STATES>::zeros();
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
        p
    }
}

/// The structured discrete transition of the 33-state model.
#[derive(Debug, Clone, PartialEq)]
pub struct AugmentedTransition<T: FilterScalar> {
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

impl<T: FilterScalar> AugmentedTransition<T> {
    /// The same transition as a full matrix (tests, benchmarks, analysis).
    pub fn to_dense(&self) -> SMatrix<T, STATES, STATES> {
        let mut phi = SMatrix::<T, STATES, STATES>::zeros();
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
        if self.coupled {
            for axis in 0..3 {
                let fa = super::newest_ar_state(ACCEL_AR, axis);
                let wa = super::newest_ar_state(GYRO_AR, axis);
                for i in 0..3 {
                    phi[(VEL + i, fa)] = self.c_bn_dt[(i, axis)];
                    phi[(ATT + i, wa)] = -self.c_bn_dt[(i, axis)];
                }
            }
        }
        phi
    }

    /// Shifts one AR block of rows of `m` by its companion matrix.
    fn shift_ar_rows<const C: usize>(
        m: &mut SMatrix<T, STATES, C>,
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
    /// blocks: ~9*9*C + 2*9*C + 6*4*C multiplies instead of 33*33*C.
    fn apply<const C: usize>(&self, m: &mut SMatrix<T, STATES, C>) {
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

impl<T: FilterScalar> Transition<T, STATES> for AugmentedTransition<T> {
    fn apply_to_matrix(&self, m: &mut SMatrix<T, STATES, STATES>) {
        self.apply(m);
    }
    fn apply_to_vector(&self, x: &mut SVector<T, STATES>) {
        self.apply(x);
    }
}
