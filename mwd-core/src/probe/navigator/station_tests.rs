//! Station surveys in navigation: a stop's zero-velocity updates and its
//! one station, the longest station, and the links between stations.

/// Navigating, a probe that turns, stops for a minute and turns again:
/// zero-velocity updates from the still detector's delay on, and one
/// station survey when it moves, with the attitude of the last still
/// cycle and the filter's uncertainty.
use super::*;
use crate::protocol::frame::{nav_flags, station_flags};
use crate::protocol::NavSolution;
extern crate std;
use super::super::still::DETECTION_DELAY_SAMPLES;

use super::super::test_support::{
    aligned_navigator, level_sample, level_turning_sample, ALL_ALIGNMENT,
};

#[test]
fn a_stop_in_navigation_gives_zero_updates_and_one_station() {
    let mut navigator = aligned_navigator();
    let start = ALL_ALIGNMENT + 1;
    let still_from = start + 100;
    let still_to = still_from + 1200; // 60 s
    let mut moving_end = NavSolution::default();
    let mut last_still = NavSolution::default();
    let mut frames = std::vec::Vec::new();
    let mut stations = std::vec::Vec::new();
    for n in start..still_to + 50 {
        let still = (still_from..still_to).contains(&n);
        let raw = if still {
            level_sample(n)
        } else {
            level_turning_sample(n, 3.0)
        };
        let s = navigator.step(&raw);
        frames.push(s);
        stations.extend(navigator.take_station().map(|st| (n, st)));
        let expect_zupt = still && n >= still_from + DETECTION_DELAY_SAMPLES - 1;
        assert_eq!(
            s.flags & (nav_flags::ZUPT_APPLIED | nav_flags::STILL) != 0,
            expect_zupt,
            "sample {n}: {s:?}"
        );
        if n == still_from - 1 {
            moving_end = s;
        }
        if n == still_to - 1 {
            last_still = s;
        }
    }
    // The velocity uncertainty grown while turning was taken back
    // (below the updates' own 1 cm/s), and the filter re-levelled: the
    // tilt sigmas fell.
    for i in 0..3 {
        let (before, after) = (moving_end.velocity_std[i], last_still.velocity_std[i]);
        assert!(
            after < 0.01 && after < before,
            "{moving_end:?} -> {last_still:?}"
        );
    }
    // (The non-holonomic updates while it turned had already levelled
    // it part of the way.)
    for i in 0..2 {
        assert!(
            last_still.attitude_std[i] < moving_end.attitude_std[i],
            "{moving_end:?} -> {last_still:?}"
        );
    }
    // Station 1 is the window's: the still cycle at the alignment's end
    // (the detector ran through the fine alignment), sent when the probe
    // first turned.
    assert_eq!(stations.len(), 2, "{stations:?}");
    let (window_at, window) = stations[0];
    assert_eq!(
        (window_at, window.station, window.start_sample),
        (start, 1, ALL_ALIGNMENT)
    );
    let (sent_at, st) = stations[1];
    assert_eq!(sent_at, still_to, "sent with the first moving sample");
    assert_eq!(st.station, 2);
    let first_zupt = still_from + DETECTION_DELAY_SAMPLES - 1;
    assert_eq!(st.start_sample, first_zupt);
    // The older of the last two checkpoints (`SURVEY_SETTLE_EPOCHS`).
    let epochs = still_to - first_zupt;
    let settled = (epochs / SURVEY_SETTLE_EPOCHS - 1) * SURVEY_SETTLE_EPOCHS;
    assert_eq!(st.end_sample, first_zupt + settled - 1);
    assert_eq!(st.time_us, u64::from(st.end_sample) * 50_000);
    let last_still = frames[(st.end_sample - start) as usize];
    // The level probe: inclination 90 deg; toolface = roll.
    let [roll, pitch, heading] = last_still.attitude.map(f64::from);
    let [inc, azi, tf] = st.angles.map(f64::from);
    assert!(
        (inc - (core::f64::consts::FRAC_PI_2 + pitch)).abs() < 1e-6,
        "{st:?}"
    );
    assert!(
        (crate::conventions::wrap_pi(tf - roll)).abs() < 1e-6,
        "{st:?}"
    );
    assert!(
        (crate::conventions::wrap_pi(azi - heading)).abs() < 1e-6,
        "{st:?}"
    );
    // No earth rate in these samples: no heading was gyrocompassed, so
    // the azimuth is undetermined, as in the navigation frames.
    assert_eq!(
        st.flags,
        station_flags::MAGNETIC_FREE
            | station_flags::AZIMUTH_UNDETERMINED
            | station_flags::UNCALIBRATED
    );
    assert_eq!(st.angles_std[1], f32::INFINITY);
    assert!(st.correlations[0].is_nan() && st.correlations[2].is_nan());
    assert!(st.correlations[1].abs() <= 1.0, "{st:?}");
    // Inclination and toolface sigmas: pitch and roll's of the frame.
    assert!((st.angles_std[0] - last_still.attitude_std[1]).abs() < 1e-3 * st.angles_std[0]);
    assert!((st.angles_std[2] - last_still.attitude_std[0]).abs() < 1e-3 * st.angles_std[2]);
    // Noise-free still samples: the quality is the detector's floor.
    assert!(st.still_quality >= 0.0 && st.still_quality < 0.1, "{st:?}");
}

/// A stop longer than the longest station: the station is sent then,
/// the updates stop, and the next station comes after the next move.
#[test]
fn a_long_stop_is_sent_at_the_longest_station_and_once() {
    let mut navigator = aligned_navigator();
    let start = ALL_ALIGNMENT + 1;
    let mut stations = std::vec::Vec::new();
    let still_end = start + MAX_STATION_SAMPLES + 300;
    for n in start..still_end + 200 {
        let moving = (still_end..still_end + 20).contains(&n);
        let raw = if moving {
            level_turning_sample(n, 3.0)
        } else {
            level_sample(n)
        };
        let s = navigator.step(&raw);
        if n == still_end - 1 {
            // Past the longest station: still, but no more updates.
            assert_eq!(
                s.flags & (nav_flags::ZUPT_APPLIED | nav_flags::STILL),
                nav_flags::STILL,
                "{s:?}"
            );
        }
        stations.extend(navigator.take_station().map(|st| (n, st)));
    }
    // One station for the long stop, sent when it reached the longest
    // station while the probe was still still; nothing when it moved.
    assert_eq!(stations.len(), 1, "{stations:?}");
    let (at, first) = stations[0];
    // Still from the first navigated sample on: the detector ran through
    // the fine alignment.
    let first_zupt = ALL_ALIGNMENT;
    assert_eq!(at, first_zupt + MAX_STATION_SAMPLES - 1);
    assert_eq!(
        (first.station, first.start_sample, first.end_sample),
        (1, first_zupt, at - SURVEY_SETTLE_EPOCHS)
    );
    assert_ne!(first.flags & station_flags::MAX_DURATION, 0);
    // The stop after the move started station 2, not ended yet.
    assert_eq!(navigator.stations(), 2);
    let mut raw = level_sample(still_end + 200);
    raw.parts[1].flags = 0;
    navigator.step(&raw);
    let second = navigator
        .take_station()
        .expect("a single part ends the station");
    assert_eq!(second.station, 2);
    assert_eq!(second.flags & station_flags::MAX_DURATION, 0);
}

/// Each station's link (`station_link`) ties it to the station before:
/// none for a station too short for two checkpoints (the window's here,
/// one cycle) and none to it; each later one to the one before, with a
/// covariance that is one (symmetric, its diagonal > 0) and a
/// cross-covariance within it (|rho| <= 1).
#[test]
#[allow(clippy::needless_range_loop)] // (r, s) as in the matrices
fn consecutive_stations_are_linked() {
    let mut navigator = aligned_navigator();
    navigator.track_station_links(true);
    let start = ALL_ALIGNMENT + 1;
    let stops = [(start + 100, start + 1300), (start + 1500, start + 2700)];
    let mut got = std::vec::Vec::new();
    for n in start..start + 2800 {
        let still = stops.iter().any(|(a, b)| (*a..*b).contains(&n));
        let raw = if still {
            level_sample(n)
        } else {
            level_turning_sample(n, 3.0)
        };
        navigator.step(&raw);
        if let Some(st) = navigator.take_station() {
            got.push((st, navigator.station_link().copied()));
        }
    }
    assert_eq!(got.len(), 3, "{got:?}");
    assert_eq!(got[0].1, None, "the window's one-cycle station");
    for (k, (st, link)) in got.iter().enumerate().skip(1) {
        let link = link.expect("a station of 60 s has its link");
        assert_eq!(link.station, st.station);
        let c = link.covariance;
        for r in 0..3 {
            assert!(c[r][r] > 0.0 && c[r][r].is_finite(), "{link:?}");
            for s in 0..3 {
                assert!((c[r][s] - c[s][r]).abs() <= 1e-9 * (c[r][r] * c[s][s]).sqrt());
            }
        }
        if k == 1 {
            assert_eq!((link.previous, link.cross_previous), (0, None));
            continue;
        }
        let before = got[k - 1].1.expect("linked");
        assert_eq!(link.previous, got[k - 1].0.station);
        let x = link.cross_previous.expect("a cross-covariance");
        for r in 0..3 {
            for s in 0..3 {
                let bound = (c[r][r] * before.covariance[s][s]).sqrt();
                assert!(x[r][s].abs() <= bound * (1.0 + 1e-6), "{r} {s}: {link:?}");
            }
        }
        // The gyro biases are constants to the filter, which learns little
        // of them in one station: their errors at two stations are
        // strongly correlated.
        let rho = x[1][1] / (c[1][1] * before.covariance[1][1]).sqrt();
        assert!(rho > 0.5, "rho {rho}");
    }
}

/// Off by default (the probe sends no links yet): no link, no snapshot.
#[test]
fn station_links_are_off_by_default() {
    let mut navigator = aligned_navigator();
    let start = ALL_ALIGNMENT + 1;
    let mut stations = 0;
    for n in start..start + 1400 {
        let raw = if (start + 100..start + 1300).contains(&n) {
            level_sample(n)
        } else {
            level_turning_sample(n, 3.0)
        };
        navigator.step(&raw);
        if navigator.take_station().is_some() {
            stations += 1;
            assert_eq!(navigator.station_link(), None);
        }
        assert!((0..3).all(|slot| !navigator.filter().snapshots().is_set(slot)));
    }
    assert_eq!(stations, 2);
}
