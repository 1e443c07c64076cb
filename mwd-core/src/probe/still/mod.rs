//! Still detection for station surveys while drilling: is the probe at
//! rest (the string in the slips at a connection)?
//!
//! Three tests on the corrected samples (both parts) over a sliding window
//! of [`WINDOW`] samples (1 s), each against a threshold derived from the
//! noise budget
//! ([`ImuNoise::scc1300`](crate::sensor_noise::ImuNoise::scc1300))
//! rather than tuned:
//!
//! 1. **rate magnitude**: `T_w = sum_k sum_i w_ki^2 / s_i^2` over the two
//!    gyros (body x and z). The earth rate (<= 15 deg/h) and the residual
//!    bias after calibration (2.1 deg/h) are left in: against a per-sample
//!    sigma of ~0.07 deg/s they add ~0.5 % to the expected value. A
//!    magnitude test, not a variance test, because a slow steady turn
//!    (1 deg/s) has no variance.
//! 2. **force variance**: `T_f = sum_k sum_i (f_ki - mean_i)^2 / s_i^2`
//!    over the three axes: vibration.
//! 3. **gravity magnitude**: `|mean f| - g`, against the residual
//!    accelerometer bias and the noise of the mean: a sustained
//!    acceleration.
//!
//! Under stillness each quadratic statistic is approximately `c chi^2(nu)`
//! (Satterthwaite's two-moment match; exact for white noise, where
//! `c = 1`): `E[T] = c nu` and `Var[T] = 2 c^2 nu`, with `Var[T] = 2 sum_i
//! sum_jk rho_i(j - k)^2` from the autocorrelation of the budget's noise
//! (white + the paper's AR(4) coloured part, `crate::ar`). The chi-square
//! quantile is the Wilson-Hilferty approximation (Wilson & Hilferty 1931:
//! `chi^2_p(nu) ~ nu (1 - 2/(9 nu) + z_p sqrt(2/(9 nu)))^3`; nu is a few
//! tens here; checked against tables at the 1e-3 quantile of chi^2(40) in
//! the tests, an approximation at 1e-7 whose error only changes how rare
//! a split station is; the moment match is Satterthwaite's, Biometrics
//! Bulletin 2(6), 1946). This is the GLRT ("SHOE") family of zero-velocity
//! detectors (Skog, Handel, Nilsson, Rantakokko, "Zero-velocity
//! detection - an algorithm evaluation", IEEE Trans. Biomed. Eng. 57(11),
//! 2010), split into its rate and force parts, with the thresholds from
//! the budget instead of tuned.
//!
//! Per-sample variances: the white density squared times the sample rate,
//! plus the AR model's stationary variance, plus the counts' rounding. The
//! rounding error is at most half a count, so its variance is at most
//! q^2/4; the uniform q^2/12 holds only when the noise spans several counts,
//! which the z accelerometer's (0.36 counts) does not. The bound is used:
//! the still-failure probabilities below are then upper bounds.
//!
//! Hysteresis (two false-alarm probabilities per test and epoch; these are
//! the defaults, the uplink can set others: [`Hysteresis`]):
//! * enter: all three tests pass at [`Z_ENTER`] (one-sided 1e-3 each) on
//!   [`ENTER_EPOCHS`] consecutive samples after a full window: the minimum
//!   still duration is `WINDOW + ENTER_EPOCHS - 1` samples, 39 (1.95 s),
//!   which is also the **detection delay** of a still probe when no window
//!   fails;
//! * stay: each test at [`Z_STAY`] (one-sided 1e-7: over a 5-minute station,
//!   6000 epochs and three tests, a split station has probability <= 0.2 %
//!   before the windows' correlation lowers it further); the first failing
//!   sample ends the still period (motion at 1 deg/s fails the rate test on
//!   its first sample).
//!
//! What it cannot see: a constant velocity (a string sliding at a steady
//! speed has no acceleration and no rate) looks still to any inertial
//! detector; in the slips the string is held. A turn slower than about
//! 0.1 deg/s passes the stay test (it is integrated by the gyros all the
//! same; the zero-velocity update it allows is still right). Only samples
//! with both parts are judged: with one part out a turn about the missing
//! gyro's axis would not be seen, and the navigator resets the detector.
//!
//! The files: `thresholds.rs` (the window, the hysteresis and the
//! thresholds derived from the noise budget) and `detector.rs` (the
//! detector, one sample at a time).

mod detector;
mod thresholds;

pub use detector::{StillDetector, StillStatistics};
pub use thresholds::{
    widened_setting, Hysteresis, StillThresholds, Threshold, DETECTION_DELAY_SAMPLES, ENTER_EPOCHS,
    WINDOW, Z_ENTER, Z_STAY,
};

#[cfg(test)]
pub(crate) mod tests;
