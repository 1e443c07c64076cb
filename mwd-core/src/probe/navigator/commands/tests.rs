//! The survey commands on noise-free samples of a still or turning probe
//! (the navigator tests' generator: no earth rate, so the azimuth is
//! undetermined and only inclination and toolface are checked).

extern crate std;
use super::super::Navigator;
use super::super::SURVEY_SETTLE_EPOCHS;
use super::*;
use crate::conventions::wrap_pi;
use crate::conventions::{specific_force_at_rest, Euler};
use crate::earth::Position;
use crate::protocol::frame::nav_mode;
use crate::protocol::frame::station_flags;
use crate::protocol::{NavSolution, RawSample};
use crate::timing::ALIGNMENT_SAMPLES;
use std::vec::Vec;

use crate::probe::test_support::{aligned_navigator as aligned, ALL_ALIGNMENT};
const G: f64 = 9.80665;

/// A level (horizontal) probe at toolface `roll` (rad), turning about the
/// vertical at `deg_s` (0: still), sample `n`.
fn sample(n: u32, roll: f64, deg_s: f32) -> RawSample {
    let force = specific_force_at_rest(&Euler::new(roll, 0.0, 0.0), G).map(|f| f as f32);
    // At rest the specific force points up: the turn's axis in body axes.
    let rate = force * (deg_s.to_radians() / G as f32);
    crate::probe::test_support::turning_sample(
        n,
        [force.x, force.y, force.z],
        [rate.x, rate.y, rate.z],
    )
}

/// A station's fields as bits (its NaN correlations compare equal).
fn bits(s: &StationSurvey) -> (u16, u16, u32, u32, [u32; 9]) {
    let mut floats = [0u32; 9];
    let all = s.angles.iter().chain(&s.angles_std).chain(&s.correlations);
    floats
        .iter_mut()
        .zip(all)
        .for_each(|(b, f)| *b = f.to_bits());
    (s.station, s.flags, s.start_sample, s.end_sample, floats)
}

fn still(n: u32) -> RawSample {
    sample(n, 0.0, 0.0)
}

#[test]
fn start_surveying_ends_the_fine_alignment_once_it_has_settled() {
    let mut navigator = Navigator::new(Position::paper_site());
    let mut reference = Navigator::new(Position::paper_site());
    assert_eq!(navigator.start_surveying(), Err(Refusal::NotReady));
    let early = ALIGNMENT_SAMPLES + MIN_FINE_ALIGNMENT_SAMPLES;
    for n in 0..early {
        navigator.step(&still(n));
        reference.step(&still(n));
        if n == ALIGNMENT_SAMPLES + 10 {
            // Fine alignment, too short yet.
            assert!(navigator.is_aligned());
            assert_eq!(navigator.start_surveying(), Err(Refusal::NotReady));
        }
    }
    assert_eq!(navigator.start_surveying(), Ok(()));
    assert!(navigator.is_navigating());
    // Acknowledged again without effect (a resend).
    assert_eq!(navigator.start_surveying(), Ok(()));
    let ended = navigator.step(&still(early));
    assert_eq!(ended.mode, nav_mode::NAVIGATING);
    // The tilt sigma it navigates with is within 10 % of a full 60 s
    // alignment's (measured: 4 % below it; the bias random walk grows it
    // over the full alignment).
    let mut full = NavSolution::default();
    for n in early..=ALL_ALIGNMENT {
        full = reference.step(&still(n));
    }
    assert_eq!(full.mode, nav_mode::NAVIGATING);
    for axis in 0..2 {
        let (short, long) = (ended.attitude_std[axis], full.attitude_std[axis]);
        assert!(
            short.is_finite() && short <= 1.1 * long,
            "{ended:?} vs {full:?}"
        );
    }
    // Navigating: still periods are stations from then on.
    let mut stations = 0;
    for n in early + 1..early + 200 {
        navigator.step(&still(n));
        stations += usize::from(navigator.take_station().is_some());
    }
    navigator.step(&sample(early + 200, 0.0, 3.0));
    assert_eq!(stations, 0);
    assert_eq!(navigator.take_station().map(|s| s.station), Some(1));
}

#[test]
fn a_station_is_taken_only_while_still_and_sent_once_per_still_period() {
    let mut navigator = Navigator::new(Position::paper_site());
    navigator.step(&still(0));
    assert_eq!(navigator.take_station_now(), Err(Refusal::NotReady));
    let (mut navigator, mut reference) = (aligned(), aligned());
    let start = ALL_ALIGNMENT + 1;
    let (still_from, still_to) = (start + 100, start + 100 + 1200);
    let mut requested = Vec::new();
    let mut sent = Vec::new();
    for n in start..still_to + 500 {
        let raw = if (still_from..still_to).contains(&n) || n >= still_to + 100 {
            still(n)
        } else {
            sample(n, 0.0, 3.0)
        };
        let a = navigator.step(&raw);
        // The command does not touch the navigation: bit for bit the
        // frames of a probe that was never asked.
        assert_eq!(a, reference.step(&raw), "sample {n}");
        let natural = reference.take_station();
        sent.extend(navigator.take_station().map(|s| (n, s)));
        if n == start + 50 || n == still_from + 20 {
            // Turning, then still for less than the detector's delay.
            assert_eq!(navigator.take_station_now(), Err(Refusal::NotStill));
        }
        if n == still_from + 600 || n == still_from + 700 {
            requested.push(navigator.take_station_now().expect("still"));
        }
        if n == still_to {
            // The natural station, which the request took the place of.
            let natural = natural.expect("the still period ended");
            assert_eq!(natural.station, requested[0].station);
        }
    }
    // Sent at sample 600 of the still period: the survey of the older of
    // its last two checkpoints, flagged; a repeat sends the same frame.
    // (Station 1 is the window's, the still cycle at the alignment's end,
    // sent when the probe first turned.)
    let window = sent.remove(0);
    assert_eq!(
        (window.0, window.1.station, window.1.start_sample),
        (start, 1, ALL_ALIGNMENT)
    );
    let first = requested[0];
    assert_eq!(first.station, 2);
    assert_eq!(
        first.flags & station_flags::REQUESTED,
        station_flags::REQUESTED
    );
    assert_eq!(first.flags & station_flags::INDEXING_DWELL, 0);
    let epochs = 600 - (DETECTION_DELAY_SAMPLES - 1) + 1;
    let settled = (epochs / SURVEY_SETTLE_EPOCHS - 1) * SURVEY_SETTLE_EPOCHS;
    assert_eq!(first.end_sample, first.start_sample + settled - 1);
    assert!(first.angles_std[0].is_finite() && first.angles_std[2].is_finite());
    assert_eq!(bits(&requested[1]), bits(&first));
    // Nothing else for that still period; the next still period (from
    // still_to + 100) is still going on at the end, so no other station.
    assert!(sent.is_empty(), "{sent:?}");
    // The next still period's station is its own.
    let n = still_to + 500;
    let next = navigator.take_station_now().expect("still again");
    assert_eq!(next.station, 3);
    assert!(next.start_sample > still_to && next.end_sample < n);
}

/// The indexing procedure over three positions of a level probe rolled
/// by the orienter, with a pause between them that does not turn the
/// toolface, and a fourth position after the procedure has ended.
#[test]
fn toolface_indexing_reports_each_new_dwell_and_ends_after_the_last() {
    let mut navigator = aligned();
    let procedure = IndexingProcedure {
        positions: 3,
        dwell_s: 4,
    };
    let mut n = ALL_ALIGNMENT + 1;
    let mut frames: Vec<(u32, StationSurvey, f64)> = Vec::new();
    let mut roll = 0.0f64;
    let mut run = |navigator: &mut Navigator, samples: u32, to_roll: f64, turn: f32| {
        let from = roll;
        for k in 0..samples {
            let at = from + (to_roll - from) * f64::from(k + 1) / f64::from(samples);
            navigator.step(&sample(n, at, turn));
            if let Some(s) = navigator.take_station() {
                frames.push((n, s, at));
            }
            n += 1;
        }
        roll = to_roll;
    };
    // moving: the window's station (the still cycle at the alignment's
    // end) goes out
    run(&mut navigator, 20, 0.0, 3.0);
    assert_eq!(navigator.index_toolface(procedure), Ok(()));
    let dwell = 4 * 20;
    // Position 1 (the toolface it is at), then a roll of 45 deg at 10 deg/s.
    run(&mut navigator, 2 * dwell, 0.0, 0.0);
    run(&mut navigator, 90, 45.0 * DEG, 0.0);
    // Position 2; a resend of the command changes nothing.
    run(&mut navigator, dwell / 2, 45.0 * DEG, 0.0);
    assert_eq!(navigator.index_toolface(procedure), Ok(()));
    assert_eq!(navigator.indexing().map(|i| i.reported), Some(1));
    run(&mut navigator, 2 * dwell, 45.0 * DEG, 0.0);
    // A turn about the vertical only, and a pause at the same toolface.
    run(&mut navigator, 40, 45.0 * DEG, 3.0);
    run(&mut navigator, 2 * dwell, 45.0 * DEG, 0.0);
    // Position 3, the last.
    run(&mut navigator, 90, 90.0 * DEG, 0.0);
    run(&mut navigator, 2 * dwell, 90.0 * DEG, 0.0);
    assert!(navigator.indexing().is_none(), "ended");
    // A fourth position: an ordinary station at its end.
    run(&mut navigator, 90, 135.0 * DEG, 0.0);
    run(&mut navigator, 2 * dwell, 135.0 * DEG, 0.0);
    run(&mut navigator, 10, 135.0 * DEG, 3.0);

    let dwells: Vec<_> = frames
        .iter()
        .filter(|(_, s, _)| s.flags & station_flags::INDEXING_DWELL != 0)
        .collect();
    assert_eq!(dwells.len(), 3, "{frames:?}");
    for (k, (at, s, roll)) in dwells.iter().enumerate() {
        // Sent when the probe had been still for the dwell time: the
        // station's first update came after the detector's delay.
        let still_from = s.start_sample - (DETECTION_DELAY_SAMPLES - 1);
        assert_eq!(*at, still_from + dwell - 1, "dwell {k}: {s:?}");
        let error = wrap_pi(f64::from(s.angles[2]) - roll);
        let sigma = f64::from(s.angles_std[2]);
        assert!(error.abs() < 3.0 * sigma, "dwell {k}: {error} vs {sigma}");
        assert!((k as f64 * 45.0 * DEG - roll).abs() < 1e-9);
    }
    // Every still period sent one frame: the window's, the three dwells,
    // the pause and the fourth position as ordinary stations when they
    // ended.
    let numbers: Vec<u16> = frames.iter().map(|(_, s, _)| s.station).collect();
    assert_eq!(numbers, [1, 2, 3, 4, 5, 6], "{frames:?}");
    assert_eq!(frames[0].1.start_sample, ALL_ALIGNMENT);
    for k in [0, 3, 5] {
        assert_eq!(frames[k].1.flags & station_flags::INDEXING_DWELL, 0);
    }
}

#[test]
fn indexing_needs_navigation_and_a_new_procedure_restarts_the_count() {
    let mut navigator = Navigator::new(Position::paper_site());
    let procedure = IndexingProcedure {
        positions: 2,
        dwell_s: 3,
    };
    assert_eq!(navigator.index_toolface(procedure), Err(Refusal::NotReady));
    let mut navigator = aligned();
    assert_eq!(navigator.index_toolface(procedure), Ok(()));
    let mut n = ALL_ALIGNMENT + 1;
    let mut dwells = 0;
    for _ in 0..100 {
        navigator.step(&still(n));
        dwells += usize::from(navigator.take_station().is_some());
        n += 1;
    }
    assert_eq!(
        (dwells, navigator.indexing().map(|i| i.reported)),
        (1, Some(1))
    );
    let longer = IndexingProcedure {
        positions: 4,
        ..procedure
    };
    assert_eq!(navigator.index_toolface(longer), Ok(()));
    let now = navigator.indexing().copied();
    assert_eq!(now.map(|i| (i.procedure, i.reported)), Some((longer, 0)));
    // This still period was sent already: not a dwell of the new one.
    for _ in 0..100 {
        navigator.step(&still(n));
        assert!(navigator.take_station().is_none());
        n += 1;
    }
}

/// One frame per still period also when a request comes before the dwell
/// time of a running procedure, and a dwell not taken at once is kept.
#[test]
fn a_request_before_the_dwell_time_is_the_still_periods_only_frame() {
    let mut navigator = aligned();
    let procedure = IndexingProcedure {
        positions: 2,
        dwell_s: 10,
    };
    assert_eq!(navigator.index_toolface(procedure), Ok(()));
    let mut n = ALL_ALIGNMENT + 1;
    for _ in 0..100 {
        navigator.step(&still(n));
        n += 1;
    }
    let requested = navigator.take_station_now().expect("still for 5 s");
    for _ in 0..300 {
        navigator.step(&still(n));
        assert!(navigator.take_station().is_none(), "sample {n}");
        n += 1;
    }
    assert_eq!(navigator.indexing().map(|i| i.reported), Some(0));
    // The next still period, after a turn about the vertical: its dwell,
    // kept until taken even across further steps.
    for _ in 0..20 {
        navigator.step(&sample(n, 0.0, 3.0));
        n += 1;
    }
    assert_eq!(
        navigator.take_station().map(|s| s.station),
        None,
        "the requested station's natural end is not sent"
    );
    for _ in 0..400 {
        navigator.step(&still(n));
        n += 1;
    }
    let dwell = navigator.take_station().expect("the dwell, kept");
    assert_eq!(dwell.station, requested.station + 1);
    assert_ne!(dwell.flags & station_flags::INDEXING_DWELL, 0);
}
