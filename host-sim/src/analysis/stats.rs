//! Small statistical helpers: the chi-square distribution for Allan
//! deviation confidence intervals (NIST SP 1065 section 5.3, eq. 45), and
//! the scale that keeps sums of squares of any finite data in range.

/// A power of two that brings the largest magnitude of `x` into [0.5, 1):
/// multiplying by it is exact in binary floating point, so an analysis of
/// the scaled data, rescaled, gives the same bits as the unscaled one
/// whenever that one does not overflow, and a finite answer whenever the
/// answer itself is representable (data of 1e200 have squares of 1e400).
/// 1 for data that are all zero.
pub fn power_of_two_scale(x: &[f64]) -> f64 {
    let largest = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    if !(largest.is_finite() && largest > 0.0) {
        return 1.0;
    }
    let (_, exponent) = libm::frexp(largest);
    // Subnormal data would need 2^1074, beyond f64: stop at 2^1023.
    libm::ldexp(1.0, -exponent.clamp(-1023, 1023))
}

/// Regularized lower incomplete gamma function P(a, x), by its power series
/// for x < a + 1 and by the continued fraction of Q = 1 - P otherwise (the
/// usual split: each converges fast on its side).
pub fn gamma_p(a: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    let log_prefactor = a * x.ln() - x - libm::lgamma(a);
    if x < a + 1.0 {
        let mut term = 1.0 / a;
        let mut sum = term;
        let mut n = a;
        for _ in 0..1000 {
            n += 1.0;
            term *= x / n;
            sum += term;
            if term.abs() < sum.abs() * 1e-16 {
                break;
            }
        }
        (sum.ln() + log_prefactor).exp()
    } else {
        // Modified Lentz evaluation of the continued fraction for Q(a, x).
        let tiny = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / tiny;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..1000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < tiny {
                d = tiny;
            }
            c = b + an / c;
            if c.abs() < tiny {
                c = tiny;
            }
            d = 1.0 / d;
            let delta = d * c;
            h *= delta;
            if (delta - 1.0).abs() < 1e-16 {
                break;
            }
        }
        1.0 - (log_prefactor.exp() * h)
    }
}

/// Chi-square cumulative distribution with `dof` degrees of freedom.
pub fn chi2_cdf(x: f64, dof: f64) -> f64 {
    gamma_p(0.5 * dof, 0.5 * x)
}

/// Chi-square quantile: the x with `chi2_cdf(x, dof) = p`, by bisection
/// (monotone, robust for the fractional EDFs the Allan estimators give).
pub fn chi2_quantile(p: f64, dof: f64) -> f64 {
    let (mut lo, mut hi) = (0.0, dof.max(1.0));
    while chi2_cdf(hi, dof) < p {
        hi *= 2.0;
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if chi2_cdf(mid, dof) < p {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo <= 1e-14 * hi {
            break;
        }
    }
    0.5 * (lo + hi)
}

/// Probability mass of a normal distribution within one sigma: the usual
/// "1-sigma" confidence level of Allan deviation error bars.
pub const ONE_SIGMA: f64 = 0.682_689_492_137_085_9;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_scale_is_a_power_of_two_bringing_the_data_below_one() {
        assert_eq!(power_of_two_scale(&[3.0, -5.0]), 0.125);
        assert_eq!(power_of_two_scale(&[0.0]), 1.0);
        let s = power_of_two_scale(&[1e200, 1.0]);
        assert!((0.5..1.0).contains(&(1e200 * s)));
        let t = power_of_two_scale(&[1e-300]);
        assert!((0.5..1.0).contains(&(1e-300 * t)));
    }

    #[test]
    fn chi2_against_textbook_quantiles() {
        // Standard chi-square table values (e.g. any statistics handbook).
        assert!((chi2_quantile(0.95, 1.0) - 3.841_458_8).abs() < 1e-6);
        assert!((chi2_quantile(0.05, 10.0) - 3.940_299_1).abs() < 1e-6);
        assert!((chi2_quantile(0.975, 30.0) - 46.979_242).abs() < 1e-5);
        // For 2 dof the CDF is 1 - exp(-x/2): exact.
        assert!((chi2_cdf(3.0, 2.0) - (1.0 - (-1.5f64).exp())).abs() < 1e-14);
    }
}
