//! Noise coefficients from an Allan deviation curve (IEEE Std 952-1997,
//! annex C): the Allan variance of independent power-law terms adds up,
//!
//!   sigma^2(tau) = 3 Q^2 / tau^2 + N^2 / tau + (0.664 B)^2 + K^2 tau / 3,
//!
//! quantization Q (slope -1 in the deviation), random walk N (slope -1/2,
//! read at tau = 1 s), bias instability B (the flat floor, sigma = B
//! sqrt(2 ln 2 / pi) = 0.664 B) and rate random walk K (slope +1/2, read at
//! tau = 3 s). The four squares are fitted jointly by non-negative weighted
//! least squares, each point weighted by its chi-square variance
//! var(sigma^2) = 2 sigma^4 / edf, so the long-tau points with few degrees
//! of freedom count little. A joint fit avoids choosing slope regions by eye.

use super::allan::AllanPoint;
use nalgebra::{DMatrix, DVector};
use serde::Serialize;

/// sigma_floor / B for flicker noise: sqrt(2 ln 2 / pi) = 0.6643.
pub fn bias_instability_factor() -> f64 {
    (2.0 * std::f64::consts::LN_2 / std::f64::consts::PI).sqrt()
}

/// Fitted noise coefficients in the data's unit (u): Q in u*s, N in
/// u*sqrt(s), B in u, K in u/sqrt(s). Zero where the term was not needed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct NoiseCoefficients {
    /// Quantization noise Q (deviation slope -1).
    pub quantization: f64,
    /// Angle / velocity random walk N (slope -1/2): sigma(1 s) of that term.
    pub random_walk: f64,
    /// Bias instability B; the floor itself is 0.664 B.
    pub bias_instability: f64,
    /// Rate random walk K (slope +1/2): sigma(3 s) of that term.
    pub rate_random_walk: f64,
}

impl NoiseCoefficients {
    /// The four terms' deviations at `tau`, in the order Q, N, B, K.
    pub fn terms_at(&self, tau: f64) -> [f64; 4] {
        [
            self.quantization * 3f64.sqrt() / tau,
            self.random_walk / tau.sqrt(),
            self.bias_instability * bias_instability_factor(),
            self.rate_random_walk * (tau / 3.0).sqrt(),
        ]
    }

    /// The model's total deviation at `tau`.
    pub fn deviation_at(&self, tau: f64) -> f64 {
        self.terms_at(tau).iter().map(|t| t * t).sum::<f64>().sqrt()
    }
}

fn basis(tau: f64) -> [f64; 4] {
    [3.0 / (tau * tau), 1.0 / tau, 1.0, tau / 3.0]
}

/// Joint non-negative weighted least-squares fit of the four terms. With
/// only four unknowns every subset of active terms is solved and the best
/// feasible one kept: exact NNLS without an iterative solver.
pub fn fit_noise(points: &[AllanPoint]) -> NoiseCoefficients {
    let usable: Vec<&AllanPoint> = points
        .iter()
        .filter(|p| p.oadev > 0.0 && p.edf.is_finite())
        .collect();
    let mut best: Option<(f64, [f64; 4])> = None;
    for mask in 1u32..16 {
        let active: Vec<usize> = (0..4).filter(|j| mask & (1 << j) != 0).collect();
        if usable.len() < active.len() {
            continue;
        }
        // Rows scaled by 1 / sd(sigma^2): residuals are in standard errors.
        let mut a = DMatrix::zeros(usable.len(), active.len());
        let mut b = DVector::zeros(usable.len());
        for (i, p) in usable.iter().enumerate() {
            let var = p.oadev * p.oadev;
            let scale = (p.edf / 2.0).sqrt() / var;
            let f = basis(p.tau);
            for (k, &j) in active.iter().enumerate() {
                a[(i, k)] = f[j] * scale;
            }
            b[i] = var * scale;
        }
        // Column equilibration: the basis spans many decades of tau.
        let norms: Vec<f64> = (0..active.len()).map(|k| a.column(k).norm()).collect();
        for (k, n) in norms.iter().enumerate() {
            if *n > 0.0 {
                a.column_mut(k).scale_mut(1.0 / n);
            }
        }
        let Ok(sol) = a.clone().svd(true, true).solve(&b, 1e-12) else {
            continue;
        };
        let coef: Vec<f64> = sol.iter().zip(&norms).map(|(s, n)| s / n).collect();
        if coef.iter().any(|c| !(c.is_finite() && *c >= 0.0)) {
            continue;
        }
        let mut full = [0.0; 4];
        for (k, &j) in active.iter().enumerate() {
            full[j] = coef[k];
        }
        let resid = (&a * &sol - &b).norm_squared();
        if best.is_none_or(|(r, _)| resid < r) {
            best = Some((resid, full));
        }
    }
    let c = best.map_or([0.0; 4], |(_, c)| c);
    NoiseCoefficients {
        quantization: c[0].sqrt(),
        random_walk: c[1].sqrt(),
        bias_instability: c[2].sqrt() / bias_instability_factor(),
        rate_random_walk: c[3].sqrt(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn synthetic(truth: &NoiseCoefficients) -> Vec<AllanPoint> {
        (0..16)
            .map(|k| {
                let tau = 0.05 * 2f64.powi(k);
                let dev = truth.deviation_at(tau);
                AllanPoint {
                    tau,
                    m: 1 << k,
                    oadev: dev,
                    adev: None,
                    terms: 1,
                    alpha: 0,
                    edf: 1000.0 / (k + 1) as f64,
                    ci_low: dev,
                    ci_high: dev,
                }
            })
            .collect()
    }

    #[test]
    fn exact_curve_gives_exact_coefficients() {
        let truth = NoiseCoefficients {
            quantization: 0.0,
            random_walk: 2.5e-4,
            bias_instability: 1.0e-5,
            rate_random_walk: 3.0e-7,
        };
        let fit = fit_noise(&synthetic(&truth));
        assert!(
            (fit.random_walk / truth.random_walk - 1.0).abs() < 1e-6,
            "{fit:?}"
        );
        assert!((fit.bias_instability / truth.bias_instability - 1.0).abs() < 1e-6);
        assert!((fit.rate_random_walk / truth.rate_random_walk - 1.0).abs() < 1e-6);
        assert!(fit.quantization < 1e-9);
        assert!((bias_instability_factor() - 0.6643).abs() < 1e-4);
    }
}
