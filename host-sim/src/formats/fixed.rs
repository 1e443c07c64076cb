//! Numbers with a fixed count of decimals, right-aligned, written exactly
//! as `format!("{x:>width$.decimals$}")` writes them but without the
//! standard library's exact-decimal machinery for the common case: a
//! survey listing of a million stations writes fourteen such numbers a
//! station, and `{:.2}` was most of its time.
//!
//! The fast path scales by 10^decimals and rounds to an integer. The
//! scaled product is within half an ulp of the true value, so the integer
//! is the right rounding unless the product lies within a hair of a
//! half; there (a true tie, which the standard library rounds to even, or
//! a near tie) and for values too large, NaN and infinities, the standard
//! library formats the number itself.

use std::fmt::Write as _;

/// How close to a half the scaled value may come before the exact path
/// decides: far beyond the product's rounding error (< 1e-7 below the
/// largest value taken here).
const NEAR_HALF: f64 = 1e-6;
/// The largest scaled magnitude the fast path takes (its ulp ~1.2e-7).
const FAST_LIMIT: f64 = 1e9;

/// Appends `x` with `decimals` decimals (at most 6), right-aligned in
/// `width` characters, to `out`.
pub fn push_fixed(out: &mut String, x: f64, decimals: usize, width: usize) {
    let mut digits = [0u8; 32];
    match fast_digits(x, decimals, &mut digits) {
        Some(text) => {
            for _ in text.len()..width {
                out.push(' ');
            }
            out.push_str(text);
        }
        None => {
            let _ = write!(out, "{x:>width$.decimals$}");
        }
    }
}

/// The number's text by the fast path, or `None` where the standard
/// library must decide.
fn fast_digits(x: f64, decimals: usize, buf: &mut [u8; 32]) -> Option<&str> {
    const SCALE: [f64; 7] = [1.0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6];
    let scale = *SCALE.get(decimals)?;
    let y = x.abs() * scale;
    if !y.is_finite() || y >= FAST_LIMIT {
        return None;
    }
    let r = y.round();
    if ((y - y.floor()) - 0.5).abs() < NEAR_HALF {
        return None;
    }
    let mut n = r as u64;
    // digits from the right: the decimals, the point, the integer part
    let mut at = buf.len();
    let mut put = |b: u8, at: &mut usize| {
        *at -= 1;
        buf[*at] = b;
    };
    for _ in 0..decimals {
        put(b'0' + (n % 10) as u8, &mut at);
        n /= 10;
    }
    if decimals > 0 {
        put(b'.', &mut at);
    }
    loop {
        put(b'0' + (n % 10) as u8, &mut at);
        n /= 10;
        if n == 0 {
            break;
        }
    }
    // the standard library keeps the sign of a negative number that
    // rounds to zero ("-0.00"), and of -0.0
    if x.is_sign_negative() {
        put(b'-', &mut at);
    }
    std::str::from_utf8(&buf[at..]).ok()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn std_text(x: f64, decimals: usize, width: usize) -> String {
        format!("{x:>width$.decimals$}")
    }

    fn ours(x: f64, decimals: usize, width: usize) -> String {
        let mut s = String::new();
        push_fixed(&mut s, x, decimals, width);
        s
    }

    #[test]
    fn the_text_is_the_standard_librarys_on_edges_and_ties() {
        let edges = [
            0.0,
            -0.0,
            0.004,
            -0.004,
            0.005,
            -0.005,
            0.015,
            0.125,
            0.375,
            2.5,
            1.005,
            1.015,
            0.045,
            99.995,
            999.995,
            1e-300,
            -1e-300,
            123456.785,
            1e7,
            9.999999,
            1e9,
            1e12,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::MAX,
            f64::MIN_POSITIVE,
            360.0,
            359.999,
            -359.995,
        ];
        for x in edges {
            for decimals in 0..=4 {
                for width in [0, 6, 9] {
                    assert_eq!(
                        ours(x, decimals, width),
                        std_text(x, decimals, width),
                        "{x}"
                    );
                }
            }
        }
    }

    #[test]
    fn the_text_is_the_standard_librarys_on_a_million_numbers() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        for k in 0..1_000_000 {
            let x: f64 = match k % 4 {
                0 => rng.random_range(-1e4..1e4),
                1 => rng.random_range(-1.0..1.0),
                // numbers on a grid of halves of the last decimal: ties
                2 => f64::from(rng.random_range(-200_000..200_000)) * 0.0005,
                _ => rng.random_range(-1e7..1e7),
            };
            let decimals = k % 4;
            assert_eq!(ours(x, decimals, 9), std_text(x, decimals, 9), "{x:e}");
        }
    }
}
