//! The log axes of the study's figures: a range holding the values, and
//! tick labels.

/// A tick label: plain digits from 0.01 to 9999, else a power of ten.
pub(super) fn tick(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    if (0.01..10_000.0).contains(&v.abs()) {
        let s = format!("{v:.3}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        format!("{v:.0e}")
    }
}

/// (low, high) of a log axis holding the positive finite values, with a
/// factor `pad` of room; `None` if there are none.
pub(super) fn log_range(values: impl Iterator<Item = f64>, pad: f64) -> Option<(f64, f64)> {
    let (lo, hi) = values
        .filter(|v| v.is_finite() && *v > 0.0)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    (lo <= hi).then(|| {
        if lo == hi {
            (lo / 10.0, hi * 10.0)
        } else {
            (lo / pad, hi * pad)
        }
    })
}
