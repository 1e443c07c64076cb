//! Autocorrelation and AR(p) fitting (MGWD paper eq. 23-26).
//!
//! Sign convention everywhere (paper eq. 23, MATLAB `aryule`):
//! `z_k = -sum_{i=1..p} a_i z_{k-i} + e_k`, `e_k` white with variance
//! `noise_variance`. statsmodels and R report `rho_i = -a_i`.
//! Reflection coefficients follow the same convention: k_m is the last
//! coefficient a_m of the order-m model (MATLAB's `rc`); the partial
//! autocorrelation at lag m is -k_m.

use super::stats::power_of_two_scale;
use anyhow::{bail, Result};
use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

/// Estimator of the AR coefficients.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "kebab-case")]
pub enum ArMethod {
    /// Biased autocorrelation + Levinson-Durbin (eq. 24-25; MATLAB `aryule`).
    YuleWalker,
    /// Burg's maximum-entropy lattice (forward-backward errors).
    Burg,
    /// Covariance method: least squares on the forward prediction error
    /// over the samples that need no padding (eq. 26; MATLAB `arcov`).
    Covariance,
}

/// The method's name in the reports' tables (the file and the command line
/// spell it `yule-walker`, `burg`, `covariance`).
impl std::fmt::Display for ArMethod {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Self::YuleWalker => "YuleWalker",
            Self::Burg => "Burg",
            Self::Covariance => "Covariance",
        })
    }
}

/// One fitted AR(p) model.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ArFit {
    /// The estimator used.
    pub method: ArMethod,
    /// `a_1 .. a_p` in the `aryule` convention.
    pub coefficients: Vec<f64>,
    /// Innovation variance (units of the data squared).
    pub noise_variance: f64,
    /// Reflection coefficients k_1 .. k_p.
    pub reflection: Vec<f64>,
    /// Asymptotic standard errors of the coefficients: the square roots of
    /// the diagonal of sigma^2 Gamma_p^-1 / n (Gamma_p the autocovariance
    /// Toeplitz matrix), the same large-sample law for all three methods.
    pub std_errors: Vec<f64>,
    /// Number of samples used.
    pub samples: usize,
}

/// Information criteria of one candidate order.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct OrderScore {
    /// Model order p.
    pub order: usize,
    /// Innovation variance at that order.
    pub noise_variance: f64,
    /// Reflection coefficient k_p (|k_p| small: the order adds little).
    pub reflection: f64,
    /// Akaike: n ln sigma^2 + 2 p.
    pub aic: f64,
    /// Schwarz/Bayes: n ln sigma^2 + p ln n.
    pub bic: f64,
}

/// Biased autocovariance r_0 .. r_max_lag (divided by n, which keeps the
/// Toeplitz matrix positive definite, eq. 24).
pub fn autocovariance(x: &[f64], max_lag: usize) -> Vec<f64> {
    let n = x.len();
    (0..=max_lag.min(n.saturating_sub(1)))
        .map(|k| x[k..].iter().zip(x).map(|(a, b)| a * b).sum::<f64>() / n as f64)
        .collect()
}

/// Normalised autocorrelation r_k / r_0 of the demeaned series.
pub fn autocorrelation(x: &[f64], max_lag: usize) -> Vec<f64> {
    let r = autocovariance(&demeaned(x), max_lag);
    let r0 = r.first().copied().unwrap_or(0.0);
    r.iter()
        .map(|v| if r0 > 0.0 { v / r0 } else { 0.0 })
        .collect()
}

/// The series minus its mean.
/// The series scaled by [`power_of_two_scale`] (exact), then demeaned if
/// asked: sums of squares of any finite data stay in range. Returns the
/// data and the scale.
fn scaled(x: &[f64], demean: bool) -> (Vec<f64>, f64) {
    let scale = power_of_two_scale(x);
    let data: Vec<f64> = x.iter().map(|v| v * scale).collect();
    if demean {
        (demeaned(&data), scale)
    } else {
        (data, scale)
    }
}

pub fn demeaned(x: &[f64]) -> Vec<f64> {
    let mean = x.iter().sum::<f64>() / x.len().max(1) as f64;
    x.iter().map(|v| v - mean).collect()
}

/// Levinson-Durbin recursion on autocovariances r_0 .. r_p: the Yule-Walker
/// solution of every order up to p. Returns (a, variances per order 1..p,
/// reflection coefficients).
pub fn levinson_durbin(r: &[f64], p: usize) -> Result<(Vec<f64>, Vec<f64>, Vec<f64>)> {
    if r.len() <= p || r[0] <= 0.0 {
        bail!("need positive variance and {p} lags for an AR({p}) fit");
    }
    let mut a: Vec<f64> = Vec::with_capacity(p);
    let mut err = r[0];
    let (mut variances, mut reflection) = (Vec::new(), Vec::new());
    for m in 1..=p {
        let acc = r[m]
            + a.iter()
                .enumerate()
                .map(|(i, ai)| ai * r[m - 1 - i])
                .sum::<f64>();
        let k = -acc / err;
        let previous = a.clone();
        for i in 0..m - 1 {
            a[i] = previous[i] + k * previous[m - 2 - i];
        }
        a.push(k);
        err *= 1.0 - k * k;
        variances.push(err);
        reflection.push(k);
    }
    Ok((a, variances, reflection))
}

/// Step-down (reverse Levinson) recursion: reflection coefficients of a
/// given model; the same law as `mwd_core::ar::ArModel::reflection_coefficients`
/// for a run-time order.
pub fn reflection_from_coefficients(a: &[f64]) -> Vec<f64> {
    let mut cur = a.to_vec();
    let mut k = vec![0.0; a.len()];
    for m in (1..=a.len()).rev() {
        let km = cur[m - 1];
        k[m - 1] = km;
        let denom = 1.0 - km * km;
        if denom.abs() < f64::EPSILON {
            break;
        }
        cur = (0..m - 1)
            .map(|i| (cur[i] - km * cur[m - 2 - i]) / denom)
            .collect();
    }
    k
}

fn check_input(x: &[f64], p: usize) -> Result<()> {
    if p == 0 {
        bail!("the AR order must be at least 1");
    }
    if x.len() < 2 * p + 2 {
        bail!("{} samples are too few for an AR({p}) fit", x.len());
    }
    if x.iter().any(|v| !v.is_finite()) {
        bail!("the series contains a non-finite value");
    }
    Ok(())
}

/// Burg's method of every order up to p: (a, variances per order, reflection).
/// The variance of order m is the mean of the squared forward and backward
/// prediction errors over their N - m valid samples (statsmodels' `burg`).
pub fn burg_orders(x: &[f64], p: usize) -> Result<(Vec<f64>, Vec<f64>, Vec<f64>)> {
    check_input(x, p)?;
    let n = x.len();
    // f[t] is the forward error at time t, b[t] the backward error at time t;
    // at order m only t >= m is valid for both.
    let (mut f, mut b) = (x.to_vec(), x.to_vec());
    let mut a: Vec<f64> = Vec::with_capacity(p);
    let (mut variances, mut reflection) = (Vec::new(), Vec::new());
    for m in 1..=p {
        let (mut num, mut den) = (0.0, 0.0);
        for t in m..n {
            num += f[t] * b[t - 1];
            den += f[t] * f[t] + b[t - 1] * b[t - 1];
        }
        if den <= 0.0 {
            bail!("Burg recursion: zero prediction-error power at order {m}");
        }
        let k = -2.0 * num / den;
        for t in (m..n).rev() {
            let (ft, bt) = (f[t], b[t - 1]);
            f[t] = ft + k * bt;
            b[t] = bt + k * ft;
        }
        let previous = a.clone();
        for i in 0..m - 1 {
            a[i] = previous[i] + k * previous[m - 2 - i];
        }
        a.push(k);
        let power: f64 = (m..n).map(|t| f[t] * f[t] + b[t] * b[t]).sum();
        variances.push(power / (2.0 * (n - m) as f64));
        reflection.push(k);
    }
    Ok((a, variances, reflection))
}

/// Covariance method (eq. 26): minimise sum_{t=p}^{n-1} (x_t + sum a_i x_{t-i})^2.
/// Returns (a, innovation variance = residual power / (n - p)).
pub fn covariance_method(x: &[f64], p: usize) -> Result<(Vec<f64>, f64)> {
    check_input(x, p)?;
    let rows = x.len() - p;
    let design = DMatrix::from_fn(rows, p, |r, i| x[p + r - 1 - i]);
    let target = DVector::from_fn(rows, |r, _| -x[p + r]);
    let svd = design.clone().svd(true, true);
    let a = svd
        .solve(&target, 1e-12)
        .map_err(|e| anyhow::anyhow!("covariance method: {e}"))?;
    let residual = &design * &a - &target;
    Ok((
        a.iter().copied().collect(),
        residual.norm_squared() / rows as f64,
    ))
}

fn standard_errors(x: &[f64], p: usize, variance: f64) -> Vec<f64> {
    let r = autocovariance(x, p);
    let gamma = DMatrix::from_fn(p, p, |i, j| r[i.abs_diff(j)]);
    match gamma.try_inverse() {
        Some(inv) => (0..p)
            .map(|i| (variance * inv[(i, i)] / x.len() as f64).sqrt())
            .collect(),
        None => vec![f64::NAN; p],
    }
}

/// Fits an AR(p) model. `demean` removes the sample mean first (the
/// paper's noise records are biased sensor outputs; the R reference fit on
/// 1..11 is done without).
pub fn fit_ar(x: &[f64], p: usize, method: ArMethod, demean: bool) -> Result<ArFit> {
    check_input(x, p)?;
    let (data, scale) = scaled(x, demean);
    let (coefficients, scaled_variance, reflection) = match method {
        ArMethod::YuleWalker => {
            let (a, v, k) = levinson_durbin(&autocovariance(&data, p), p)?;
            (a, v[p - 1], k)
        }
        ArMethod::Burg => {
            let (a, v, k) = burg_orders(&data, p)?;
            (a, v[p - 1], k)
        }
        ArMethod::Covariance => {
            let (a, v) = covariance_method(&data, p)?;
            let k = reflection_from_coefficients(&a);
            (a, v, k)
        }
    };
    // The coefficients and their standard errors do not depend on the
    // data's scale; the variance goes with its square.
    let noise_variance = scaled_variance / (scale * scale);
    let std_errors = standard_errors(&data, p, scaled_variance);
    let finite = coefficients
        .iter()
        .chain(&std_errors)
        .all(|v| v.is_finite());
    if !(finite && noise_variance.is_finite()) {
        bail!(
            "the AR({p}) fit is not a finite number (innovation variance {noise_variance:e}): \
             the data's variance is beyond what a number holds, or the data are degenerate"
        );
    }
    Ok(ArFit {
        method,
        std_errors,
        coefficients,
        noise_variance,
        reflection,
        samples: x.len(),
    })
}

/// AIC and BIC for orders 1..=max_order (order-selection help).
pub fn order_scores(
    x: &[f64],
    max_order: usize,
    method: ArMethod,
    demean: bool,
) -> Result<Vec<OrderScore>> {
    check_input(x, max_order)?;
    let (data, scale) = scaled(x, demean);
    let (variances, reflection) = match method {
        ArMethod::YuleWalker => {
            let (_, v, k) = levinson_durbin(&autocovariance(&data, max_order), max_order)?;
            (v, k)
        }
        ArMethod::Burg => {
            let (_, v, k) = burg_orders(&data, max_order)?;
            (v, k)
        }
        ArMethod::Covariance => {
            let mut v = Vec::new();
            let mut k = Vec::new();
            for p in 1..=max_order {
                let (a, var) = covariance_method(&data, p)?;
                v.push(var);
                k.push(a[p - 1]);
            }
            (v, k)
        }
    };
    let n = x.len() as f64;
    Ok(variances
        .iter()
        .zip(&reflection)
        .enumerate()
        .map(|(i, (&v, &k))| {
            let p = (i + 1) as f64;
            // ln of the unscaled variance, finite even when it is not.
            let ln_variance = v.ln() - 2.0 * scale.ln();
            OrderScore {
                order: i + 1,
                noise_variance: v / (scale * scale),
                reflection: k,
                aic: n * ln_variance + 2.0 * p,
                bic: n * ln_variance + p * n.ln(),
            }
        })
        .collect())
}

/// Simulates `n` samples of an AR model (aryule convention) from seeded
/// Gaussian innovations, after a burn-in that forgets the zero start.
pub fn simulate_ar(a: &[f64], noise_variance: f64, n: usize, seed: u64) -> Vec<f64> {
    use rand::SeedableRng;
    use rand_distr::{Distribution, StandardNormal};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let sd = noise_variance.max(0.0).sqrt();
    let burn_in = 1000;
    let mut z = vec![0.0; n + burn_in];
    for t in 0..z.len() {
        let past: f64 = a
            .iter()
            .enumerate()
            .filter(|(i, _)| t > *i)
            .map(|(i, ai)| ai * z[t - 1 - i])
            .sum();
        let w: f64 = StandardNormal.sample(&mut rng);
        z[t] = -past + sd * w;
    }
    z.split_off(burn_in)
}
