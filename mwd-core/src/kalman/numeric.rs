//! The filter's scalar (f32 on the probe, f64 on the host) and the
//! standard deviation of a variance that may not be valid.

use nalgebra::RealField;

/// The filter's scalar: f32 or f64.
pub trait FilterScalar: RealField + Copy {
    fn of(x: f64) -> Self;
    fn as_f64(self) -> f64;
}

impl FilterScalar for f32 {
    fn of(x: f64) -> Self {
        x as f32
    }
    fn as_f64(self) -> f64 {
        self as f64
    }
}

impl FilterScalar for f64 {
    fn of(x: f64) -> Self {
        x
    }
    fn as_f64(self) -> f64 {
        self
    }
}

/// sqrt of a variance: NaN for a negative or NaN one, +inf for +inf.
pub fn std_dev_of<T: FilterScalar>(variance: T) -> T {
    if variance >= T::zero() {
        variance.sqrt()
    } else {
        T::zero() / T::zero()
    }
}
