//! A tool the still detector takes for still while it moves: a slide too
//! smooth for it (no acceleration, turning at build and walk rates), and a
//! stop longer than the longest station. The rate gyrocompass's gate ends
//! the station when quiet gyros see the turn; past a station's end the
//! moving tool's constraints hold the velocity.

use super::*;
use crate::calibration::ProbeCalibration;
use crate::earth::Position;
use crate::probe_sample::ProbeSample;
use crate::protocol::frame::nav_flags;
use crate::protocol::frame::station_flags;
use crate::protocol::{NavSolution, StationSurvey};
use crate::sensor_noise::ImuNoise;
use nalgebra::Vector3;
extern crate std;
use crate::conventions::Euler;

use super::super::test_support::{earth_rate_sample, level_sample, quieter_gyros, ALL_ALIGNMENT};

/// A GE-2020-like gyro budget (the SCC1300's gyro noise and biases 300
/// times smaller): its block means see a turn of a few deg/h.
static QUIET: ImuNoise = quieter_gyros(300.0);

/// Sample `n` of a level tool heading 60 deg at the paper's site, error
/// free, turning about the vertical at `turn_deg_h` on top of the
/// earth's rate.
fn sample(n: u32, turn_deg_h: f64) -> (u64, u32, ProbeSample) {
    let turn = Vector3::new(0.0, 0.0, turn_deg_h.to_radians() / 3600.0);
    earth_rate_sample(n, &Euler::new(0.0, 0.0, 60f64.to_radians()), turn)
}

/// Runs a quiet navigator still through its alignment and `still` more
/// samples, then `turning` samples turning at `turn_deg_h`; returns the
/// stations sent (with the sample that sent each) and the last solution.
fn slide(
    still: u32,
    turning: u32,
    turn_deg_h: f64,
) -> (std::vec::Vec<(u32, StationSurvey)>, NavSolution) {
    let mut navigator =
        Navigator::<f64>::calibrated(Position::paper_site(), ProbeCalibration::default());
    navigator.set_noise_budget(&QUIET);
    let mut stations = std::vec::Vec::new();
    let mut last = None;
    let end = ALL_ALIGNMENT + still + turning;
    for n in 0..end {
        let turn = if n >= ALL_ALIGNMENT + still {
            turn_deg_h
        } else {
            0.0
        };
        let (time, counter, s) = sample(n, turn);
        last = Some(navigator.step_sample(time, counter, &s));
        stations.extend(navigator.take_station().map(|st| (n, st)));
    }
    (stations, last.expect("samples were stepped"))
}

#[test]
fn a_still_quiet_probe_passes_its_rate_gyrocompass_blocks() {
    // 4 minutes: the station goes on, with updates, and nothing is sent.
    let (stations, last) = slide(4800, 0, 0.0);
    assert!(stations.is_empty(), "{stations:?}");
    assert_eq!(
        last.flags & (nav_flags::STILL | nav_flags::ZUPT_APPLIED),
        nav_flags::STILL | nav_flags::ZUPT_APPLIED,
        "{last:?}"
    );
}

#[test]
fn a_smooth_turn_the_still_detector_misses_ends_the_station() {
    // One minute still, then a 10 deg/h walk (a slide through a turn at
    // 5 deg/30 m and 60 m/h), which the still detector cannot see.
    let still = 1200;
    let (stations, last) = slide(still, 1200, 10.0);
    assert_eq!(stations.len(), 1, "{stations:?}");
    let (at, station) = stations[0];
    assert_ne!(station.flags & station_flags::MOTION_SEEN, 0, "{station:?}");
    assert_eq!(station.flags & station_flags::MAX_DURATION, 0);
    // Ended at the end of the first block that holds the turn; its survey
    // is a checkpoint before that block.
    let turn_from = ALL_ALIGNMENT + still;
    assert!(
        at >= turn_from && at < turn_from + SURVEY_SETTLE_EPOCHS,
        "{at}"
    );
    assert!(station.end_sample < turn_from, "{station:?}");
    // Still to the detector, but no zero-velocity updates any more.
    assert_eq!(
        last.flags & (nav_flags::STILL | nav_flags::ZUPT_APPLIED),
        nav_flags::STILL,
        "{last:?}"
    );
}

/// Past the longest station the probe may be at rest or sliding smoothly:
/// the moving tool's constraints keep its velocity known; free inertial
/// navigation there (as before) let the velocity sigma grow without bound.
#[test]
fn past_the_longest_station_the_velocity_stays_constrained() {
    let mut navigator = Navigator::new(Position::paper_site());
    let end = ALL_ALIGNMENT + MAX_STATION_SAMPLES + 12_000;
    let mut last = None;
    for n in 0..end {
        last = Some(navigator.step(&level_sample(n)));
    }
    let last = last.expect("samples were stepped");
    assert_eq!(last.flags & nav_flags::ZUPT_APPLIED, 0, "{last:?}");
    assert_eq!(last.flags & nav_flags::COVARIANCE_INVALID, 0, "{last:?}");
    // 10 minutes past the station's end.
    let speed_sigma = last.velocity_std.iter().map(|s| s * s).sum::<f32>().sqrt();
    assert!(speed_sigma < 0.1, "{last:?}");
    let speed = last.velocity_ned.iter().map(|v| v * v).sum::<f32>().sqrt();
    assert!(speed < 3.0 * speed_sigma, "{last:?}");
}

/// An orienter's turn at rest that stops into a still period (a
/// toolface-indexed connection): no gyro senses the roll, whose rate
/// follows the accelerometer roll a sample late and overshoots where the
/// turn stops. The first still cycle takes the accelerometer roll's offset
/// into the roll's variance, and the station re-levels it: the roll and
/// the heading stay inside their sigmas. (Without it the roll was 0.25 deg
/// off under a 0.02 deg sigma, and the station read it as heading.)
#[test]
fn a_turn_at_rest_that_stops_leaves_the_roll_inside_its_sigma() {
    let mut navigator =
        Navigator::<f64>::calibrated(Position::paper_site(), ProbeCalibration::default());
    navigator.set_noise_budget(&QUIET);
    let heading = 60f64.to_radians();
    let rate = 10f64.to_radians(); // the orienter's 10 deg/s
    let still = ALL_ALIGNMENT + 1200;
    let turn = 360; // 18 s: 180 deg
    let roll_at = |n: u32| f64::from(n.saturating_sub(still).min(turn)) * 0.05 * rate;
    let mut worst: f64 = 0.0;
    let mut last = None;
    for n in 0..still + turn + 1200 {
        let attitude = Euler::new(roll_at(n), 0.0, heading);
        let (time, counter, s) = earth_rate_sample(n, &attitude, Vector3::zeros());
        let solution = navigator.step_sample(time, counter, &s);
        navigator.take_station();
        if n > still + turn && solution.flags & nav_flags::STILL != 0 {
            let error = crate::conventions::wrap_pi(f64::from(solution.attitude[0]) - roll_at(n));
            worst = worst.max(error.abs() / f64::from(solution.attitude_std[0]));
        }
        last = Some(solution);
    }
    assert!(worst < 3.0, "the roll {worst} sigma off");
    let last = last.expect("samples were stepped");
    let heading_error = crate::conventions::wrap_pi(f64::from(last.attitude[2]) - heading);
    assert!(
        heading_error.abs() < 3.0 * f64::from(last.attitude_std[2]),
        "{heading_error} rad against {last:?}"
    );
}
