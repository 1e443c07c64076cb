//! Autoregressive AR(p) noise models (paper eq. 23, 31-42).
//!
//! Sign convention of the paper and of MATLAB `aryule`:
//! `z_k = -(a_1 z_{k-1} + ... + a_p z_{k-p}) + e_k`, with `e_k` white of
//! variance `noise_variance` (SI units squared). All methods are fixed-size
//! and allocation-free so the probe can use them too.
//!
//! State ordering of the companion form: oldest first,
//! `x_k = [z_{k-p+1}, ..., z_{k-1}, z_k]` (the paper's Upsilon_1 = df_{k-3} ..
//! Upsilon_4 = df_k, eq. 33-36). With that ordering the last row of the
//! companion matrix is `[-a_p ... -a_1]`; the paper's eq. 41-42 print
//! `[-a_1 ... -a_p]`, which is erratum 1 in `docs/paper-errata.md`.

use crate::conventions::DEG;
use nalgebra::{SMatrix, SVector};

/// An AR(p) model in the `aryule` convention.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArModel<const P: usize> {
    /// `a_1 .. a_p`: `z_k = -sum a_i z_{k-i} + e_k`.
    pub coefficients: [f64; P],
    /// Variance of the driving white noise `e_k` (the paper's beta), SI units squared.
    pub noise_variance: f64,
}

/// The paper's order (Tables 4 and 5).
pub type Ar4 = ArModel<4>;

/// Converts a variance in (deg/s)^2 to (rad/s)^2.
const DEG2_TO_RAD2: f64 = DEG * DEG;

/// Paper Table 4, accelerometer X (body x, right). Beta in (m/s^2)^2.
pub const ACCEL_X: Ar4 = ArModel::new([0.3308, -0.0995, 0.2036, 0.3347], 0.0034);
/// Paper Table 4, accelerometer Y (body y, tool axis). Beta in (m/s^2)^2.
pub const ACCEL_Y: Ar4 = ArModel::new([0.3307, -0.1118, 0.1956, 0.3350], 2.0947e-4);
/// Paper Table 4, accelerometer Z (body z, up). Beta in (m/s^2)^2.
pub const ACCEL_Z: Ar4 = ArModel::new([0.1249, -0.0801, 0.0382, 0.0724], 3.3090e-6);

/// Body x gyro (right): paper Table 5 row "Y" (the azimuth-board gyro).
///
/// Project assumption: Table 5 betas are variances in (deg/s)^2; the paper
/// prints no unit. Converted here to (rad/s)^2.
pub const GYRO_X: Ar4 = ArModel::new(
    [-0.8466, -0.1105, 0.2948, -0.1642],
    7.1662e-7 * DEG2_TO_RAD2,
);
/// Body y (tool-axis) rate derived from accelerometer roll (eq. 1-2): paper
/// Table 5 row "X", the row the paper marks as accelerometer-derived.
pub const GYRO_Y: Ar4 = ArModel::new(
    [-0.0866, -0.5159, -0.0947, -0.1270],
    2.2871e-7 * DEG2_TO_RAD2,
);
/// Body z gyro (up): paper Table 5 row "Z". Beta 6.9822e-7 from the table,
/// not the appendix's 6.982e-8.
pub const GYRO_Z: Ar4 = ArModel::new(
    [-0.2683, -0.0026, 0.0192, -0.3496],
    6.9822e-7 * DEG2_TO_RAD2,
);

/// The three accelerometer models in body order x, y, z.
pub const ACCEL_DEFAULTS: [Ar4; 3] = [ACCEL_X, ACCEL_Y, ACCEL_Z];
/// The three rate models in body order x, y, z.
pub const GYRO_DEFAULTS: [Ar4; 3] = [GYRO_X, GYRO_Y, GYRO_Z];

/// Iteration cap of the doubling Lyapunov solver: 2^60 samples of memory.
const MAX_DOUBLINGS: usize = 60;

impl<const P: usize> ArModel<P> {
    /// A model from `aryule`-convention coefficients and the innovation variance.
    pub const fn new(coefficients: [f64; P], noise_variance: f64) -> Self {
        Self {
            coefficients,
            noise_variance,
        }
    }

    /// Reflection (PARCOR) coefficients by the step-down (reverse Levinson)
    /// recursion, last stage first in index `P-1`. `None` when a stage has
    /// `|k| >= 1` (the model is not stationary) or a value is not finite.
    pub fn reflection_coefficients(&self) -> Option<[f64; P]> {
        let mut a = self.coefficients;
        let mut k = [0.0; P];
        for m in (1..=P).rev() {
            let km = a[m - 1];
            if km.is_nan() || km.abs() >= 1.0 {
                return None;
            }
            k[m - 1] = km;
            let denom = 1.0 - km * km;
            let prev = a;
            for i in 1..m {
                a[i - 1] = (prev[i - 1] - km * prev[m - i - 1]) / denom;
            }
        }
        Some(k)
    }

    /// True when all roots of `1 + a_1 z^-1 + ... + a_p z^-p` lie strictly
    /// inside the unit circle (Schur-Cohn via the step-down recursion).
    pub fn is_stationary(&self) -> bool {
        self.noise_variance.is_finite()
            && self.noise_variance >= 0.0
            && self.reflection_coefficients().is_some()
    }

    /// Companion (transition) matrix for the oldest-first state ordering:
    /// shift rows `x_i <- x_{i+1}`, last row `[-a_p ... -a_1]` (erratum 1).
    pub fn companion(&self) -> SMatrix<f64, P, P> {
        let mut a = SMatrix::<f64, P, P>::zeros();
        for i in 0..P.saturating_sub(1) {
            a[(i, i + 1)] = 1.0;
        }
        if P > 0 {
            for j in 0..P {
                a[(P - 1, j)] = -self.coefficients[P - 1 - j];
            }
        }
        a
    }

    /// Input vector of the white noise: it enters the newest state only.
    pub fn noise_input(&self) -> SVector<f64, P> {
        let mut b = SVector::<f64, P>::zeros();
        if P > 0 {
            b[P - 1] = 1.0;
        }
        b
    }

    /// One sample of the process: `history` holds the last `P` outputs
    /// oldest first and is shifted in place; returns the new output.
    /// `e` is the innovation (already scaled to the model's variance).
    pub fn step(&self, history: &mut [f64; P], e: f64) -> f64 {
        // Accumulate oldest first, like the companion row `[-a_p .. -a_1]`
        // times the state, then add the innovation: the same operations in
        // the same order, so `step` and the companion form agree bit for bit.
        let mut z = 0.0;
        for (j, h) in history.iter().enumerate() {
            z += -self.coefficients[P - 1 - j] * h;
        }
        z += e;
        history.rotate_left(1.min(P));
        if P > 0 {
            history[P - 1] = z;
        }
        z
    }

    /// Stationary covariance of the companion state, solution of the
    /// discrete Lyapunov equation `S = A S A^T + sigma^2 b b^T`, by the
    /// doubling (Smith) iteration. `None` for a non-stationary model.
    pub fn stationary_state_covariance(&self) -> Option<SMatrix<f64, P, P>> {
        if !self.is_stationary() {
            return None;
        }
        let b = self.noise_input();
        let mut s = b * b.transpose() * self.noise_variance;
        let mut a_pow = self.companion();
        for _ in 0..MAX_DOUBLINGS {
            // After j steps s = sum_{k < 2^j} A^k Q A^kT and a_pow = A^(2^j).
            s += a_pow * s * a_pow.transpose();
            a_pow = a_pow * a_pow;
            if a_pow.amax() < 1e-18 {
                return Some(s);
            }
        }
        Some(s)
    }

    /// Autocovariances `gamma(0) .. gamma(P-1)` from the stationary state
    /// covariance (it is Toeplitz: `S_ij = gamma(|i-j|)`).
    fn leading_autocovariances(&self) -> Option<[f64; P]> {
        let s = self.stationary_state_covariance()?;
        let mut g = [0.0; P];
        for (k, gk) in g.iter_mut().enumerate() {
            *gk = s[(P - 1, P - 1 - k)];
        }
        Some(g)
    }

    /// Autocovariance `gamma(lag) = E[z_k z_{k+lag}]` of the stationary
    /// process. Lags beyond `P-1` follow the Yule-Walker recursion
    /// `gamma(k) = -sum a_i gamma(k-i)` (paper eq. 24). `None` if not stationary.
    pub fn autocovariance(&self, lag: usize) -> Option<f64> {
        let mut window = self.leading_autocovariances()?;
        if lag < P {
            return Some(window[lag]);
        }
        // The window holds gamma(k-P .. k-1) oldest first; `step` with zero
        // innovation is exactly the Yule-Walker recursion.
        let mut last = 0.0;
        for _ in P..=lag {
            last = self.step(&mut window, 0.0);
        }
        Some(last)
    }

    /// Variance of the mean of `n` consecutive samples of the stationary
    /// process: `(1/n) [gamma(0) + 2 sum_{k=1}^{n-1} (1 - k/n) gamma(k)]`,
    /// exact from the autocovariance. `None` if not stationary or `n == 0`.
    pub fn variance_of_mean(&self, n: usize) -> Option<f64> {
        if n == 0 {
            return None;
        }
        let mut window = self.leading_autocovariances()?;
        let nf = n as f64;
        let mut sum = window.first().copied().unwrap_or(self.noise_variance);
        for k in 1..n {
            let gk = if k < P {
                window[k]
            } else {
                self.step(&mut window, 0.0)
            };
            sum += 2.0 * (1.0 - k as f64 / nf) * gk;
        }
        Some(sum / nf)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Deterministic pseudo-random innovations (xorshift), no dependency.
    fn noise(seed: &mut u64) -> f64 {
        *seed ^= *seed << 13;
        *seed ^= *seed >> 7;
        *seed ^= *seed << 17;
        (*seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    }

    #[test]
    fn companion_form_reproduces_simulated_sequence_exactly() {
        for model in ACCEL_DEFAULTS.iter().chain(GYRO_DEFAULTS.iter()) {
            let a = model.companion();
            let b = model.noise_input();
            let mut history = [0.0; 4];
            let mut x = SVector::<f64, 4>::zeros();
            let mut seed = 0x9e37_79b9_7f4a_7c15;
            for _ in 0..2000 {
                let e = noise(&mut seed);
                let z = model.step(&mut history, e);
                x = a * x + b * e;
                assert_eq!(x[3], z);
                assert_eq!(x.as_slice(), &history[..]);
            }
        }
    }

    #[test]
    fn companion_last_row_is_reversed_coefficients() {
        let a = ACCEL_X.companion();
        assert_eq!(a[(3, 0)], -0.3347);
        assert_eq!(a[(3, 3)], -0.3308);
        assert_eq!(a[(0, 1)], 1.0);
        assert_eq!(a[(2, 3)], 1.0);
    }

    #[test]
    fn all_six_paper_models_are_stationary_with_the_papers_root_range() {
        for model in ACCEL_DEFAULTS.iter().chain(GYRO_DEFAULTS.iter()) {
            assert!(model.is_stationary());
            let radius = model
                .companion()
                .complex_eigenvalues()
                .iter()
                .map(|c| libm::hypot(c.re, c.im))
                .fold(0.0, f64::max);
            assert!((0.5..0.93).contains(&radius), "radius {radius}");
        }
    }

    #[test]
    fn stationarity_test_rejects_roots_on_or_outside_the_unit_circle() {
        // (1 - 1.1 z^-1): root at 1.1.
        assert!(!ArModel::new([-1.1], 1.0).is_stationary());
        // Random walk: root exactly on the circle.
        assert!(!ArModel::new([-1.0], 1.0).is_stationary());
        // (1 - 0.5 z^-1)(1 - 1.5 z^-1) = 1 - 2 z^-1 + 0.75 z^-2.
        assert!(!ArModel::new([-2.0, 0.75], 1.0).is_stationary());
        // (1 - 0.5 z^-1)(1 + 0.9 z^-1) = 1 + 0.4 z^-1 - 0.45 z^-2.
        assert!(ArModel::new([0.4, -0.45], 1.0).is_stationary());
        assert!(!ArModel::new([f64::NAN, 0.0], 1.0).is_stationary());
    }

    #[test]
    fn ar1_autocovariance_matches_closed_form() {
        // z_k = 0.8 z_{k-1} + e: gamma(k) = s2 0.8^k / (1 - 0.64).
        let m = ArModel::new([-0.8], 2.0);
        for lag in 0..10 {
            let expected = 2.0 * libm::pow(0.8, lag as f64) / (1.0 - 0.64);
            let got = m.autocovariance(lag).unwrap();
            assert!((got - expected).abs() < 1e-12 * expected, "{lag}");
        }
    }

    #[test]
    fn autocovariances_satisfy_yule_walker_and_lyapunov() {
        for model in ACCEL_DEFAULTS.iter().chain(GYRO_DEFAULTS.iter()) {
            let g: [f64; 8] = core::array::from_fn(|k| model.autocovariance(k).unwrap());
            // eq. 25: sigma^2 = gamma(0) + sum a_i gamma(i).
            let s2 = g[0]
                + (1..=4)
                    .map(|i| model.coefficients[i - 1] * g[i])
                    .sum::<f64>();
            assert!((s2 - model.noise_variance).abs() < 1e-10 * model.noise_variance);
            let s = model.stationary_state_covariance().unwrap();
            let a = model.companion();
            let b = model.noise_input();
            let residual = a * s * a.transpose() + b * b.transpose() * model.noise_variance - s;
            assert!(residual.amax() < 1e-12 * g[0]);
        }
    }

    #[test]
    fn variance_of_mean_matches_brute_force_double_sum() {
        let model = GYRO_X;
        for n in [1usize, 2, 5, 17, 100] {
            let mut sum = 0.0;
            for i in 0..n {
                for j in 0..n {
                    sum += model.autocovariance(i.abs_diff(j)).unwrap();
                }
            }
            let expected = sum / (n * n) as f64;
            let got = model.variance_of_mean(n).unwrap();
            assert!((got - expected).abs() < 1e-10 * expected, "n={n}");
        }
        assert_eq!(model.variance_of_mean(0), None);
        assert_eq!(ArModel::new([-1.0], 1.0).variance_of_mean(10), None);
    }

    #[test]
    fn white_noise_variance_of_mean_is_sigma2_over_n() {
        let m = ArModel::<0>::new([], 3.0);
        assert!((m.variance_of_mean(30).unwrap() - 0.1).abs() < 1e-15);
    }
}
