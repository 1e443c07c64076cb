//! The error dynamics of the master/backup difference (paper eq. 1-18),
//! east-north-up, vertical channel left out as in the paper.
//!
//! System 1 is the single-axis backup, system 2 the dual-axis master. Both
//! sit at the same true position and velocity (lever arm ignored, as in the
//! paper's eq. 21-22), so each one's attitude, velocity and position errors
//! obey the same linear navigation block (eq. 12-17, the standard psi-angle
//! model of Titterton and Weston, ch. 12) and their difference obeys it too,
//! driven by the difference of the sensor errors each system's body-to-
//! navigation rotation C_bi^n projects into the navigation frame.

use crate::earth::radii;
use crate::kalman::FilterScalar;
use nalgebra::{Matrix3, SMatrix};

/// States of the full augmented model (eq. 1): 3 + 2 + 2 + 3 + 3 + 2 + 2.
pub const FULL_STATES: usize = 17;
/// States of the reduced model (eq. 7).
pub const REDUCED_STATES: usize = 8;
/// Process-noise inputs (eq. 6): gyro noise x y z of system 1, of system 2,
/// horizontal accelerometer noise x y of system 1, of system 2.
pub const NOISE_INPUTS: usize = 10;
/// States of the navigation block (attitude 3, velocity 2, position 2).
const NAV: usize = 7;

/// The true motion the error model is linearised about (the paper's L, h,
/// v_E, v_N and f_E, f_N, f_U).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Motion {
    /// Latitude L (rad).
    pub lat: f64,
    /// Height h (m).
    pub height: f64,
    /// East and north velocity (m/s).
    pub v_east: f64,
    pub v_north: f64,
    /// Specific force east, north, up (m/s^2); at constant velocity
    /// (0, 0, g).
    pub specific_force_enu: [f64; 3],
}

impl Motion {
    /// Uniform motion at `speed` (m/s) along `course` (rad from north,
    /// clockwise) at latitude `lat` (rad), specific force (0, 0, `g`): the
    /// paper's observability case (section 2.3).
    pub fn uniform(lat: f64, height: f64, speed: f64, course: f64, g: f64) -> Self {
        let (s, c) = libm::sincos(course);
        Self {
            lat,
            height,
            v_east: speed * s,
            v_north: speed * c,
            specific_force_enu: [0.0, 0.0, g],
        }
    }
}

/// The navigation block of eq. 11 (F_1 .. F_8 of eq. 12-17): the rows and
/// columns of the attitude, velocity and position error (differences).
/// The paper's R_N is the meridian radius, its R_E the transverse one.
pub fn navigation_block<T: FilterScalar>(m: &Motion) -> SMatrix<T, 7, 7> {
    let r = radii(m.lat);
    let (rn, re) = (r.meridian + m.height, r.transverse + m.height);
    let (sin_l, cos_l) = libm::sincos(m.lat);
    let tan_l = sin_l / cos_l;
    let sec2 = 1.0 / (cos_l * cos_l);
    let w = crate::earth::EARTH_RATE;
    let (ve, vn) = (m.v_east, m.v_north);
    let [fe, fn_, fu] = m.specific_force_enu;
    let up_rate = ve * tan_l / re + w * sin_l;
    let east_rate = w * cos_l + ve / re;
    let rows: [[f64; NAV]; NAV] = [
        // F_1 | F_2 | F_3 (eq. 12-13)
        [0.0, up_rate, -east_rate, 0.0, -1.0 / rn, 0.0, 0.0],
        [-up_rate, 0.0, -vn / rn, 1.0 / re, 0.0, -w * sin_l, 0.0],
        [
            east_rate,
            vn / rn,
            0.0,
            tan_l / re,
            0.0,
            east_rate + ve * (sec2 - 1.0) / re,
            0.0,
        ],
        // F_4 | F_5 | F_6 (eq. 14-16)
        [
            0.0,
            -fu,
            fn_,
            vn * tan_l / re,
            up_rate + w * sin_l,
            2.0 * w * vn * cos_l + vn * ve * sec2 / re,
            0.0,
        ],
        [
            fu,
            0.0,
            -fe,
            -2.0 * up_rate,
            0.0,
            -2.0 * w * ve * cos_l - ve * ve * sec2 / re,
            0.0,
        ],
        // 0 | F_7 | F_8 (eq. 17)
        [0.0, 0.0, 0.0, 0.0, 1.0 / rn, 0.0, 0.0],
        [
            0.0,
            0.0,
            0.0,
            1.0 / (re * cos_l),
            0.0,
            ve * tan_l / (re * cos_l),
            0.0,
        ],
    ];
    SMatrix::from_fn(|i, j| T::of(rows[i][j]))
}

/// The full augmented model F (eq. 5 with the state of eq. 1): the
/// navigation block driven by -C_b1^n eps_1 + C_b2^n eps_2 (attitude) and
/// M C_b1^n M^T nabla_1 - M C_b2^n M^T nabla_2 (velocity), the biases
/// random constants. `c_b1`, `c_b2`: each system's body (rotating IMU) to
/// ENU rotation.
pub fn full_dynamics<T: FilterScalar>(
    m: &Motion,
    c_b1: &Matrix3<T>,
    c_b2: &Matrix3<T>,
) -> SMatrix<T, FULL_STATES, FULL_STATES> {
    use super::index::*;
    let mut f = SMatrix::<T, FULL_STATES, FULL_STATES>::zeros();
    f.fixed_view_mut::<7, 7>(0, 0)
        .copy_from(&navigation_block::<T>(m));
    f.fixed_view_mut::<3, 3>(PHI_E, EPS_1).copy_from(&(-c_b1));
    f.fixed_view_mut::<3, 3>(PHI_E, EPS_2).copy_from(c_b2);
    f.fixed_view_mut::<2, 2>(DV_E, NABLA_1)
        .copy_from(&c_b1.fixed_view::<2, 2>(0, 0));
    f.fixed_view_mut::<2, 2>(DV_E, NABLA_2)
        .copy_from(&(-c_b2.fixed_view::<2, 2>(0, 0)));
    f
}

/// The full model's noise input G (eq. 5-6), same structure as the bias
/// columns of [`full_dynamics`]: the noises drive what the biases drive.
pub fn full_noise_input<T: FilterScalar>(
    c_b1: &Matrix3<T>,
    c_b2: &Matrix3<T>,
) -> SMatrix<T, FULL_STATES, NOISE_INPUTS> {
    use super::index::*;
    let mut g = SMatrix::<T, FULL_STATES, NOISE_INPUTS>::zeros();
    g.fixed_view_mut::<3, 3>(PHI_E, 0).copy_from(&(-c_b1));
    g.fixed_view_mut::<3, 3>(PHI_E, 3).copy_from(c_b2);
    g.fixed_view_mut::<2, 2>(DV_E, 6)
        .copy_from(&c_b1.fixed_view::<2, 2>(0, 0));
    g.fixed_view_mut::<2, 2>(DV_E, 8)
        .copy_from(&(-c_b2.fixed_view::<2, 2>(0, 0)));
    g
}

/// The reduction T of eq. 8 (8 x 17): keeps the seven navigation states
/// and, of the ten biases, the backup's azimuth drift eps_z (T_22 picks the
/// third bias).
pub fn reduction<T: FilterScalar>() -> SMatrix<T, REDUCED_STATES, FULL_STATES> {
    let mut t = SMatrix::zeros();
    for i in 0..NAV {
        t[(i, i)] = T::one();
    }
    t[(super::index::DRIFT_Z, super::index::EPS_1 + 2)] = T::one();
    t
}

/// F_r of eq. 11 written directly: the navigation block with the drift
/// column C_b1^n N, N = (0, 0, -1) (the azimuth drift turns the attitude
/// about the backup's body z axis). Equals T F T^T (eq. 10).
pub fn reduced_dynamics<T: FilterScalar>(
    m: &Motion,
    c_b1: &Matrix3<T>,
) -> SMatrix<T, REDUCED_STATES, REDUCED_STATES> {
    let mut f = SMatrix::<T, REDUCED_STATES, REDUCED_STATES>::zeros();
    f.fixed_view_mut::<7, 7>(0, 0)
        .copy_from(&navigation_block::<T>(m));
    f.fixed_view_mut::<3, 1>(0, super::index::DRIFT_Z)
        .copy_from(&(-c_b1.column(2)));
    f
}

/// G_r of eq. 18 written directly (with erratum RINS-3: the master's velocity
/// block is -M C_b2^n M^T, 2 x 2). Equals T G (eq. 10).
pub fn reduced_noise_input<T: FilterScalar>(
    c_b1: &Matrix3<T>,
    c_b2: &Matrix3<T>,
) -> SMatrix<T, REDUCED_STATES, NOISE_INPUTS> {
    let mut g = SMatrix::<T, REDUCED_STATES, NOISE_INPUTS>::zeros();
    g.fixed_view_mut::<7, NOISE_INPUTS>(0, 0)
        .copy_from(&full_noise_input(c_b1, c_b2).fixed_view::<7, NOISE_INPUTS>(0, 0));
    g
}

/// The discrete transition Phi = exp(F dt) (eq. 32) by its Taylor series
/// to sixth order, in Horner form. Sixth and not second order because the
/// drift reaches the measured position only through a chain of four
/// couplings (drift -> phi_U -> phi_E -> dv_N -> dL): a shorter series
/// would drop its first contribution within a step. The largest rate in F
/// is the Schuler frequency (1.24e-3 rad/s); at dt = 10 s the first
/// omitted term is ~(1.24e-2)^7 / 5040 of a state.
pub fn transition<T: FilterScalar, const N: usize>(
    f: &SMatrix<T, N, N>,
    dt: T,
) -> SMatrix<T, N, N> {
    const ORDER: usize = 6;
    let a = f * dt;
    let identity = SMatrix::<T, N, N>::identity();
    let mut sum = identity;
    for k in (1..=ORDER).rev() {
        sum = identity + (a * sum) / T::of(k as f64);
    }
    sum
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::conventions::DEG;

    fn heading(angle: f64) -> Matrix3<f64> {
        // body-to-ENU for a level body whose y axis points `angle` east of
        // north (rotation about up by -angle)
        let (s, c) = libm::sincos(angle);
        Matrix3::new(c, s, 0.0, -s, c, 0.0, 0.0, 0.0, 1.0)
    }

    #[test]
    fn reduced_model_is_the_projection_of_the_full_one() {
        let m = Motion::uniform(32.0 * DEG, 0.0, 5.0, 60.0 * DEG, 9.79);
        let (c1, c2) = (
            heading(0.3),
            heading(1.1) * Matrix3::new(1.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, -1.0),
        );
        let t = reduction::<f64>();
        let diff_f = reduced_dynamics(&m, &c1) - t * full_dynamics(&m, &c1, &c2) * t.transpose();
        let diff_g = reduced_noise_input(&c1, &c2) - t * full_noise_input(&c1, &c2);
        assert_eq!(diff_f.amax(), 0.0);
        assert_eq!(diff_g.amax(), 0.0);
    }

    #[test]
    fn transition_matches_a_fine_product() {
        let m = Motion::uniform(45.0 * DEG, 0.0, 3.0, 0.0, 9.8);
        let f = reduced_dynamics::<f64>(&m, &heading(0.0));
        let coarse = transition(&f, 10.0);
        let mut fine = SMatrix::<f64, 8, 8>::identity();
        let step = transition(&f, 0.01);
        for _ in 0..1000 {
            fine = step * fine;
        }
        // entry by entry: the drift column's entries are tiny (per rad/s)
        for (c, f) in coarse.iter().zip(fine.iter()) {
            assert!((c - f).abs() <= 1e-6 * f.abs() + 1e-18, "{c} vs {f}");
        }
    }
}
