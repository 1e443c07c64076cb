//! Frames lost between the probe and the capture: nothing lost without
//! being said, nothing moved. A lost station frame loses that station
//! alone (the listing names it, the others keep their MD and angles; their
//! positions follow the longer course across the gap), a lost
//! tie-on station is refused rather than the tie-on put on a later
//! station; `replay` and `survey` count what they could not use and exit
//! 2 (written but incomplete), with or without a tie-in job.
mod common;

use common::{capture_frames, run, s, scratch, simulate_tied_in, simulate_tied_in_on};
use mwd_core::protocol::Payload;
use std::path::{Path, PathBuf};

/// `capture` without the frames `lose` picks, written to `name` beside
/// it; how many were taken out.
fn losing(capture: &Path, name: &str, lose: impl Fn(&Payload) -> bool) -> (PathBuf, usize) {
    let bytes = std::fs::read(capture).unwrap();
    let mut kept = Vec::new();
    let mut lost = 0;
    for (chunk, frame) in capture_frames(&bytes) {
        if frame.as_ref().is_some_and(|f| lose(&f.payload)) {
            lost += 1;
        } else {
            kept.extend(chunk);
        }
    }
    let out = capture.with_file_name(name);
    std::fs::write(&out, kept).unwrap();
    (out, lost)
}

fn station_number(p: &Payload) -> Option<u16> {
    match p {
        Payload::Station(st) => Some(st.station),
        _ => None,
    }
}

/// The listing's station lines by station number (the first column).
fn station_lines(listing: &str) -> Vec<(u16, String)> {
    listing
        .lines()
        .filter_map(|l| {
            let mut words = l.split_whitespace();
            let number = words.next()?.parse().ok()?;
            words.next()?.parse::<f64>().ok()?;
            Some((number, l.to_string()))
        })
        .collect()
}

fn survey(capture: &Path, depth: &Path, job: &Path) -> common::Run {
    run(&["survey", s(capture), "--depth", s(depth), "--job", s(job)])
}

#[test]
fn a_lost_station_frame_loses_that_station_only_and_a_lost_tie_on_station_is_refused() {
    let dir = scratch("losses", "stations");
    // four stations, 28 m apart
    let (bin, depth, job) = simulate_tied_in_on(&dir, "lateral-100m.json");
    let whole = survey(&bin, &depth, &job);
    assert_eq!(whole.code, Some(0), "{}", whole.stderr);
    assert!(!whole.stdout.contains("lost"), "{}", whole.stdout);
    let all = station_lines(&whole.stdout);
    assert!(all.len() >= 3, "{}", whole.stdout);
    assert_eq!(all[0].0, 1, "{}", whole.stdout);

    // station 2 lost: its line says so, every other station is where it was
    let (two_lost, n) = losing(&bin, "two-lost.bin", |p| station_number(p) == Some(2));
    assert_eq!(n, 1);
    let out = survey(&two_lost, &depth, &job);
    assert_eq!(out.code, Some(2), "{}{}", out.stdout, out.stderr);
    assert!(
        out.stdout.contains("station 2 lost (frame not received)"),
        "{}",
        out.stdout
    );
    assert!(
        out.stderr
            .contains("1 frames lost in the capture, 1 stations among them (station 2)"),
        "{}",
        out.stderr
    );
    let kept = station_lines(&out.stdout);
    let expected: Vec<_> = all.iter().filter(|(n, _)| *n != 2).collect();
    assert_eq!(kept.len(), expected.len(), "{}", out.stdout);
    let words = |l: &str| l.split_whitespace().map(String::from).collect::<Vec<_>>();
    for ((n, line), (m, before)) in kept.iter().zip(&expected) {
        assert_eq!(n, m);
        let (now, then) = (words(line), words(before));
        if *n == 1 {
            assert_eq!(line, before);
            continue;
        }
        // MD (by time, from the log) and the angles as before; N/E by
        // minimum curvature across the longer course, within the 95 %
        // ellipse's major semi-axis of the whole capture's position
        assert_eq!(now[..5], then[..5], "station {n}");
        let number = |w: &[String], k: usize| w[k].parse::<f64>().unwrap();
        let major = number(&then, 11);
        for k in [5, 6, 7] {
            let moved = (number(&now, k) - number(&then, k)).abs();
            assert!(moved < major, "station {n} column {k}: {line} vs {before}");
        }
    }
    let gap = out.stdout.find("station 2 lost").unwrap();
    let three = out.stdout.find(&kept[1].1).unwrap();
    assert!(
        gap < three,
        "the gap is listed where station 2 was: {}",
        out.stdout
    );

    // station 1 lost: the tie-on's station is not known, refused
    let (one_lost, _) = losing(&bin, "one-lost.bin", |p| station_number(p) == Some(1));
    let out = survey(&one_lost, &depth, &job);
    assert_eq!(out.code, Some(1), "{}{}", out.stdout, out.stderr);
    assert!(
        out.stderr.contains("station 1 lost (frame not received)"),
        "{}",
        out.stderr
    );
    assert!(!out.stdout.contains("3000.00"), "{}", out.stdout);
    // with --tie-on-md alone too
    let out = run(&[
        "survey",
        s(&one_lost),
        "--depth",
        s(&depth),
        "--tie-on-md",
        "3000",
    ]);
    assert_eq!(out.code, Some(1), "{}{}", out.stdout, out.stderr);
    // without a tie-on the stations keep the log's MD; the gap is listed
    let out = run(&["survey", s(&one_lost), "--depth", s(&depth)]);
    assert_eq!(out.code, Some(2), "{}{}", out.stdout, out.stderr);
    assert!(
        out.stdout.contains("station 1 lost (frame not received)"),
        "{}",
        out.stdout
    );
}

#[test]
fn replay_counts_lost_frames_as_not_compared_and_exits_2_with_or_without_a_job() {
    let dir = scratch("losses", "replay");
    let (bin, _depth, job) = simulate_tied_in(&dir);
    let whole = run(&["replay", s(&bin), "--job", s(&job)]);
    assert_eq!(whole.code, Some(0), "{}{}", whole.stdout, whole.stderr);
    // the 100th navigation frame and the first station frame lost
    let nav = std::cell::Cell::new(0);
    let (lossy, n) = losing(&bin, "lossy.bin", |p| match p {
        Payload::Nav(_) => {
            nav.set(nav.get() + 1);
            nav.get() == 100
        }
        Payload::Station(st) => st.station == 1,
        _ => false,
    });
    assert_eq!(n, 2);
    for with_job in [true, false] {
        let mut args = vec!["replay", s(&lossy)];
        if with_job {
            args.extend(["--job", s(&job)]);
        }
        let out = run(&args);
        let expected = if with_job { Some(2) } else { Some(3) };
        // without its job the replay has no tie-in and differs (3): a
        // difference outranks an incomplete comparison
        assert_eq!(out.code, expected, "{}{}", out.stdout, out.stderr);
        assert!(
            out.stdout
                .contains("(2 of them frames lost in the capture)"),
            "{}",
            out.stdout
        );
        if with_job {
            assert!(
                out.stderr
                    .contains("warning: 2 frames lost in the capture could not be compared"),
                "{}",
                out.stderr
            );
        }
    }
}

#[test]
fn a_bad_command_line_is_an_error_not_an_incomplete_output() {
    let out = run(&["survey", "--no-such-option"]);
    assert_eq!(out.code, Some(1), "{}", out.stderr);
    let help = run(&["decode", "--help"]);
    assert_eq!(help.code, Some(0));
    assert!(help.stdout.contains("Exit status: 0 complete; 1 error"));
    assert!(help
        .stdout
        .contains("2 written but incomplete: frames were lost"));
    let help = run(&["survey", "--help"]);
    assert!(help.stdout.contains("2 written but incomplete"));
    let help = run(&["replay", "--help"]);
    assert!(help.stdout.contains("3 replayed solutions"));
}
