//! What a modelled channel measures ([`ArQuantity`]), and the check of
//! one AR model against the physical [`limits`](super::limits): its order,
//! finite coefficients, the roots of its AR polynomial inside the unit
//! circle with a margin (stationary), and the innovation variance in the
//! range of what it measures.

use super::limits;
use crate::analysis::units::Quantity;
use anyhow::{bail, Result};
use serde::{Deserialize, Serialize};

/// What a modelled channel measures.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ArQuantity {
    /// Accelerometer: variance in (m/s^2)^2.
    SpecificForce,
    /// Gyro (or a derived rate): variance in (rad/s)^2.
    AngularRate,
    /// Unknown unit: variance in the input unit squared.
    Other,
}

impl std::fmt::Display for ArQuantity {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Self::SpecificForce => "a specific force",
            Self::AngularRate => "an angular rate",
            Self::Other => "a quantity of unknown unit",
        })
    }
}

impl From<Quantity> for ArQuantity {
    fn from(quantity: Quantity) -> Self {
        match quantity {
            Quantity::AngularRate => Self::AngularRate,
            Quantity::SpecificForce => Self::SpecificForce,
            Quantity::Other => Self::Other,
        }
    }
}

impl ArQuantity {
    /// The variance unit written beside the number.
    pub fn variance_unit(self) -> &'static str {
        match self {
            Self::SpecificForce => "(m/s^2)^2",
            Self::AngularRate => "(rad/s)^2",
            Self::Other => "(u)^2",
        }
    }
}

/// Checks one AR model: order, finite coefficients, roots at most
/// [`limits::MAX_ROOT_MODULUS`], the innovation variance (SI) in the
/// range of `quantity`.
pub fn check_ar(coefficients: &[f64], noise_variance: f64, quantity: ArQuantity) -> Result<()> {
    if !limits::ORDER.contains(&coefficients.len()) {
        bail!(
            "order {} outside {} to {}",
            coefficients.len(),
            limits::ORDER.start(),
            limits::ORDER.end()
        );
    }
    for (i, &a) in coefficients.iter().enumerate() {
        if !a.is_finite() {
            bail!("`coefficients[{i}]` is {a}, not a finite number");
        }
    }
    let modulus = largest_root_modulus(coefficients);
    if modulus >= 1.0 {
        bail!(
            "the model is not stationary: a root of its AR polynomial has modulus >= 1 \
             (the limit is {})",
            limits::MAX_ROOT_MODULUS
        );
    }
    if modulus > limits::MAX_ROOT_MODULUS {
        bail!(
            "a root of the AR polynomial has modulus {modulus:.6}, beyond {}: too near the \
             unit circle (the model must be stationary with a margin)",
            limits::MAX_ROOT_MODULUS
        );
    }
    let range = match quantity {
        ArQuantity::SpecificForce => limits::specific_force_variance(),
        ArQuantity::AngularRate => limits::angular_rate_variance(),
        ArQuantity::Other => limits::OTHER_VARIANCE,
    };
    range.check("noise_variance", noise_variance)?;
    Ok(())
}

/// The largest modulus of the roots of z^p + a_1 z^(p-1) + ... + a_p, to
/// 1e-6, found by bisection on r: every root is inside the circle of radius
/// r exactly when the model with coefficients a_i / r^i is stationary
/// (all its reflection coefficients below 1 in magnitude, the step-down
/// test). At least 1 when the model is not stationary.
pub fn largest_root_modulus(a: &[f64]) -> f64 {
    let inside = |r: f64| {
        let scaled: Vec<f64> = a
            .iter()
            .enumerate()
            .map(|(i, v)| v / r.powi(i as i32 + 1))
            .collect();
        let k = crate::analysis::arfit::reflection_from_coefficients(&scaled);
        k.iter().all(|k| k.is_finite() && k.abs() < 1.0)
    };
    if !inside(1.0) {
        return 1.0;
    }
    let (mut low, mut high) = (0.0, 1.0);
    while high - low > 1e-7 {
        let mid = 0.5 * (low + high);
        if mid > 0.0 && inside(mid) {
            high = mid;
        } else {
            low = mid;
        }
    }
    high
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_largest_root_modulus() {
        // z^2 - 0.25 = (z - 0.5)(z + 0.5); z + 0.9; complex pair of modulus 0.8.
        assert!((largest_root_modulus(&[0.0, -0.25]) - 0.5).abs() < 1e-6);
        assert!((largest_root_modulus(&[0.9]) - 0.9).abs() < 1e-6);
        assert!((largest_root_modulus(&[0.0, 0.64]) - 0.8).abs() < 1e-6);
        assert_eq!(largest_root_modulus(&[-1.0]), 1.0);
    }
}
