//! The redundant-INS models (mwd_core::redundant) against what the paper
//! states about them: the reduction of eq. 10, the rank of eq. 27, and the
//! physics of the navigation block.

use mwd_core::conventions::DEG;
use mwd_core::earth::{normal_gravity, radii, EARTH_RATE};
use mwd_core::redundant::{
    full_dynamics, full_noise_input, navigation_block, reduced_dynamics, reduced_noise_input,
    reduction, stripped_rank, Motion,
};
use nalgebra::{Matrix3, SMatrix};
use proptest::prelude::*;

const TOLERANCE: f64 = 1e-9;

fn radius(lat: f64) -> f64 {
    let r = radii(lat);
    (r.meridian * r.transverse).sqrt()
}

/// Body-to-ENU rotation of a level body turned by `angle` about up, then
/// flipped by 180 deg about its own x axis if `flipped` (the master's
/// dwell orientations).
fn orientation(angle: f64, flipped: bool) -> Matrix3<f64> {
    let (s, c) = angle.sin_cos();
    let about_up = Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0);
    let flip = if flipped {
        Matrix3::from_diagonal(&nalgebra::Vector3::new(1.0, -1.0, -1.0))
    } else {
        Matrix3::identity()
    };
    about_up * flip
}

fn rank_at(m: &Motion, c_b1: &Matrix3<f64>) -> usize {
    let f = reduced_dynamics::<f64>(m, c_b1);
    stripped_rank(
        &[f],
        normal_gravity(m.lat, m.height),
        radius(m.lat),
        TOLERANCE,
    )
}

#[test]
fn reduced_model_is_observable_in_uniform_motion_eq_27() {
    for lat in [-60.0, -10.0, 0.0, 32.0, 75.0] {
        for (speed, course) in [(0.0, 0.0), (5.0, 90.0), (10.0, 37.0)] {
            let m = Motion::uniform(lat * DEG, 0.0, speed, course * DEG, 9.8);
            for heading in [0.0, 90.0, 215.0] {
                let rank = rank_at(&m, &orientation(heading * DEG, false));
                assert_eq!(
                    rank, 8,
                    "lat {lat} speed {speed} course {course} heading {heading}"
                );
            }
        }
    }
}

#[test]
fn the_rank_test_sees_an_unobservable_drift() {
    // a drift that does not reach the attitude (its column zeroed) cannot be
    // seen: rank 7, so the rank 8 above is not the test's default.
    let m = Motion::uniform(32.0 * DEG, 0.0, 5.0, 90.0 * DEG, 9.8);
    let mut f = reduced_dynamics::<f64>(&m, &Matrix3::identity());
    f.fixed_view_mut::<3, 1>(0, 7).fill(0.0);
    assert_eq!(stripped_rank(&[f], 9.8, radius(32.0 * DEG), TOLERANCE), 7);
    // nor does a system with no segments determine anything.
    assert_eq!(stripped_rank::<f64>(&[], 9.8, 6.4e6, TOLERANCE), 0);
}

#[test]
fn stripped_matrix_of_the_backups_dwells_has_rank_8() {
    let m = Motion::uniform(32.0 * DEG, 0.0, 5.0, 90.0 * DEG, 9.8);
    let segments: Vec<SMatrix<f64, 8, 8>> = [0.0, 180.0, 90.0, 270.0]
        .iter()
        .map(|a| reduced_dynamics(&m, &orientation(a * DEG, false)))
        .collect();
    assert_eq!(
        stripped_rank(&segments, 9.8, radius(32.0 * DEG), TOLERANCE),
        8
    );
}

#[test]
fn the_model_is_generic_over_the_scalar() {
    let m = Motion::uniform(32.0 * DEG, 0.0, 5.0, 90.0 * DEG, 9.8);
    let f32_model = reduced_dynamics::<f32>(&m, &Matrix3::identity());
    let f64_model = reduced_dynamics::<f64>(&m, &Matrix3::identity());
    for (a, b) in f32_model.iter().zip(f64_model.iter()) {
        assert!((*a as f64 - b).abs() <= 1e-6 * b.abs());
    }
}

#[test]
fn navigation_block_at_rest_oscillates_at_schuler_and_earth_rate() {
    // At rest the error model's modes are the Schuler oscillation split by
    // the Foucault rate, omega_s +- Omega sin L, and the earth-rate
    // (24 h) mode: a physics check of eq. 12-17 independent of the paper's
    // print.
    let lat = 45.0 * DEG;
    let g = normal_gravity(lat, 0.0);
    let m = Motion::uniform(lat, 0.0, 0.0, 0.0, g);
    let f = navigation_block::<f64>(&m);
    let mut freqs: Vec<f64> = f
        .complex_eigenvalues()
        .iter()
        .map(|e| e.im)
        .filter(|w| *w > 0.0)
        .collect();
    freqs.sort_by(f64::total_cmp);
    let schuler = (g / radius(lat)).sqrt();
    let foucault = EARTH_RATE * lat.sin();
    let expected = [EARTH_RATE, schuler - foucault, schuler + foucault];
    assert_eq!(freqs.len(), 3, "{freqs:?}");
    for (got, want) in freqs.iter().zip(expected) {
        assert!((got - want).abs() < 0.01 * want, "{got} vs {want}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    /// eq. 10, numerically: the directly written F_r and G_r (eq. 11, 18)
    /// equal T F T^T and T G of the full model for any motion and any two
    /// orientations.
    #[test]
    fn reduced_model_equals_t_f_t_transpose(
        lat in -80.0..80.0f64, speed in 0.0..15.0f64, course in 0.0..360.0f64,
        f_e in -0.5..0.5f64, f_n in -0.5..0.5f64,
        a1 in 0.0..360.0f64, a2 in 0.0..360.0f64, flip in any::<bool>(),
    ) {
        let mut m = Motion::uniform(lat * DEG, 100.0, speed, course * DEG, 9.8);
        m.specific_force_enu = [f_e, f_n, 9.8];
        let (c1, c2) = (orientation(a1 * DEG, false), orientation(a2 * DEG, flip));
        let t = reduction::<f64>();
        let full = full_dynamics(&m, &c1, &c2);
        let projected = t * full * t.transpose();
        prop_assert_eq!(reduced_dynamics(&m, &c1), projected);
        prop_assert_eq!(reduced_noise_input(&c1, &c2), t * full_noise_input(&c1, &c2));
        // T keeps exactly the eight states: T T^T = I_8.
        prop_assert_eq!(t * t.transpose(), SMatrix::<f64, 8, 8>::identity());
    }
}
