//! The few statistics the studies print: RMS, nearest-rank percentiles.
//! `None` where there is nothing to summarise, never 0.

/// Root mean square; `None` for no values.
pub fn rms(values: &[f64]) -> Option<f64> {
    (!values.is_empty())
        .then(|| (values.iter().map(|v| v * v).sum::<f64>() / values.len() as f64).sqrt())
}

/// Nearest-rank percentile `p` (0-1): the smallest value with at least
/// the fraction `p` of the values at or below it; `None` for no values.
pub fn percentile(values: &[f64], p: f64) -> Option<f64> {
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    let rank = ((p * v.len() as f64).ceil() as usize).clamp(1, v.len().max(1));
    v.get(rank - 1).copied()
}

/// The nearest-rank median (the lower middle value of an even count).
pub fn median(values: &[f64]) -> Option<f64> {
    percentile(values, 0.5)
}

/// The RMS of the errors and the median of the sigmas of (error, sigma)
/// pairs.
pub fn rms_and_median_sigma(pairs: &[(f64, f64)]) -> (Option<f64>, Option<f64>) {
    let errors: Vec<f64> = pairs.iter().map(|(e, _)| *e).collect();
    let sigmas: Vec<f64> = pairs.iter().map(|(_, s)| *s).collect();
    (rms(&errors), median(&sigmas))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_percentile_is_the_nearest_rank() {
        let v: Vec<f64> = (1..=20).rev().map(f64::from).collect();
        assert_eq!(percentile(&v, 0.95), Some(19.0));
        assert_eq!(percentile(&v, 1.0), Some(20.0));
        assert_eq!(percentile(&v, 0.0), Some(1.0));
        assert_eq!(median(&v), Some(10.0));
        assert_eq!(median(&[3.0]), Some(3.0));
    }

    #[test]
    fn nothing_to_summarise_is_none_not_zero() {
        assert_eq!(rms(&[]), None);
        assert_eq!(percentile(&[], 0.95), None);
        assert_eq!(median(&[]), None);
        assert_eq!(rms(&[3.0, -4.0]), Some((12.5f64).sqrt()));
    }
}
