//! Weighting functions of this probe's stationary gyrocompass survey, valid
//! from 0 to 180 deg inclination (derivation: docs/probe-tool-model.md).
//!
//! The probe has gyros only across the tool (body x right, z up; y along
//! the tool) and three accelerometers. At a station the accelerometers give
//! inclination `I` and gravity toolface `theta` (high side to body +z,
//! clockwise looking down-hole, `mwd_core::conventions`); the gyros,
//! rotated by `theta` into the hole's right (`r`) and high-side (`h`)
//! directions, measure the earth rate across the tool:
//!
//! ```text
//! m(A) = ( w_r, w_h ) = ( -Omega_h sin A,  Omega_h cos I cos A + Omega_v sin I )
//! ```
//!
//! (`Omega_h = Omega cos(lat)`, `Omega_v = Omega sin(lat)`). The azimuth is
//! the least-squares fit of `m(A)` to the two readings, with `I` known. To
//! first order (Gauss-Newton at the solution) a reading error `e` gives
//! `dA = m'(A) . e / |m'(A)|^2`, with
//!
//! ```text
//! m'(A) = -Omega_h ( cos A, cos I sin A ),   |m'(A)| = Omega_h S,
//! S = sqrt(1 - sin^2 I sin^2 A)          (the azimuth sensitivity)
//! ```
//!
//! so the azimuth gradient with respect to the `r` and `h` readings is
//! `g = (g_r, g_h) = -(cos A, cos I sin A) / (Omega_h S^2)`, `|g| = 1 /
//! (Omega_h S)`. Unlike the OWSG GYRO-MWD functions (SPE 90408 Tables 1 and
//! 4), which divide the high-side channel by `cos I`, nothing here is
//! singular at 90 deg; `S` vanishes only for a horizontal tool heading east
//! or west, where `w_r` is stationary in `A` and `w_h` does not depend on
//! it. Below [`MIN_AZIMUTH_SENSITIVITY`] the station's azimuth is taken as
//! undetermined: the weights are NaN, so every covariance from that
//! station on is NaN (never a number extrapolated from the first-order
//! model). `host-sim survey` stops the model before such a station and
//! flags it (`survey_listing::apply_model`); it does the same where the
//! station's own first-order azimuth sigma from the gyro terms is beyond
//! [`first_order_azimuth_limit`] (the range the first-order model holds
//! in, measured by the Monte Carlo of `probe_weighting/tests.rs`) - for
//! the SCC1300 at one 120 s station, everywhere.
//!
//! Functions (`Wt.Fn.` names):
//! * `PRB-GXB`, `PRB-GZB`: a bias of the body-x / body-z gyro. It enters
//!   `(r, h)` through the toolface: x gives `(cos theta, -sin theta)`, z
//!   gives `(sin theta, cos theta)`, so the azimuth weights are
//!   `g_r cos theta - g_h sin theta` and `g_r sin theta + g_h cos theta`.
//!   Without a toolface each is given the bound `|g| = 1 / (Omega_h S)`,
//!   valid for any toolface (the largest either weight takes over theta);
//!   with equal biases on both axes it overstates the station's azimuth
//!   variance by a factor 2 (sigma by sqrt 2), and along a straight hole
//!   it bounds the covariance for any sequence of toolfaces.
//! * `PRB-GN`: white noise of equal sigma on both gyros: its azimuth sigma
//!   `|g| sigma` does not depend on the toolface (the rotation keeps the
//!   noise isotropic); times the site's `gyro_noise_reduction`, as GXY-RN.

use super::stations::{Site, Station, StationTrig, EARTH_RATE};

/// Smallest azimuth sensitivity `S` at which a station's azimuth counts as
/// determined (docs/probe-tool-model.md, "The threshold"): below it the
/// first-order azimuth error is more than ten times that of a vertical or
/// north/south station, and at 90 deg the two least-squares solutions `A`
/// and `180 deg - A`, which a horizontal tool cannot tell apart, lie within
/// 2 asin(0.1) = 11.5 deg of each other.
pub const MIN_AZIMUTH_SENSITIVITY: f64 = 0.1;

/// The azimuth sensitivity `S = sqrt(1 - sin^2 I sin^2 A)`: the change of
/// the cross-axis earth rate per radian of azimuth, over `Omega_h`.
pub fn azimuth_sensitivity(sin_inc: f64, sin_azi: f64) -> f64 {
    (1.0 - (sin_inc * sin_azi).powi(2)).max(0.0).sqrt()
}

/// Whether the gyrocompass determines the azimuth of a station at this
/// inclination and azimuth (rad).
pub fn azimuth_determined(inc: f64, azi: f64) -> bool {
    azimuth_sensitivity(inc.sin(), azi.sin()) >= MIN_AZIMUTH_SENSITIVITY
}

/// First-order gradient of the least-squares azimuth with respect to the
/// earth rate read along the hole's right and high-side directions,
/// `(g_r, g_h)` in rad per rad/s; `None` where the azimuth is undetermined.
pub fn azimuth_gradient(
    sin_inc: f64,
    cos_inc: f64,
    sin_azi: f64,
    cos_azi: f64,
    horizontal_earth_rate: f64,
) -> Option<[f64; 2]> {
    let s = azimuth_sensitivity(sin_inc, sin_azi);
    if s < MIN_AZIMUTH_SENSITIVITY {
        return None;
    }
    let k = -1.0 / (horizontal_earth_rate * s * s);
    Some([k * cos_azi, k * cos_inc * sin_azi])
}

/// Azimuth weights of the three gyro sources at one station, from the
/// gradient `g` (rad per rad/s): `[x bias, z bias, noise]`. A body-x bias
/// reads as `(cos theta, -sin theta)` on (r, h), a body-z bias as
/// `(sin theta, cos theta)`; without a toolface each bias takes the bound
/// `|g|` (valid for any toolface). The noise weight is `|g|` (isotropic
/// noise stays isotropic under the toolface rotation); the site's
/// noise-reduction factor is not applied here.
fn gyro_weights(grad: [f64; 2], toolface: Option<f64>) -> [f64; 3] {
    let [gr, gh] = grad;
    let bound = gr.hypot(gh);
    match toolface {
        Some(tf) => {
            let (st, ct) = tf.sin_cos();
            [gr * ct - gh * st, gr * st + gh * ct, bound]
        }
        None => [bound, bound, bound],
    }
}

/// The probe's weighting functions: `(dD, dI, dA)` per unit of the source;
/// `None` for a name that is not one of them. NaN azimuth weight at a
/// station whose azimuth is undetermined.
pub(super) fn weighting(
    name: &str,
    s: &Station,
    trig: &StationTrig,
    site: &Site,
) -> Option<[f64; 3]> {
    let omega_h = EARTH_RATE * site.latitude.cos();
    let w = azimuth_gradient(
        trig.sin_inc,
        trig.cos_inc,
        trig.sin_azi,
        trig.cos_azi,
        omega_h,
    )
    .map(|g| gyro_weights(g, s.toolface));
    let a = match name {
        "PRB-GXB" => w.map(|w| w[0]),
        "PRB-GZB" => w.map(|w| w[1]),
        "PRB-GN" => w.map(|w| w[2] * site.gyro_noise_reduction),
        _ => return None,
    };
    Some([0.0, 0.0, a.unwrap_or(f64::NAN)])
}

/// Largest single-station first-order azimuth 1-sigma (deg) at which the
/// first-order (ISCWSA) azimuth error is taken as meaningful where the
/// model is straight (`azimuth_curvature` 0). Measured by the Monte Carlo
/// in `probe_weighting/tests.rs` (study `print_first_order_range`, test
/// `first_order_holds_up_to_the_sigma_limit`; docs/probe-tool-model.md,
/// "Where the first-order model holds"): up to 10 deg the least-squares
/// gyrocompass's azimuth spread exceeds the first-order sigma by 1-4 %
/// there, at 15 deg by up to 8 %, at 30 deg by up to 26 %.
pub const MAX_FIRST_ORDER_AZIMUTH_SIGMA_DEG: f64 = 10.0;

/// Largest `sigma_A * c` (rad, `c` = [`azimuth_curvature`]): the
/// second-order term of the least-squares azimuth relative to the first
/// is `(3/2) c sigma_A` (below), so near the fold of a near-horizontal tool
/// heading east or west the first-order sigma stops holding long before
/// 10 deg. The Monte Carlo puts a 5 % understatement at `sigma_A c` of
/// about 0.1; 0.08 keeps it within about 3 %.
pub const MAX_FIRST_ORDER_CURVATURE_EFFECT: f64 = 0.08;

/// The model's parameter-effect curvature in azimuth (Bates & Watts 1980,
/// relative curvature of a nonlinear least-squares fit, one parameter):
/// `c = |m'(A) . m''(A)| / |m'(A)|^2 = sin^2 I |sin A cos A| / S^2`. A
/// second-order expansion of the normal equation `m'(A) . (y - m(A)) = 0`
/// gives `dA = dA1 + (m'' . e dA1 - (3/2) (m' . m'') dA1^2) / |m'|^2`, with
/// `dA1` the first-order error: the squared term, relative to `dA1`, is
/// `(3/2) c dA1`. `c` is 0 at vertical and heading north or south, 0.58
/// horizontal at 30 deg azimuth, 5.7 at 80 deg; infinite where `S` is 0.
pub fn azimuth_curvature(sin_inc: f64, sin_azi: f64, cos_azi: f64) -> f64 {
    let s2 = azimuth_sensitivity(sin_inc, sin_azi).powi(2);
    sin_inc * sin_inc * (sin_azi * cos_azi).abs() / s2
}

/// The largest single-station first-order azimuth 1-sigma (rad) at which
/// the first-order model holds at this inclination and azimuth (rad):
/// [`MAX_FIRST_ORDER_AZIMUTH_SIGMA_DEG`], less near the fold
/// ([`MAX_FIRST_ORDER_CURVATURE_EFFECT`] / `c`).
pub fn first_order_azimuth_limit(inc: f64, azi: f64) -> f64 {
    let (sa, ca) = azi.sin_cos();
    let c = azimuth_curvature(inc.sin(), sa, ca);
    let max = MAX_FIRST_ORDER_AZIMUTH_SIGMA_DEG.to_radians();
    if c > 0.0 {
        max.min(MAX_FIRST_ORDER_CURVATURE_EFFECT / c)
    } else {
        max
    }
}

/// Gyro error magnitudes of one station, rad/s (root-sum-square of the
/// table's terms of each kind): white + coloured noise of the station
/// mean on both cross-axis gyros (`PRB-GN`), residual bias of the body-x
/// (`PRB-GXB`) and body-z (`PRB-GZB`) gyro.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GyroErrors {
    pub noise: f64,
    pub bias_x: f64,
    pub bias_z: f64,
}

/// The first-order azimuth 1-sigma (rad) of a single station from the
/// gyro errors alone, the same weights as the engine (toolface when given,
/// else the bound; the noise times `noise_reduction`); `None` where the
/// azimuth is undetermined (`S` below [`MIN_AZIMUTH_SENSITIVITY`]).
pub fn single_station_azimuth_sigma(
    inc: f64,
    azi: f64,
    toolface: Option<f64>,
    latitude: f64,
    noise_reduction: f64,
    e: &GyroErrors,
) -> Option<f64> {
    let (si, ci) = inc.sin_cos();
    let (sa, ca) = azi.sin_cos();
    let g = azimuth_gradient(si, ci, sa, ca, EARTH_RATE * latitude.cos())?;
    let [wx, wz, wn] = gyro_weights(g, toolface);
    let var = (e.bias_x * wx).powi(2)
        + (e.bias_z * wz).powi(2)
        + (e.noise * noise_reduction * wn).powi(2);
    Some(var.sqrt())
}

#[cfg(test)]
mod tests;
