use super::*;
use crate::conventions::specific_force_at_rest;
use crate::earth::{normal_gravity, Position};
use proptest::prelude::*;

const DEG: f64 = PI / 180.0;

fn config(gyro_axes: [bool; 3], noise: ImuNoise, prior: Option<f64>) -> AlignmentConfig {
    AlignmentConfig {
        latitude: Position::paper_site().lat,
        sample_interval: 0.05,
        gyro_axes,
        noise,
        heading_prior: prior,
    }
}

/// The exact means of a perfect probe at rest with attitude `e`, plus a
/// gyro bias.
fn ideal_segment(e: &Euler, bias: Vector3<f64>) -> StaticSegment {
    let site = Position::paper_site();
    let g = normal_gravity(site.lat, site.height);
    let c_nb = dcm_from_euler(e).transpose();
    StaticSegment {
        specific_force: specific_force_at_rest(e, g),
        rate: c_nb * earth_rate_n(site.lat) + bias,
        samples: 100,
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Noise-free data: roll and pitch to 1e-6 deg; heading to 1e-3 deg
    /// wherever the geometry allows (not ill-conditioned), with a prior
    /// within 60 deg choosing between mirror candidates.
    #[test]
    fn noise_free_alignment_recovers_the_attitude(
        roll in -3.1f64..3.1, pitch in -1.3f64..1.3, heading in -3.1f64..3.1,
        prior_offset in -1.0f64..1.0,
    ) {
        let truth = Euler::new(roll, pitch, heading);
        let seg = ideal_segment(&truth, Vector3::zeros());
        let cfg = config(PROBE_GYROS, ImuNoise::NONE, Some(heading + prior_offset));
        let lev = level_segment(&seg, &cfg).unwrap();
        prop_assert!(wrap_pi(lev.roll.value - roll).abs() < 1e-6 * DEG);
        prop_assert!((lev.pitch.value - pitch).abs() < 1e-6 * DEG);
        let est = gyrocompass(&[seg], &cfg).unwrap();
        if !est.ill_conditioned {
            let err = wrap_pi(est.heading.value - heading).abs();
            prop_assert!(err < 1e-3 * DEG, "error {} deg", err / DEG);
        }
    }

    /// Analytical alignment (eq. 30): exact with three gyros; with the
    /// probe's two gyros one of its two candidates is the truth.
    #[test]
    fn analytical_alignment_on_noise_free_data(
        roll in -3.1f64..3.1, pitch in -1.3f64..1.3, heading in -3.1f64..3.1,
    ) {
        let truth = Euler::new(roll, pitch, heading);
        let seg = ideal_segment(&truth, Vector3::zeros());
        let full = analytical(&seg, &config(ALL_GYROS, ImuNoise::NONE, None)).unwrap();
        prop_assert!(wrap_pi(full.heading.value - heading).abs() < 1e-6 * DEG);
        let probe = analytical(&seg, &config(PROBE_GYROS, ImuNoise::NONE, None)).unwrap();
        let best = [Some(probe.heading.value), probe.alternative]
            .iter()
            .flatten()
            .map(|h| wrap_pi(h - heading).abs())
            .fold(f64::INFINITY, f64::min);
        prop_assert!(best < 1e-6 * DEG, "best candidate off by {} deg", best / DEG);
    }
}

#[test]
fn heading_east_or_west_is_ill_conditioned_north_is_not() {
    let noise = ImuNoise::scc1300();
    for (heading, expect_ill) in [(90.0, true), (-95.0, true), (0.0, false), (170.0, false)] {
        let seg = ideal_segment(&Euler::new(0.2, -0.05, heading * DEG), Vector3::zeros());
        let est = gyrocompass(&[seg], &config(PROBE_GYROS, noise, Some(heading * DEG))).unwrap();
        assert_eq!(est.ill_conditioned, expect_ill, "heading {heading}");
    }
}

#[test]
fn level_tool_heading_north_is_ambiguous_until_a_prior_chooses() {
    let truth = Euler::new(0.0, 0.0, 10.0 * DEG);
    let seg = ideal_segment(&truth, Vector3::zeros());
    let noise = ImuNoise::scc1300();
    let est = gyrocompass(&[seg], &config(PROBE_GYROS, noise, Some(0.0))).unwrap();
    assert!(est.ambiguous);
    let alt = est.alternative.unwrap();
    // The mirror candidate is 180 deg - heading.
    assert!(wrap_pi(alt - (PI - truth.heading)).abs() < 1e-6);
    assert!(wrap_pi(est.heading.value - truth.heading).abs() < 1e-6);
    let south = gyrocompass(&[seg], &config(PROBE_GYROS, noise, Some(PI))).unwrap();
    assert!(wrap_pi(south.heading.value - (PI - truth.heading)).abs() < 1e-6);
}

#[test]
fn toolface_indexing_separates_gyro_bias_from_earth_rate() {
    // A gyro bias of 5 deg/h on x and -3 deg/h on z, half the earth rate:
    // one position is biased, two toolfaces 180 deg apart are not.
    let bias = Vector3::new(5.0, 0.0, -3.0) * (DEG / 3600.0);
    let mut noise = ImuNoise::NONE;
    for g in noise.gyro.iter_mut() {
        g.residual_bias = 10.0 * DEG / 3600.0;
    }
    let heading = 20.0 * DEG;
    let a = ideal_segment(&Euler::new(0.3, -0.1, heading), bias);
    let b = ideal_segment(&Euler::new(0.3 + PI, -0.1, heading), bias);
    let cfg = config(PROBE_GYROS, noise, Some(0.0));
    let single = gyrocompass(&[a], &cfg).unwrap();
    assert!(wrap_pi(single.heading.value - heading).abs() > 5.0 * DEG);
    let indexed = gyrocompass(&[a, b], &cfg).unwrap();
    assert!(wrap_pi(indexed.heading.value - heading).abs() < 1e-3 * DEG);
    assert!((indexed.gyro_bias - bias).norm() < 1e-3 * DEG / 3600.0);
    assert!(indexed.heading.sigma < single.heading.sigma / 10.0);
}

#[test]
fn uncertainty_grows_with_gyro_noise_and_shrinks_with_time() {
    let seg = ideal_segment(&Euler::new(0.1, 0.2, 0.3), Vector3::zeros());
    let cfg = config(PROBE_GYROS, ImuNoise::scc1300(), Some(0.3));
    let short = gyrocompass(&[seg], &cfg).unwrap();
    let long = gyrocompass(
        &[StaticSegment {
            samples: 100 * 3600,
            ..seg
        }],
        &cfg,
    )
    .unwrap();
    assert!(long.heading.sigma < short.heading.sigma);
    let lev = level_segment(&seg, &cfg).unwrap();
    // 1 mg residual bias: about 0.057 deg of tilt.
    assert!(lev.roll.sigma > 0.04 * DEG && lev.roll.sigma < 0.1 * DEG);
}

#[test]
fn bad_data_gets_a_clear_error() {
    let good = ideal_segment(&Euler::default(), Vector3::zeros());
    let cfg = config(PROBE_GYROS, ImuNoise::scc1300(), None);
    let mut nan = good;
    nan.rate.x = f64::NAN;
    assert_eq!(gyrocompass(&[nan], &cfg), Err(AlignmentError::InvalidData));
    let mut moving = good;
    moving.specific_force *= 1.5;
    assert_eq!(level_segment(&moving, &cfg), Err(AlignmentError::NotStatic));
    assert_eq!(gyrocompass(&[], &cfg), Err(AlignmentError::SegmentCount));
    let too_many = [good; MAX_SEGMENTS + 1];
    assert_eq!(
        gyrocompass(&too_many, &cfg),
        Err(AlignmentError::SegmentCount)
    );
    let no_gyro = config([false; 3], ImuNoise::scc1300(), None);
    assert_eq!(gyrocompass(&[good], &no_gyro), Err(AlignmentError::NoGyro));
    let empty = StaticSegment { samples: 0, ..good };
    assert_eq!(analytical(&empty, &cfg), Err(AlignmentError::InvalidData));
}

#[test]
fn no_heading_information_at_the_pole() {
    let mut cfg = config(PROBE_GYROS, ImuNoise::scc1300(), None);
    cfg.latitude = PI / 2.0;
    // At the pole the earth rate is vertical: the same at every heading.
    let c_nb = dcm_from_euler(&Euler::new(0.1, 0.0, 0.0)).transpose();
    let seg = StaticSegment {
        specific_force: specific_force_at_rest(&Euler::new(0.1, 0.0, 0.0), 9.83),
        rate: c_nb * earth_rate_n(cfg.latitude),
        samples: 100,
    };
    // Either no minimum at all, or one that is flagged and undetermined.
    match gyrocompass(&[seg], &cfg) {
        Err(e) => assert_eq!(e, AlignmentError::NoHeadingInformation),
        Ok(est) => assert!(est.ill_conditioned && !est.determined, "{est:?}"),
    }
}
