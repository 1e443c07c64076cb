//! Allan deviation of rate (frequency-type) data, NIST SP 1065 (2008):
//! the non-overlapping (section 5.2.2, eq. 6) and overlapping (5.2.4, eq. 9)
//! estimators, noise identification by the lag-1 autocorrelation (5.5.6)
//! and the simple equivalent-degrees-of-freedom formulas (5.3.x, Table 5)
//! for chi-square confidence intervals (eq. 45).
//!
//! Input samples are rates (rad/s, m/s^2, ... or any unit); the deviations
//! come out in the same unit. Everything is O(n) per averaging time.

use super::stats::{chi2_quantile, ONE_SIGMA};
use serde::Serialize;

/// Which averaging factors m (tau = m tau0) to evaluate.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TauSet {
    /// m = 1, 2, 4, ... (the usual log-log plot; cheap).
    Octave,
    /// Every m from 1 to n/2: O(n^2), for short records only.
    All,
}

/// One averaging time of an Allan analysis.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AllanPoint {
    /// Averaging time (s).
    pub tau: f64,
    /// Averaging factor, tau = m / rate.
    pub m: usize,
    /// Overlapping Allan deviation.
    pub oadev: f64,
    /// Non-overlapping Allan deviation (`None` with fewer than 2 averages).
    pub adev: Option<f64>,
    /// Number of second differences in the overlapping sum.
    pub terms: usize,
    /// Identified power-law noise exponent alpha of S_y(f) ~ f^alpha.
    pub alpha: i32,
    /// Equivalent degrees of freedom of the overlapping estimate.
    pub edf: f64,
    /// 1-sigma (68.3 %) confidence interval of `oadev`.
    pub ci_low: f64,
    /// Upper end of the confidence interval.
    pub ci_high: f64,
}

/// The averaging factors of a tau set for `n` rate samples.
pub fn averaging_factors(n: usize, set: TauSet) -> Vec<usize> {
    let max_m = n / 2;
    match set {
        TauSet::All => (1..=max_m).collect(),
        TauSet::Octave => std::iter::successors(Some(1usize), |m| m.checked_mul(2))
            .take_while(|&m| m <= max_m)
            .collect(),
    }
}

/// Phase (integrated rate) with the mean rate removed: x_0 = 0,
/// x_{i+1} = x_i + (y_i - mean) tau0. The Allan variance ignores a constant
/// rate, and removing it keeps the running sum small so that second
/// differences of a 600,000-point record lose no precision.
pub fn phase_from_rate(y: &[f64], tau0: f64) -> Vec<f64> {
    let mean = y.iter().sum::<f64>() / y.len().max(1) as f64;
    let mut x = Vec::with_capacity(y.len() + 1);
    let mut acc = 0.0;
    x.push(acc);
    for v in y {
        acc += (v - mean) * tau0;
        x.push(acc);
    }
    x
}

/// Overlapping Allan variance from phase data (SP 1065 eq. 9):
/// sum of (x_{i+2m} - 2 x_{i+m} + x_i)^2 over all i, / (2 (N - 2m) (m tau0)^2).
/// Returns the variance and the number of terms, or `None` if N <= 2m.
pub fn overlapping_avar(x: &[f64], m: usize, tau0: f64) -> Option<(f64, usize)> {
    let terms = x.len().checked_sub(2 * m).filter(|&t| t > 0 && m > 0)?;
    let sum: f64 = x
        .windows(2 * m + 1)
        .map(|w| {
            let d = w[2 * m] - 2.0 * w[m] + w[0];
            d * d
        })
        .sum();
    let tau = m as f64 * tau0;
    Some((sum / (2.0 * terms as f64 * tau * tau), terms))
}

/// Non-overlapping Allan variance from rate data (SP 1065 eq. 6): the
/// variance of successive m-sample averages, M = floor(n / m) of them.
pub fn nonoverlapping_avar(y: &[f64], m: usize) -> Option<f64> {
    if m == 0 || y.len() / m < 2 {
        return None;
    }
    let averages: Vec<f64> = y
        .chunks_exact(m)
        .map(|c| c.iter().sum::<f64>() / m as f64)
        .collect();
    let sum: f64 = averages.windows(2).map(|w| (w[1] - w[0]).powi(2)).sum();
    Some(sum / (2.0 * (averages.len() - 1) as f64))
}

/// Noise type at averaging factor m by the lag-1 autocorrelation of the
/// m-sample averages (SP 1065 section 5.5.6, after Riley & Greenhall):
/// difference until rho = r1 / (1 + r1) < 0.25, alpha = -2 (round(rho) + d).
/// `None` when fewer than 30 averages are left (the method's minimum).
pub fn identify_noise(y: &[f64], m: usize) -> Option<i32> {
    let mut z: Vec<f64> = y
        .chunks_exact(m.max(1))
        .map(|c| c.iter().sum::<f64>() / c.len() as f64)
        .collect();
    if z.len() < 30 {
        return None;
    }
    detrend_linear(&mut z);
    let mut d = 0;
    loop {
        let r1 = lag1_autocorrelation(&z);
        let rho = r1 / (1.0 + r1);
        if rho < 0.25 || d >= 2 {
            let alpha = -(2.0 * rho).round() as i32 - 2 * d;
            return Some(alpha.clamp(-2, 2));
        }
        z = z.windows(2).map(|w| w[1] - w[0]).collect();
        d += 1;
    }
}

fn detrend_linear(z: &mut [f64]) {
    let n = z.len() as f64;
    let t_mean = (n - 1.0) / 2.0;
    let z_mean = z.iter().sum::<f64>() / n;
    let (mut stt, mut stz) = (0.0, 0.0);
    for (i, v) in z.iter().enumerate() {
        let t = i as f64 - t_mean;
        stt += t * t;
        stz += t * (v - z_mean);
    }
    let slope = if stt > 0.0 { stz / stt } else { 0.0 };
    for (i, v) in z.iter_mut().enumerate() {
        *v -= z_mean + slope * (i as f64 - t_mean);
    }
}

fn lag1_autocorrelation(z: &[f64]) -> f64 {
    let mean = z.iter().sum::<f64>() / z.len() as f64;
    let den: f64 = z.iter().map(|v| (v - mean).powi(2)).sum();
    let num: f64 = z.windows(2).map(|w| (w[0] - mean) * (w[1] - mean)).sum();
    if den > 0.0 {
        num / den
    } else {
        0.0
    }
}

/// Equivalent degrees of freedom of the overlapping Allan variance by the
/// simple approximations of SP 1065 Table 5 (Howe, Allan & Barnes), for
/// `n_phase` phase points, averaging factor m and noise exponent alpha.
pub fn edf_overlapping(n_phase: usize, m: usize, alpha: i32) -> f64 {
    let n = n_phase as f64;
    let mf = m as f64;
    let edf = match alpha {
        2 => (n + 1.0) * (n - 2.0 * mf) / (2.0 * (n - mf)),
        1 => {
            let a = ((n - 1.0) / (2.0 * mf)).ln();
            let b = ((2.0 * mf + 1.0) * (n - 1.0) / 4.0).ln();
            (a * b).max(0.0).sqrt().exp()
        }
        0 => {
            (3.0 * (n - 1.0) / (2.0 * mf) - 2.0 * (n - 2.0) / n) * (4.0 * mf * mf)
                / (4.0 * mf * mf + 5.0)
        }
        -1 if m == 1 => 2.0 * (n - 2.0) / (2.3 * n - 4.9),
        -1 => 5.0 * n * n / (4.0 * mf * (n + 3.0 * mf)),
        _ => {
            (n - 2.0) / (mf * (n - 3.0).powi(2))
                * ((n - 1.0).powi(2) - 3.0 * mf * (n - 1.0) + 4.0 * mf * mf)
        }
    };
    // Below one degree of freedom the chi-square interval is meaningless.
    if edf.is_finite() {
        edf.max(1.0)
    } else {
        1.0
    }
}

/// 1-sigma confidence interval of a deviation with `edf` degrees of
/// freedom (SP 1065 eq. 45): sigma^2 edf / chi2(p) at p = (1 +- 0.683) / 2.
pub fn confidence_interval(dev: f64, edf: f64) -> (f64, f64) {
    let tail = (1.0 - ONE_SIGMA) / 2.0;
    let lo = dev * (edf / chi2_quantile(1.0 - tail, edf)).sqrt();
    let hi = dev * (edf / chi2_quantile(tail, edf)).sqrt();
    (lo, hi)
}

/// Full Allan analysis of one rate series sampled at `rate_hz`.
/// `progress` is called once per averaging time with the number of
/// samples processed, for a progress bar on long runs.
pub fn allan_deviation(
    y: &[f64],
    rate_hz: f64,
    set: TauSet,
    mut progress: impl FnMut(u64),
) -> Vec<AllanPoint> {
    let tau0 = 1.0 / rate_hz;
    let x = phase_from_rate(y, tau0);
    let mut alpha = 0;
    let mut points = Vec::new();
    for m in averaging_factors(y.len(), set) {
        let Some((avar, terms)) = overlapping_avar(&x, m, tau0) else {
            continue;
        };
        // Keep the last identification where too few averages remain.
        if let Some(a) = identify_noise(y, m) {
            alpha = a;
        }
        let oadev = avar.sqrt();
        let edf = edf_overlapping(x.len(), m, alpha);
        let (ci_low, ci_high) = confidence_interval(oadev, edf);
        points.push(AllanPoint {
            tau: m as f64 * tau0,
            m,
            oadev,
            adev: nonoverlapping_avar(y, m).map(f64::sqrt),
            terms,
            alpha,
            edf,
            ci_low,
            ci_high,
        });
        progress(y.len() as u64);
    }
    points
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn octave_factors_stop_at_half_the_record() {
        assert_eq!(averaging_factors(9, TauSet::Octave), vec![1, 2, 4]);
        assert_eq!(averaging_factors(9, TauSet::All), vec![1, 2, 3, 4]);
        assert!(averaging_factors(1, TauSet::Octave).is_empty());
    }

    #[test]
    fn overlapping_equals_nonoverlapping_at_m1() {
        let y = [1.0, 3.0, 2.0, 5.0, 4.0, 4.5];
        let x = phase_from_rate(&y, 0.5);
        let (o, _) = overlapping_avar(&x, 1, 0.5).unwrap();
        let a = nonoverlapping_avar(&y, 1).unwrap();
        assert!((o - a).abs() < 1e-12 * a);
    }

    #[test]
    fn white_noise_identified_and_edf_sane() {
        use rand::SeedableRng;
        use rand_distr::{Distribution, StandardNormal};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let y: Vec<f64> = (0..4000).map(|_| StandardNormal.sample(&mut rng)).collect();
        assert_eq!(identify_noise(&y, 1), Some(0));
        let mut walk = 0.0;
        let rw: Vec<f64> = y
            .iter()
            .map(|v| {
                walk += v;
                walk
            })
            .collect();
        assert_eq!(identify_noise(&rw, 4), Some(-2));
        // White FM at m = 1: about 3/2 (N - 1) / 1 * 4/9 of the data.
        let edf = edf_overlapping(4001, 1, 0);
        assert!(edf > 2000.0 && edf < 4000.0, "{edf}");
        let (lo, hi) = confidence_interval(1.0, edf);
        assert!(lo < 1.0 && hi > 1.0 && hi - lo < 0.05);
    }
}
