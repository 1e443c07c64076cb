//! The uplink's still settings (`StillSettings`, command 0x44) change the
//! navigator's behaviour, and their defaults change nothing (noise-free
//! samples of a still, level probe: the navigator tests' generator).

extern crate std;
use super::state::station_zupt_variance;
use super::*;
use crate::calibration::ProbeCalibration;
use crate::config::default_still_settings;
use crate::earth::Position;
use crate::probe::still::{Hysteresis, DETECTION_DELAY_SAMPLES};
use crate::probe::test_support::{level_sample, level_turning_sample, ALL_ALIGNMENT};
use crate::protocol::frame::nav_flags;
use crate::protocol::frame::station_flags;
use crate::protocol::uplink::StillSettings;
use crate::protocol::{NavSolution, StationSurvey};
use std::format;
use std::vec::Vec;

/// Samples the probe turns for right after the alignment, so that its
/// still period after them is detected afresh (the detector runs through
/// the fine alignment: a probe still throughout is still from its first
/// navigating cycle on).
const TURN: u32 = 20;

/// The sample at which the detector first says still after the turn,
/// with the default settings.
const FIRST_STILL: u32 = ALL_ALIGNMENT + TURN + DETECTION_DELAY_SAMPLES;

fn navigator(settings: &StillSettings) -> Navigator {
    Navigator::with_settings(
        Position::paper_site(),
        ProbeCalibration::default(),
        settings,
    )
}

/// Each navigation sample's solution and the stations taken, from the
/// alignment's end through sample `end`, the probe still but for the
/// [`TURN`] samples after the alignment (station 1, the window's still
/// cycle at the alignment's end, is sent when it turns).
fn run(settings: &StillSettings, end: u32) -> (Vec<NavSolution>, Vec<(u32, StationSurvey)>) {
    let mut navigator = navigator(settings);
    let (mut solutions, mut stations) = (Vec::new(), Vec::new());
    for n in 0..end {
        let raw = if (ALL_ALIGNMENT + 1..=ALL_ALIGNMENT + TURN).contains(&n) {
            level_turning_sample(n, 3.0)
        } else {
            level_sample(n)
        };
        let s = navigator.step(&raw);
        if n > ALL_ALIGNMENT {
            solutions.push(s);
        }
        stations.extend(navigator.take_station().map(|st| (n, st)));
    }
    (solutions, stations)
}

fn first_still(solutions: &[NavSolution]) -> Option<u32> {
    solutions
        .iter()
        .position(|s| s.flags & nav_flags::STILL != 0)
        .map(|k| ALL_ALIGNMENT + 1 + k as u32)
}

#[test]
fn the_default_settings_are_the_constants_to_the_bit() {
    let defaults = default_still_settings();
    assert_eq!(Hysteresis::from_settings(&defaults), Hysteresis::DEFAULT);
    assert_eq!(
        station_zupt_variance(defaults.zupt_velocity_sigma).to_bits(),
        STATION_ZUPT_VARIANCE.to_bits()
    );
    // Through a station and a move: the same frames as `Navigator::new`
    // (compared as text: NaN placeholders compare unequal as numbers).
    let mut plain = Navigator::new(Position::paper_site());
    let mut set = navigator(&defaults);
    for n in 0..ALL_ALIGNMENT + 400 {
        let raw = if (ALL_ALIGNMENT + 200..ALL_ALIGNMENT + 220).contains(&n) {
            level_turning_sample(n, 3.0)
        } else {
            level_sample(n)
        };
        let (a, b) = (plain.step(&raw), set.step(&raw));
        assert_eq!(format!("{a:?}"), format!("{b:?}"), "sample {n}");
    }
}

#[test]
fn more_enter_epochs_delay_the_first_still_sample_by_as_many() {
    let end = ALL_ALIGNMENT + 200;
    let (defaults, _) = run(&default_still_settings(), end);
    assert_eq!(first_still(&defaults), Some(FIRST_STILL));
    let slower = StillSettings {
        enter_epochs: 60,
        ..default_still_settings()
    };
    let (delayed, _) = run(&slower, end);
    assert_eq!(first_still(&delayed), Some(FIRST_STILL + 40));
}

#[test]
fn max_station_samples_caps_a_station() {
    let capped = StillSettings {
        max_station_samples: 200,
        ..default_still_settings()
    };
    let end = FIRST_STILL + 400;
    let (solutions, stations) = run(&capped, end);
    assert_eq!(stations.len(), 2, "{stations:?}");
    assert_eq!(stations[0].1.start_sample, ALL_ALIGNMENT);
    let (at, station) = stations[1];
    assert_eq!(at, FIRST_STILL + 200 - 1);
    assert_ne!(station.flags & station_flags::MAX_DURATION, 0);
    // Past the cap: still, but no more zero-velocity updates.
    let last = solutions.last().expect("navigation frames");
    assert_eq!(
        last.flags & (nav_flags::STILL | nav_flags::ZUPT_APPLIED),
        nav_flags::STILL
    );
    // The default cap (6000) has not been reached: only the window's.
    let (_, uncapped) = run(&default_still_settings(), end);
    assert_eq!(uncapped.len(), 1, "{uncapped:?}");
}

#[test]
fn a_looser_zupt_sigma_leaves_a_larger_velocity_sigma() {
    let end = FIRST_STILL + 100;
    let loose = StillSettings {
        zupt_velocity_sigma: 0.5,
        ..default_still_settings()
    };
    let (tight, _) = run(&default_still_settings(), end);
    let (loose, _) = run(&loose, end);
    let (t, l) = (tight.last().unwrap(), loose.last().unwrap());
    assert_ne!(l.flags & nav_flags::ZUPT_APPLIED, 0);
    for axis in 0..3 {
        assert!(
            l.velocity_std[axis] > 2.0 * t.velocity_std[axis],
            "{axis}: {l:?} vs {t:?}"
        );
    }
}
