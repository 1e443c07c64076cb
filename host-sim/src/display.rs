//! How the host shows angles and their uncertainty to people, in one
//! place: azimuth and toolface in [0, 360) deg; an azimuth whose sigma is
//! beyond what the alignment calls determined is shown as "undetermined",
//! never as a number; a placeholder (NaN, e.g. no solution yet) as "n/a".

use mwd_core::alignment::MAX_DETERMINED_SIGMA;
use mwd_core::conventions::wrap_two_pi;

/// An angle (rad) in degrees in [0, 360): azimuth and toolface.
pub fn deg_0_360(angle_rad: f64) -> f64 {
    let deg = wrap_two_pi(angle_rad).to_degrees();
    // wrap_two_pi can round up to exactly 2 pi.
    if deg >= 360.0 {
        0.0
    } else {
        deg
    }
}

/// Whether an azimuth with this 1-sigma (rad) is determined: finite and
/// within [`MAX_DETERMINED_SIGMA`] (the alignment's own rule).
pub fn azimuth_is_determined(sigma_rad: f64) -> bool {
    sigma_rad.is_finite() && sigma_rad <= MAX_DETERMINED_SIGMA
}

/// An azimuth for people: "123.46 +- 1.23 deg (1 sigma)" with `decimals`
/// decimals, "undetermined" when its sigma says so, "n/a" for a
/// placeholder.
pub fn azimuth_text(azimuth_rad: f64, sigma_rad: f64, decimals: usize) -> String {
    if !azimuth_rad.is_finite() || sigma_rad.is_nan() {
        "n/a".to_string()
    } else if !azimuth_is_determined(sigma_rad) {
        "undetermined".to_string()
    } else {
        format!(
            "{:.decimals$} +- {:.decimals$} deg (1 sigma)",
            deg_0_360(azimuth_rad),
            sigma_rad.to_degrees()
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mwd_core::conventions::DEG;

    #[test]
    fn azimuths_read_in_0_to_360() {
        assert_eq!(deg_0_360(-90.0 * DEG), 270.0);
        assert!((deg_0_360(725.0 * DEG) - 5.0).abs() < 1e-9);
        assert_eq!(deg_0_360(-1e-18), 0.0);
        assert!(deg_0_360(-1e-18) < 360.0);
    }

    #[test]
    fn an_undetermined_azimuth_is_never_a_number() {
        assert_eq!(azimuth_text(1.0, f64::INFINITY, 2), "undetermined");
        assert_eq!(azimuth_text(1.0, 25.0 * DEG, 2), "undetermined");
        assert_eq!(azimuth_text(f64::NAN, 0.1, 2), "n/a");
        assert_eq!(azimuth_text(1.0, f64::NAN, 2), "n/a");
        assert_eq!(
            azimuth_text(-30.0 * DEG, 1.5 * DEG, 2),
            "330.00 +- 1.50 deg (1 sigma)"
        );
    }
}
