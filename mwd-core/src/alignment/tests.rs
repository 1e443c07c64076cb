use super::misfit::{Misfit, GRID_POINTS};
use super::segments::MeanSigmas;
use super::uncertainty::{half_width, ALLOWED_CHI2};
use super::*;
use crate::conventions::specific_force_at_rest;
use crate::conventions::{dcm_from_euler, wrap_pi, Euler};
use crate::earth::earth_rate_n;
use crate::earth::{normal_gravity, Position};
use crate::probe_sample::ProbeSample;
use crate::sensor_noise::ImuNoise;
use core::f64::consts::{PI, TAU};
use nalgebra::Vector3;
use proptest::prelude::*;

use crate::conventions::DEG;

fn config(noise: ImuNoise, prior: Option<f64>) -> AlignmentConfig {
    AlignmentConfig {
        noise,
        ..AlignmentConfig::probe(Position::paper_site().lat)
    }
    .with_heading_prior(prior)
}

fn segment(specific_force: Vector3<f64>, rate: Vector3<f64>, samples: usize) -> StaticSegment {
    StaticSegment {
        mean: ProbeSample::new(rate.x, rate.z, specific_force),
        samples,
    }
}

/// The exact means of a perfect probe at rest with attitude `e`, plus a
/// gyro bias.
fn ideal_segment(e: &Euler, bias: Vector3<f64>) -> StaticSegment {
    let site = Position::paper_site();
    let g = normal_gravity(site.lat, site.height);
    let c_nb = dcm_from_euler(e).transpose();
    segment(
        specific_force_at_rest(e, g),
        c_nb * earth_rate_n(site.lat) + bias,
        100,
    )
}

/// Noise-free data: roll and pitch to 1e-6 deg; heading to 1e-3 deg
/// wherever the geometry allows (not ill-conditioned), with a prior
/// within 60 deg choosing between mirror candidates. The ill-conditioned
/// cases, whose heading is not checked, are counted: a few in 64 random
/// attitudes are (near east or west with little pitch, or with a prior
/// there; typically 3 to 6), and at least three quarters of all cases
/// (48 of 64) must have had their heading checked, so the heading
/// assertion cannot quietly become vacuous.
#[test]
fn noise_free_alignment_recovers_the_attitude() {
    let runner_config = ProptestConfig {
        source_file: Some(file!()),
        ..ProptestConfig::with_cases(64)
    };
    let cases = runner_config.cases;
    let mut runner = proptest::test_runner::TestRunner::new(runner_config);
    let checked = core::cell::Cell::new(0u32);
    let skipped = core::cell::Cell::new(0u32);
    let strategy = (-3.1f64..3.1, -1.3f64..1.3, -3.1f64..3.1, -1.0f64..1.0);
    runner
        .run(&strategy, |(roll, pitch, heading, prior_offset)| {
            let truth = Euler::new(roll, pitch, heading);
            let seg = ideal_segment(&truth, Vector3::zeros());
            let cfg = config(ImuNoise::NONE, Some(heading + prior_offset));
            let lev = level_segment(&seg, &cfg).unwrap();
            prop_assert!(wrap_pi(lev.roll.value - roll).abs() < 1e-6 * DEG);
            prop_assert!((lev.pitch.value - pitch).abs() < 1e-6 * DEG);
            let est = gyrocompass(&[seg], &cfg).unwrap();
            if est.ill_conditioned {
                skipped.set(skipped.get() + 1);
            } else {
                let err = wrap_pi(est.heading.value - heading).abs();
                prop_assert!(err < 1e-3 * DEG, "error {} deg", err / DEG);
                checked.set(checked.get() + 1);
            }
            Ok(())
        })
        .unwrap();
    let (checked, skipped) = (checked.get(), skipped.get());
    let total = checked + skipped;
    assert!(total >= cases, "only {total} of {cases} cases ran");
    assert!(
        4 * checked >= 3 * total,
        "heading checked in only {checked} of {total} cases ({skipped} ill-conditioned)"
    );
}

/// Fixed well-conditioned attitudes (headings near north or south, rolled
/// and pitched, prior 30 deg off), so the heading check above never rests
/// on the random draw alone: none may be flagged, all must be determined
/// and recovered to 1e-3 deg.
#[test]
fn noise_free_heading_is_recovered_at_fixed_well_conditioned_attitudes() {
    let attitudes = [
        (0.3, 0.2, 0.0),
        (-2.0, -0.8, 3.0),
        (1.2, 0.5, -0.4),
        (3.0, -1.2, 2.8),
        (0.0, 0.0, 0.3),
        (-0.7, 1.0, -2.9),
        (2.2, 0.1, 0.5),
        (-3.0, -0.3, -0.2),
    ];
    for (roll, pitch, heading) in attitudes {
        let seg = ideal_segment(&Euler::new(roll, pitch, heading), Vector3::zeros());
        let cfg = config(ImuNoise::NONE, Some(heading + 30.0 * DEG));
        let est = gyrocompass(&[seg], &cfg).unwrap();
        let at = (roll, pitch, heading);
        assert!(!est.ill_conditioned, "{at:?} flagged: {est:?}");
        assert!(est.determined, "{at:?} undetermined: {est:?}");
        let err = wrap_pi(est.heading.value - heading).abs();
        assert!(err < 1e-3 * DEG, "{at:?}: error {} deg", err / DEG);
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Analytical alignment (eq. 30): with the probe's two gyros one of its
    /// two candidates is the truth.
    #[test]
    fn analytical_alignment_on_noise_free_data(
        roll in -3.1f64..3.1, pitch in -1.3f64..1.3, heading in -3.1f64..3.1,
    ) {
        let truth = Euler::new(roll, pitch, heading);
        let seg = ideal_segment(&truth, Vector3::zeros());
        let probe = analytical(&seg, &config(ImuNoise::NONE, None)).unwrap();
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
        let est = gyrocompass(&[seg], &config(noise, Some(heading * DEG))).unwrap();
        assert_eq!(est.ill_conditioned, expect_ill, "heading {heading}");
    }
}

/// The flag comes from the geometry, not from the prior: a tool heading
/// east or west is flagged with no prior at all and with a prior pointing
/// north or south (far from the truth), and a tool heading north or south
/// is not flagged without a prior. A prior near east still flags a tool
/// heading north (the documented second source of the flag).
#[test]
fn east_west_flag_comes_from_the_geometry_not_the_prior() {
    let noise = ImuNoise::scc1300();
    for heading in [90.0, -95.0, 80.0, -90.0] {
        let seg = ideal_segment(&Euler::new(0.2, -0.05, heading * DEG), Vector3::zeros());
        for prior in [None, Some(0.0), Some(PI), Some(heading * DEG + PI)] {
            let est = gyrocompass(&[seg], &config(noise, prior)).unwrap();
            assert!(
                est.ill_conditioned,
                "heading {heading}, prior {prior:?}: not flagged ({est:?})"
            );
        }
    }
    for heading in [0.0, 170.0, -10.0] {
        let seg = ideal_segment(&Euler::new(0.2, -0.05, heading * DEG), Vector3::zeros());
        let est = gyrocompass(&[seg], &config(noise, None)).unwrap();
        assert!(!est.ill_conditioned, "heading {heading} flagged: {est:?}");
    }
    let north = ideal_segment(&Euler::new(0.2, -0.05, 0.0), Vector3::zeros());
    let est = gyrocompass(&[north], &config(noise, Some(PI / 2.0))).unwrap();
    assert!(est.ill_conditioned, "prior east did not flag: {est:?}");
}

/// A level tool heading 89 deg (noise-free) has its
/// mirror candidate at 91 deg, closer than the 5 deg search grid: both
/// minima must be found, the heading reported ambiguous, and the prior
/// must choose (before, the two were merged and 91.000 came back as the
/// only answer). Also 1 deg from west, and at 0.5 deg from east.
#[test]
fn mirror_candidates_closer_than_the_grid_step_are_both_found() {
    for (heading, mirror) in [(89.0, 91.0), (-88.0, -92.0), (90.5, 89.5)] {
        let seg = ideal_segment(&Euler::new(0.0, 0.0, heading * DEG), Vector3::zeros());
        for (prior, expected, other) in [(heading, heading, mirror), (mirror, mirror, heading)] {
            let est = gyrocompass(&[seg], &config(ImuNoise::NONE, Some(prior * DEG))).unwrap();
            assert!(est.ambiguous, "heading {heading}, prior {prior}: {est:?}");
            assert!(
                wrap_pi(est.heading.value - expected * DEG).abs() < 1e-3 * DEG,
                "heading {heading}, prior {prior}: {} deg",
                est.heading.value / DEG
            );
            let alt = est.alternative.expect("the mirror candidate");
            assert!(
                wrap_pi(alt - other * DEG).abs() < 1e-3 * DEG,
                "heading {heading}: alternative {} deg",
                alt / DEG
            );
        }
    }
}

#[test]
fn level_tool_heading_north_is_ambiguous_until_a_prior_chooses() {
    let truth = Euler::new(0.0, 0.0, 10.0 * DEG);
    let seg = ideal_segment(&truth, Vector3::zeros());
    let noise = ImuNoise::scc1300();
    let est = gyrocompass(&[seg], &config(noise, Some(0.0))).unwrap();
    assert!(est.ambiguous);
    let alt = est.alternative.unwrap();
    // The mirror candidate is 180 deg - heading.
    assert!(wrap_pi(alt - (PI - truth.heading)).abs() < 1e-6);
    assert!(wrap_pi(est.heading.value - truth.heading).abs() < 1e-6);
    let south = gyrocompass(&[seg], &config(noise, Some(PI))).unwrap();
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
    let cfg = config(noise, Some(0.0));
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
    let cfg = config(ImuNoise::scc1300(), Some(0.3));
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
    let cfg = config(ImuNoise::scc1300(), None);
    let mut nan = good;
    nan.mean.gyro[0] = f64::NAN;
    assert_eq!(gyrocompass(&[nan], &cfg), Err(AlignmentError::InvalidData));
    let mut moving = good;
    moving.mean.specific_force *= 1.5;
    assert_eq!(level_segment(&moving, &cfg), Err(AlignmentError::NotStatic));
    assert_eq!(gyrocompass(&[], &cfg), Err(AlignmentError::SegmentCount));
    let too_many = [good; MAX_SEGMENTS + 1];
    assert_eq!(
        gyrocompass(&too_many, &cfg),
        Err(AlignmentError::SegmentCount)
    );
    let empty = StaticSegment { samples: 0, ..good };
    assert_eq!(analytical(&empty, &cfg), Err(AlignmentError::InvalidData));
}

#[test]
fn errors_read_as_sentences_not_variant_names() {
    extern crate std;
    use std::string::ToString;
    for e in [
        AlignmentError::SegmentCount,
        AlignmentError::InvalidData,
        AlignmentError::NotStatic,
        AlignmentError::NoHeadingInformation,
    ] {
        let (text, name) = (e.to_string(), std::format!("{e:?}"));
        assert!(text.split(' ').count() >= 4, "{name}: `{text}`");
        assert!(!text.contains(&name), "{name}: `{text}`");
    }
}

#[test]
fn no_heading_information_at_the_pole() {
    let mut cfg = config(ImuNoise::scc1300(), None);
    cfg.latitude = PI / 2.0;
    // At the pole the earth rate is vertical: the same at every heading.
    let c_nb = dcm_from_euler(&Euler::new(0.1, 0.0, 0.0)).transpose();
    let seg = segment(
        specific_force_at_rest(&Euler::new(0.1, 0.0, 0.0), 9.83),
        c_nb * earth_rate_n(cfg.latitude),
        100,
    );
    // Either no minimum at all, or one that is flagged and undetermined.
    match gyrocompass(&[seg], &cfg) {
        Err(e) => assert_eq!(e, AlignmentError::NoHeadingInformation),
        Ok(est) => assert!(est.ill_conditioned && !est.determined, "{est:?}"),
    }
}

/// Two toolface positions 180 deg apart, `samples` each, at one heading.
fn indexed_pair(pitch: f64, heading: f64, samples: usize) -> [StaticSegment; 2] {
    let at = |roll: f64| StaticSegment {
        samples,
        ..ideal_segment(&Euler::new(roll, pitch, heading), Vector3::zeros())
    };
    [at(0.4), at(0.4 + PI)]
}

/// Noise pulls the estimate of a tool heading east away from east, to
/// where the geometry is good and the local curvature of the misfit is
/// high. Here the gyro means are exactly those of a tool heading 55 deg
/// (2 x 10 min, toolface-indexed), and a tool heading east explains them
/// within the noise. At 55 deg the sensitivity alone would not flag the
/// heading, and the local (Cramer-Rao) 2 sigma would not reach east; the
/// headings the data allow do, so the heading is flagged and its bound
/// covers east (or it is undetermined), with or without a prior.
#[test]
fn a_heading_pulled_away_from_east_is_flagged_and_its_bound_reaches_east() {
    let noise = ImuNoise::scc1300();
    let heading = 55.0 * DEG;
    let segs = indexed_pair(-0.1, heading, 12_000);
    let cfg = config(noise, None);
    let sigmas = MeanSigmas::new(&segs, &cfg);
    let model = Misfit::new(&segs, &cfg, &sigmas);
    // The premises: what the estimate alone says, and what the data allow.
    assert!(model.sensitivity(heading) > ILL_CONDITIONED_SENSITIVITY);
    let local_bound = COVERAGE_FACTOR * model.cramer_rao_sigma(heading);
    assert!(local_bound < 35.0 * DEG, "{}", local_bound / DEG);
    let east = model.cost(PI / 2.0) - model.cost(heading);
    assert!(east < ALLOWED_CHI2, "east is {east} above the minimum");
    for prior in [None, Some(0.0), Some(heading)] {
        let est = gyrocompass(&segs, &config(noise, prior)).unwrap();
        assert!(wrap_pi(est.heading.value - heading).abs() < 1e-3 * DEG);
        assert!(est.ill_conditioned, "prior {prior:?}: {est:?}");
        assert!(est.bound() >= 35.0 * DEG, "prior {prior:?}: {est:?}");
    }
}

/// Where the misfit is nearly quadratic (heading north, 2 x 5 min
/// indexed) the allowed interval is the local 2 sigma, a few percent wider
/// on the side towards east/west; its edges lie where the misfit crosses
/// the threshold; and the heading stays determined and unflagged.
#[test]
fn allowed_interval_is_the_local_bound_where_the_misfit_is_quadratic() {
    let noise = ImuNoise::scc1300();
    let step = TAU / GRID_POINTS as f64;
    for (pitch, heading) in [(-0.1, 0.0), (0.3, 5.0 * DEG), (0.0, 180.0 * DEG)] {
        let segs = indexed_pair(pitch, heading, 6000);
        let cfg = config(noise, Some(heading));
        let sigmas = MeanSigmas::new(&segs, &cfg);
        let model = Misfit::new(&segs, &cfg, &sigmas);
        let grid = model.grid();
        let threshold = model.cost(heading) + ALLOWED_CHI2;
        let (below, above) = model
            .allowed_interval(&grid, heading, threshold)
            .expect("not the whole circle");
        let local = COVERAGE_FACTOR * model.cramer_rao_sigma(heading);
        for side in [below, above] {
            assert!(
                side > 0.97 * local && side < 1.15 * local,
                "edge {} deg, local 2 sigma {} deg",
                side / DEG,
                local / DEG
            );
        }
        for edge in [heading - below, heading + above] {
            let inward = if edge < heading { step } else { -step } / 512.0;
            assert!(model.cost(edge) > threshold);
            assert!(model.cost(edge + inward) <= threshold);
        }
        let est = gyrocompass(&segs, &cfg).unwrap();
        assert!(est.determined && !est.ill_conditioned, "{est:?}");
        // The estimate's own interval, to the bisection's resolution.
        let expected = (half_width(Some((below, above))) - step / 256.0) / COVERAGE_FACTOR;
        assert!(est.heading.sigma >= expected, "{est:?}");
    }
}

/// When the data exclude no heading (5 s, one position) the allowed
/// interval is the whole circle: the heading is undetermined with a
/// finite sigma (a quarter turn; no "no solution"), and the flag comes
/// from the candidates and the prior (tested above).
#[test]
fn five_seconds_allow_every_heading() {
    let seg = ideal_segment(&Euler::new(0.2, -0.05, 0.0), Vector3::zeros());
    let cfg = config(ImuNoise::scc1300(), None);
    let sigmas = MeanSigmas::new(core::slice::from_ref(&seg), &cfg);
    let model = Misfit::new(core::slice::from_ref(&seg), &cfg, &sigmas);
    let grid = model.grid();
    let threshold = model.cost(0.0) + ALLOWED_CHI2;
    assert_eq!(model.allowed_interval(&grid, 0.0, threshold), None);
    let est = gyrocompass(&[seg], &cfg).unwrap();
    assert!(!est.determined && est.bound() == PI, "{est:?}");
    assert!(est.heading.sigma.is_finite() && est.heading.sigma >= PI / COVERAGE_FACTOR);
    let tri = analytical(&seg, &cfg).unwrap();
    assert!(
        !tri.determined && tri.heading.sigma >= PI / COVERAGE_FACTOR,
        "{tri:?}"
    );
}
