use super::*;
use crate::calibration::ProbeCalibration;
use crate::conventions::{Euler, DEG};
use crate::earth::Position;
use crate::error_model::AugmentedModel;
use crate::probe::raw::{reading, Reading};
use crate::protocol::frame::{nav_flags, nav_mode};
use crate::protocol::NavSolution;
use crate::sensor_noise::ImuNoise;
use crate::timing::ALIGNMENT_SAMPLES;
extern crate std;
use super::super::still::DETECTION_DELAY_SAMPLES;
use crate::calibration::TriadCalibration;
use crate::protocol::frame::raw_flags;
use crate::protocol::RawPart;
use crate::sensor_units::STANDARD_GRAVITY_M_S2;

use super::super::test_support::{
    aligned_navigator, level_sample, level_turning_sample, quieter_gyros, still_sample,
    ALL_ALIGNMENT,
};

#[test]
fn a_body_sample_steps_as_its_raw_frame_does() {
    let position = Position::paper_site();
    let (mut by_raw, mut by_sample) = (Navigator::new(position), Navigator::new(position));
    // Tilted, so the alignment and the filter have work to do.
    let tilted = |n| still_sample(n, [0.3, 0.5, STANDARD_GRAVITY_M_S2 - 0.02]);
    for n in 0..ALL_ALIGNMENT + 40 {
        let raw = tilted(n);
        let sample = match reading(&raw, &ProbeCalibration::default()) {
            Reading::Both(sample) => sample,
            other => panic!("{other:?}"),
        };
        let a = by_raw.step(&raw);
        let b = by_sample.step_sample(raw.time_us, raw.sample_counter, &sample);
        assert_eq!(std::format!("{a:?}"), std::format!("{b:?}"), "sample {n}");
    }
    assert_eq!(by_raw.filter().state(), by_sample.filter().state());
}

#[test]
fn a_quieter_budget_gives_smaller_sigmas() {
    static QUIET: ImuNoise = quieter_gyros(100.0);
    let position = Position::paper_site();
    let (mut scc1300, mut quiet) = (Navigator::new(position), Navigator::new(position));
    quiet.set_noise_budget(&QUIET);
    assert_eq!(scc1300.noise_budget(), &ImuNoise::scc1300());
    let (mut a, mut b) = (None, None);
    for n in 0..ALL_ALIGNMENT {
        a = Some(scc1300.step(&level_sample(n)));
        b = Some(quiet.step(&level_sample(n)));
    }
    let (a, b) = (a.unwrap(), b.unwrap());
    assert_eq!(
        (a.mode, b.mode),
        (nav_mode::NAVIGATING, nav_mode::NAVIGATING)
    );
    // Velocity sigmas are the accelerometers' (the same budget); the
    // filter's covariance stays healthy with the still AR blocks.
    assert!(
        b.velocity_std.iter().all(|s| s.is_finite() && *s > 0.0),
        "{b:?}"
    );
    let gyro_bias = |n: &Navigator, i: usize| {
        n.filter().filter().p[(
            crate::error_model::GYRO_BIAS + i,
            crate::error_model::GYRO_BIAS + i,
        )]
    };
    assert!(gyro_bias(&quiet, 0) < 1e-3 * gyro_bias(&scc1300, 0));
}

#[test]
fn coarse_then_fine_alignment_then_navigation_on_a_still_level_probe() {
    let mut navigator = Navigator::new(Position::paper_site());
    for n in 0..ALIGNMENT_SAMPLES - 1 {
        let s = navigator.step(&level_sample(n));
        // No solution yet: said by the invalid bit that comes with every
        // NaN sigma; the probe has no calibration (bit 9).
        assert_eq!(
            (s.mode, s.flags),
            (
                nav_mode::COARSE_ALIGNMENT,
                nav_flags::SOLUTION_INVALID | nav_flags::UNCALIBRATED
            )
        );
        assert!(s.velocity_std[0].is_nan());
        // No solution yet: the attitude and velocity are placeholders,
        // and look like them.
        assert!(s.attitude.iter().chain(&s.velocity_ned).all(|a| a.is_nan()));
    }
    // A sample with no valid part is flagged and does not count.
    let mut bad = level_sample(99);
    bad.parts[0].flags = 0;
    bad.parts[1].flags = 0;
    let s = navigator.step(&bad);
    assert_eq!(
        s.flags,
        nav_flags::SENSOR_DEGRADED | nav_flags::SOLUTION_INVALID | nav_flags::UNCALIBRATED
    );
    assert!(!navigator.is_aligned());

    // The coarse alignment ends: the filter takes over.
    let first = navigator.step(&level_sample(100));
    assert!(navigator.is_aligned() && !navigator.is_navigating());
    assert_eq!(first.mode, nav_mode::FINE_ALIGNMENT);
    assert!(first.attitude_std[0] > 0.0 && first.attitude_std[1] > 0.0);
    let mut last = first;
    for n in 101..=ALL_ALIGNMENT {
        last = navigator.step(&level_sample(n));
        assert_eq!(last.sample_counter, n);
        assert!(last.attitude[0].abs() < 1e-3 && last.attitude[1].abs() < 1e-3);
        if n < ALL_ALIGNMENT {
            assert_eq!(last.mode, nav_mode::FINE_ALIGNMENT, "sample {n}");
            assert_eq!(
                last.flags,
                nav_flags::ZUPT_APPLIED | nav_flags::UNCALIBRATED,
                "sample {n}"
            );
        }
    }
    // After 60 s the probe navigates; the zero updates are over.
    assert!(navigator.is_navigating());
    assert_eq!(last.mode, nav_mode::NAVIGATING);
    // No earth rate in these samples: the heading stays unknown, and
    // the frames say so rather than quoting the filter's small-angle
    // azimuth sigma.
    assert!(last.attitude_std[2].is_infinite(), "{last:?}");
    // The fine alignment converged in velocity and position; the tilt
    // sigmas stay at the floor the accelerometer bias sets (at rest
    // tilt and bias are inseparable: sigma_tilt >= sigma_b / g,
    // docs/filter-derivation.md section 3b), a little above it as the
    // bias random walk grows.
    let floor = (AugmentedModel::paper().biases.accel[0].initial_sigma
        / f64::from(STANDARD_GRAVITY_M_S2)) as f32;
    for axis in 0..2 {
        let sigma = last.attitude_std[axis];
        assert!(
            sigma >= 0.99 * floor && sigma < 1.5 * first.attitude_std[axis],
            "floor {floor}: {first:?} -> {last:?}"
        );
    }
    for i in 0..3 {
        assert!(
            last.velocity_std[i] < 0.2 * first.velocity_std[i],
            "{last:?}"
        );
        assert!(
            last.position_std_ned[i] < 0.2 * first.position_std_ned[i],
            "{last:?}"
        );
    }

    // Navigating (turning, so not still) without zero updates, the
    // uncertainties grow.
    let mut later = last;
    for n in ALL_ALIGNMENT + 1..ALL_ALIGNMENT + 200 {
        later = navigator.step(&level_turning_sample(n, 3.0));
        assert_eq!(later.mode, nav_mode::NAVIGATING);
        assert_eq!(later.flags & nav_flags::ZUPT_APPLIED, 0);
    }
    assert!(
        later.velocity_std[0] > 2.0 * last.velocity_std[0],
        "{later:?}"
    );
    assert!(
        later.position_std_ned[0] > last.position_std_ned[0],
        "{later:?}"
    );
}

#[test]
fn the_calibration_removes_an_accelerometer_bias_before_alignment() {
    // 10 counts (~0.15 m/s^2) of bias on body x tilt an uncalibrated
    // probe by ~0.9 deg in roll; the calibration takes it out.
    let bias = 10.0 * STANDARD_GRAVITY_M_S2 / 650.0;
    let biased = |n| still_sample(n, [bias, 0.0, STANDARD_GRAVITY_M_S2]);
    let triad = TriadCalibration {
        bias: [f64::from(bias), 0.0, 0.0],
        ..TriadCalibration::IDENTITY
    };
    let calibration = ProbeCalibration {
        accel: [triad; 2],
        ..ProbeCalibration::default()
    };
    let mut plain = Navigator::new(Position::paper_site());
    let mut calibrated = Navigator::with_calibration(Position::paper_site(), calibration);
    let (mut a, mut b) = (NavSolution::default(), NavSolution::default());
    for n in 0..=ALIGNMENT_SAMPLES {
        a = plain.step(&biased(n));
        b = calibrated.step(&biased(n));
    }
    let tilt = (bias / STANDARD_GRAVITY_M_S2).atan();
    assert!((a.attitude[0].abs() - tilt).abs() < 0.05 * tilt, "{a:?}");
    assert!(b.attitude[0].abs() < 0.02 * tilt, "{b:?}");
}

/// A probe turning at 3 deg/s with 1 s of invalid
/// samples ended with a permanent 3 deg heading offset and unchanged
/// sigmas (the gap was not propagated).
#[test]
fn a_sensor_gap_is_propagated_with_the_held_rates_and_flagged() {
    let (mut reference, mut gapped) = (aligned_navigator(), aligned_navigator());
    let start = ALL_ALIGNMENT + 1;
    let gap = start + 100..start + 120;
    let (mut a, mut b) = (NavSolution::default(), NavSolution::default());
    for n in start..start + 200 {
        let raw = level_turning_sample(n, 3.0);
        a = reference.step(&raw);
        let mut raw = raw;
        if gap.contains(&n) {
            raw.parts.iter_mut().for_each(|p| p.flags = 0);
        }
        b = gapped.step(&raw);
        if gap.contains(&n) {
            assert_ne!(b.flags & nav_flags::SENSOR_DEGRADED, 0);
        }
        if n >= gap.start {
            // Navigation has no aid: coasting until the next alignment.
            assert_ne!(b.flags & nav_flags::COASTING, 0, "sample {n}");
        } else {
            assert_eq!(b.flags & nav_flags::COASTING, 0, "sample {n}");
        }
    }
    assert_eq!(a.flags & nav_flags::COASTING, 0);
    // The turn went on through the gap: the headings agree to well
    // under the 3 deg the frozen solution lost.
    let offset = (a.attitude[2] - b.attitude[2]).to_degrees();
    assert!(offset.abs() < 0.1, "heading offset {offset} deg");
    // The held rates' uncertainty was added: the gap's solution is
    // less certain (the heading's sigma in the frames is infinite in
    // both, the coarse alignment having had no earth rate; the
    // filter's own shows the growth).
    let (sa, sb) = (reference.filter().euler_std(), gapped.filter().euler_std());
    // 20 missed steps of a rate held within 1 deg/s: (20 x 0.05 x
    // 1 deg)^2 = (1 deg)^2 more heading variance.
    let added = sb.z * sb.z - sa.z * sa.z;
    assert!(added > 0.8f64.to_radians().powi(2), "{sa:?} vs {sb:?}");
    for axis in 0..2 {
        assert!(
            b.attitude_std[axis] > a.attitude_std[axis],
            "{a:?} vs {b:?}"
        );
    }
    for i in 0..3 {
        assert!(b.velocity_std[i] > a.velocity_std[i], "{a:?} vs {b:?}");
    }
}

/// A gap in the fine alignment: coasting until the next zero update.
#[test]
fn a_gap_in_the_fine_alignment_coasts_until_the_next_zero_update() {
    let mut navigator = Navigator::new(Position::paper_site());
    for n in 0..ALIGNMENT_SAMPLES + 50 {
        navigator.step(&level_sample(n));
    }
    let mut bad = level_sample(ALIGNMENT_SAMPLES + 50);
    bad.parts.iter_mut().for_each(|p| p.flags = 0);
    let s = navigator.step(&bad);
    assert_eq!(s.mode, nav_mode::FINE_ALIGNMENT);
    assert_ne!(s.flags & nav_flags::COASTING, 0, "{s:?}");
    assert_eq!(s.flags & nav_flags::ZUPT_APPLIED, 0, "{s:?}");
    let s = navigator.step(&level_sample(ALIGNMENT_SAMPLES + 51));
    assert_eq!(
        s.flags,
        nav_flags::ZUPT_APPLIED | nav_flags::UNCALIBRATED,
        "{s:?}"
    );
}

/// With part 1 dead from boot the probe stayed in
/// its coarse alignment for ever. Now part 2's triad levels the probe
/// and its gyro carries what it can; the azimuth is not determined.
#[test]
fn with_part_1_dead_from_boot_the_healthy_part_levels_and_navigates() {
    let truth = Euler::new(10.0 * DEG, -5.0 * DEG, 0.0);
    let force = crate::conventions::specific_force_at_rest(&truth, 9.80665).map(|f| f as f32);
    let dead = |n| {
        let mut raw = still_sample(n, [force.x, force.y, force.z]);
        raw.parts[0] = RawPart {
            flags: raw_flags::NO_RESPONSE,
            ..RawPart::default()
        };
        raw
    };
    let mut navigator = Navigator::new(Position::paper_site());
    let mut last = NavSolution::default();
    for n in 0..=ALL_ALIGNMENT + 20 {
        last = navigator.step(&dead(n));
        assert_ne!(last.flags & nav_flags::SINGLE_PART, 0, "{last:?}");
        if n == ALIGNMENT_SAMPLES - 1 || n == ALL_ALIGNMENT {
            assert!(navigator.is_aligned(), "sample {n}");
            for (axis, angle) in [truth.roll, truth.pitch].into_iter().enumerate() {
                let (value, sigma) = (last.attitude[axis], last.attitude_std[axis]);
                let error = f64::from(value) - angle;
                assert!(
                    sigma.is_finite() && error.abs() < 3.0 * f64::from(sigma),
                    "sample {n}, axis {axis}: {last:?}"
                );
            }
            assert_eq!(last.attitude_std[2], f32::INFINITY, "{last:?}");
        }
    }
    assert!(navigator.is_navigating());
    assert_eq!(last.mode, nav_mode::NAVIGATING);
    assert_eq!(last.attitude_std[2], f32::INFINITY);
    assert!(
        last.attitude_std[..2].iter().all(|s| s.is_finite()),
        "{last:?}"
    );
}

/// A probe still through the end of its fine alignment is still from its
/// first navigating cycle on (the still detector ran through the fine
/// alignment): a zero-velocity update and the roll held, where the
/// detector's delay used to make ~2 s of "moving" cycles whose roll
/// followed the accelerometer roll's noise unmodelled.
#[test]
fn a_probe_still_at_the_end_of_its_fine_alignment_navigates_on_as_still() {
    let mut navigator = aligned_navigator();
    let both = nav_flags::STILL | nav_flags::ZUPT_APPLIED;
    for n in ALL_ALIGNMENT + 1..ALL_ALIGNMENT + 1 + DETECTION_DELAY_SAMPLES {
        let s = navigator.step(&level_sample(n));
        assert_eq!(s.flags & both, both, "sample {n}: {s:?}");
    }
}

/// One that moves from its first navigating cycle on: the fine alignment
/// held its roll as at rest, so, as after any still period, its offset
/// from the accelerometer roll and two samples' roll noise go into the
/// roll's variance when it starts to follow the accelerometer roll (the
/// non-holonomic updates of the cycles after take it down again: a roll
/// error tilts gravity into the cross-axis velocity they hold at zero).
#[test]
fn a_probe_moving_from_its_first_navigating_cycle_gets_the_roll_variance() {
    let mut navigator = aligned_navigator();
    let before = navigator.filter().euler_std().x;
    let s = navigator.step(&level_turning_sample(ALL_ALIGNMENT + 1, 3.0));
    assert_eq!(s.flags & nav_flags::STILL, 0, "{s:?}");
    let after = navigator.filter().euler_std().x;
    // sqrt(2) single-sample roll sigmas (0.48 deg) against the
    // levelling's ~0.07 deg
    let expected = SINGLE_SAMPLE_ROLL_SIGMA_RAD * core::f64::consts::SQRT_2;
    assert!(
        after > 0.9 * expected && after > 5.0 * before,
        "roll sigma {before} -> {after} rad"
    );
}

#[test]
fn an_f64_filter_gives_the_probes_f32_solutions_to_their_rounding() {
    // The host's studies run the filter in f64 (faster there); the probe
    // computes in f32. Alignment, a turn (the moving cycles' constraints),
    // a station (zero-velocity updates, the rate gyrocompass), a turn.
    let position = Position::paper_site();
    let mut single = Navigator::new(position);
    let mut double = Navigator::<f64>::calibrated(position, ProbeCalibration::default());
    let turn = ALL_ALIGNMENT + 100;
    let station = turn + 200;
    let sample = |n| match n {
        n if n < ALL_ALIGNMENT || (turn..station).contains(&n) => level_sample(n),
        n => level_turning_sample(n, 2.0),
    };
    let (mut worst_angle, mut worst_sigma) = (0f32, 0f32);
    let mut stations = 0;
    for n in 0..station + 100 {
        let (a, b) = (single.step(&sample(n)), double.step(&sample(n)));
        assert_eq!((a.mode, a.flags), (b.mode, b.flags), "sample {n}");
        for (x, y) in a.attitude.iter().zip(&b.attitude) {
            worst_angle = worst_angle.max((x - y).abs());
        }
        let sigmas = |s: &NavSolution| [s.attitude_std, s.velocity_std, s.position_std_ned];
        for (x, y) in sigmas(&a)
            .as_flattened()
            .iter()
            .zip(sigmas(&b).as_flattened())
        {
            worst_sigma = worst_sigma.max((x / y - 1.0).abs());
        }
        let (x, y) = (single.take_station(), double.take_station());
        assert_eq!(x.is_some(), y.is_some(), "sample {n}");
        if let (Some(x), Some(y)) = (x, y) {
            stations += 1;
            assert_eq!((x.flags, x.end_sample), (y.flags, y.end_sample));
            for (p, q) in x.angles.iter().zip(&y.angles) {
                assert!((p - q).abs() < 1e-5, "{x:?} {y:?}");
            }
        }
    }
    assert_eq!(stations, 1);
    // Measured: 1.8e-7 rad and 1.2e-5.
    assert!(worst_angle < 1e-6, "{worst_angle} rad");
    assert!(worst_sigma < 1e-4, "{worst_sigma}");
}

/// Bit 9 says whether the probe corrects its samples: set on every frame
/// of a probe without a calibration, on none of a calibrated one.
#[test]
fn only_an_uncalibrated_probe_flags_its_frames_uncalibrated() {
    let mut calibration = ProbeCalibration::default();
    calibration.gyro[0].bias = 1e-5;
    let mut calibrated = Navigator::with_calibration(Position::paper_site(), calibration);
    let mut uncalibrated = Navigator::new(Position::paper_site());
    assert!(uncalibrated.is_uncalibrated() && !calibrated.is_uncalibrated());
    for n in 0..ALIGNMENT_SAMPLES + 20 {
        let a = calibrated.step(&level_sample(n));
        let b = uncalibrated.step(&level_sample(n));
        assert_eq!(a.flags & nav_flags::UNCALIBRATED, 0, "sample {n}: {a:?}");
        assert_eq!(b.flags, a.flags | nav_flags::UNCALIBRATED, "sample {n}");
    }
}
