//! The physical range of a number in one of the tool's files, and the
//! check that names the field and the range when a value is outside it.
//! Each file type lists its ranges in one place (`calibration_file`,
//! `ar_file`, `sim::model_file`); the README's tables repeat them.

use anyhow::{bail, Result};

/// An inclusive range of finite values, with its unit for messages.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Range {
    pub min: f64,
    pub max: f64,
    /// Unit as people read it ("" for a ratio).
    pub unit: &'static str,
}

impl Range {
    pub const fn new(min: f64, max: f64, unit: &'static str) -> Self {
        Self { min, max, unit }
    }

    /// A range symmetric about zero.
    pub const fn within(limit: f64, unit: &'static str) -> Self {
        Self::new(-limit, limit, unit)
    }

    /// Whether `value` is a finite number inside the range.
    pub fn contains(&self, value: f64) -> bool {
        value.is_finite() && value >= self.min && value <= self.max
    }

    /// `value` if it is inside the range, else an error naming `field`,
    /// the value and the range.
    pub fn check(&self, field: &str, value: f64) -> Result<f64> {
        if !self.contains(value) {
            let unit = if self.unit.is_empty() {
                String::new()
            } else {
                format!(" {}", self.unit)
            };
            bail!(
                "`{field}` is {}{unit}, outside its range {} to {}{unit}",
                number(value),
                number(self.min),
                number(self.max)
            );
        }
        Ok(value)
    }
}

/// A number as people read it: plain between 1e-4 and 1e6, else in
/// exponent form (never 300 digits).
pub fn number(v: f64) -> String {
    if v == 0.0 || !v.is_finite() || (1e-4..1e6).contains(&v.abs()) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_error_names_the_field_and_the_range() {
        let r = Range::new(0.5, 2.0, "");
        assert_eq!(r.check("gyro[0].scale", 1.0).unwrap(), 1.0);
        let e = r.check("gyro[0].scale", -1.0).unwrap_err().to_string();
        assert_eq!(e, "`gyro[0].scale` is -1, outside its range 0.5 to 2");
        assert!(r.check("x", f64::NAN).is_err());
        let e = Range::within(1.0, "m/s^2").check("b", 1e308).unwrap_err();
        assert!(
            e.to_string()
                .contains("1e308 m/s^2, outside its range -1 to 1 m/s^2"),
            "{e}"
        );
    }
}
