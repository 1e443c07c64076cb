//! The physical range of every field (README, "Sensor-noise analysis and
//! calibration"), for the AR models of the AR model file and of the
//! sensor-model file (`sim::model_file`).

use crate::formats::ranges::Range;
use mwd_core::conventions::DEG;
use mwd_core::sensor_units::{
    ACCEL_LSB_PER_G, ACCEL_RANGE_G, GYRO_LSB_PER_DEG_S, GYRO_RANGE_DEG_S, STANDARD_GRAVITY,
};

/// Model orders a file may hold (the filter takes 4).
pub const ORDER: std::ops::RangeInclusive<usize> = 1..=64;
/// Sample rates of the data a model describes.
pub const SAMPLE_RATE_HZ: Range = Range::new(1e-3, 1e4, "Hz");
/// Largest modulus of a root of the AR polynomial: strictly inside the
/// unit circle with a margin, so that the model is stationary and its
/// correlation time, -1 / (rate ln r), at most ~1000 samples (50 s at
/// 20 Hz; slower drifts belong to the bias states, not the AR ones).
pub const MAX_ROOT_MODULUS: f64 = 0.999;

/// Innovation variance of an accelerometer, (m/s^2)^2: from a
/// thousandth of an LSB (1/650 g) squared, below which the output
/// cannot show it, to the full scale (6 g) squared.
pub fn specific_force_variance() -> Range {
    let lsb = STANDARD_GRAVITY / f64::from(ACCEL_LSB_PER_G);
    let full = f64::from(ACCEL_RANGE_G) * STANDARD_GRAVITY;
    Range::new((1e-3 * lsb).powi(2), full * full, "(m/s^2)^2")
}

/// Innovation variance of a gyro, (rad/s)^2: a thousandth of an LSB
/// (1/18 deg/s) squared to the full scale (300 deg/s) squared.
pub fn angular_rate_variance() -> Range {
    let lsb = DEG / f64::from(GYRO_LSB_PER_DEG_S);
    let full = f64::from(GYRO_RANGE_DEG_S) * DEG;
    Range::new((1e-3 * lsb).powi(2), full * full, "(rad/s)^2")
}

/// Innovation variance of a channel of unknown unit: positive, at most
/// 1e12 (no SCC1300 output, raw counts included, comes near).
pub const OTHER_VARIANCE: Range = Range::new(f64::MIN_POSITIVE, 1e12, "(u)^2");
