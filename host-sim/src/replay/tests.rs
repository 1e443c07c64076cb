//! The replay's unit tests (frames without commands).

use super::*;
use mwd_core::earth::Position;
use mwd_core::probe::{Navigator, TieIn};
use mwd_core::protocol::frame::{nav_flags, raw_flags};
use mwd_core::protocol::{
    EventKind, Frame, NavSolution, Payload, RawPart, RawSample, StationSurvey,
};
use mwd_core::sensor_units::{m_s2_to_accel_count, PART_MOUNTINGS, STANDARD_GRAVITY_M_S2};

fn raw(n: u32) -> Frame {
    let parts = PART_MOUNTINGS.map(|m| RawPart {
        accel: m
            .body_to_sensor([0.0, 0.0, STANDARD_GRAVITY_M_S2])
            .map(m_s2_to_accel_count),
        flags: raw_flags::GYRO_VALID | raw_flags::ACCEL_VALID,
        ..RawPart::default()
    });
    Frame {
        seq: n as u16,
        payload: Payload::Raw(RawSample {
            time_us: u64::from(n) * 50_000,
            sample_counter: n,
            parts,
        }),
    }
}

/// Sample `n` of a probe turning about body z at 0.05 rad/s.
fn turning(n: u32) -> Frame {
    let mut frame = raw(n);
    if let Payload::Raw(r) = &mut frame.payload {
        for (part, m) in r.parts.iter_mut().zip(PART_MOUNTINGS) {
            part.gyro_rate = mwd_core::sensor_units::rad_s_to_gyro_count(
                m.gyro_rate_from_body([0.0, 0.0, 0.05]),
            );
        }
    }
    frame
}

#[test]
fn replay_matches_the_same_code_and_catches_a_changed_solution() {
    let site = Position::paper_site();
    let raws: Vec<Frame> = (0..150).map(raw).collect();
    // The "probe's" solutions: the same navigation run once already.
    let (first, _) = replay(&raws, site);
    let mut capture = Vec::new();
    for (frame, row) in raws.iter().zip(&first) {
        let mut nav = row.solution;
        if nav.sample_counter == 120 {
            nav.attitude[2] += 1e-6;
        }
        capture.extend(numbered(capture.len(), [frame.payload, Payload::Nav(nav)]));
    }
    let (rows, summary) = replay(&capture, site);
    assert_eq!(rows.len(), 150);
    assert_eq!(
        summary,
        ReplaySummary {
            raw_frames: 150,
            probe_solutions: 150,
            matched: 149,
            mismatched: 1,
            unchecked: 0,
            degraded: 0,
            restarts: 0,
        }
    );
    let mut csv = Vec::new();
    write_csv(&rows, &mut csv).unwrap();
    let text = String::from_utf8(csv).unwrap();
    assert_eq!(text.lines().count(), 151);
    assert!(text.lines().nth(121).unwrap().ends_with(",no"));
}

/// Frames numbered from `first` on, as the probe numbers them.
fn numbered(first: usize, payloads: impl IntoIterator<Item = Payload>) -> Vec<Frame> {
    (first..)
        .zip(payloads)
        .map(|(seq, payload)| Frame {
            seq: seq as u16,
            payload,
        })
        .collect()
}

/// A probe run as the probe sends it: boot event, then per sample the
/// raw frame and its navigation frame, numbered from 0.
fn probe_run(samples: u32) -> Vec<Frame> {
    let site = Position::paper_site();
    let mut navigator = Navigator::new(site);
    let boot = Payload::Event(mwd_core::protocol::Event {
        time_us: 0,
        kind: EventKind::Boot,
        part: mwd_core::protocol::frame::NO_PART,
        code: 1,
        value: 0,
    });
    let payloads = std::iter::once(boot).chain((0..samples).flat_map(|n| {
        let Payload::Raw(r) = raw(n).payload else {
            unreachable!()
        };
        [Payload::Raw(r), Payload::Nav(navigator.step(&r))]
    }));
    numbered(0, payloads.collect::<Vec<_>>())
}

#[test]
fn a_lost_raw_frame_stops_the_comparison_there_and_a_boot_restarts_it() {
    let site = Position::paper_site();
    // Raw frame of sample 69 lost (frame 139: boot, then two per sample).
    let mut capture = probe_run(130);
    capture.remove(139);
    // The probe reboots and runs again.
    capture.extend(probe_run(130));
    let mut replayer = Replayer::new(site);
    for frame in &capture {
        replayer.push(frame);
    }
    assert_eq!(
        replayer.step_losses(),
        &[StepLoss {
            run: 0,
            from_sample: 70,
            reason: StepLossReason::RawFramesLost
        }]
    );
    let (rows, summary) = replayer.finish();
    assert_eq!(
        summary,
        ReplaySummary {
            raw_frames: 129 + 130,
            probe_solutions: 260,
            // 0..=68 of the first run, all 130 of the second.
            matched: 69 + 130,
            mismatched: 0,
            // 70..130 of the first run, and sample 69's own.
            unchecked: 60 + 1,
            degraded: 0,
            restarts: 1,
        }
    );
    assert!(rows[69..129]
        .iter()
        .all(|r| !r.in_step && r.matches_probe.is_none()));
    assert!(rows[129..]
        .iter()
        .all(|r| r.in_step && r.matches_probe == Some(true)));
}

#[test]
fn samples_the_probe_skipped_itself_keep_the_replay_in_step() {
    // A resynchronisation: no raw frame for samples 51 and 52, no
    // frame lost (the numbers run on).
    let mut navigator = Navigator::new(Position::paper_site());
    let payloads = (0..100u32).filter(|n| !(51..53).contains(n)).flat_map(|n| {
        let Payload::Raw(r) = raw(n).payload else {
            unreachable!()
        };
        [Payload::Raw(r), Payload::Nav(navigator.step(&r))]
    });
    let capture = numbered(0, payloads.collect::<Vec<_>>());
    let mut replayer = Replayer::new(Position::paper_site());
    for frame in &capture {
        replayer.push(frame);
    }
    assert!(replayer.step_losses().is_empty());
    let (_, summary) = replayer.finish();
    assert_eq!((summary.matched, summary.unchecked), (98, 0));
}

#[test]
fn a_capture_that_starts_mid_run_is_not_compared() {
    let capture = probe_run(120);
    let mut replayer = Replayer::new(Position::paper_site());
    for frame in &capture[21..] {
        replayer.push(frame);
    }
    assert_eq!(replayer.step_losses()[0].from_sample, 10);
    let (_, summary) = replayer.finish();
    assert_eq!((summary.matched, summary.mismatched), (0, 0));
}

#[test]
fn lost_navigation_frames_alone_keep_the_replay_in_step() {
    let mut capture = probe_run(120);
    capture.retain(|f| f.seq % 10 != 4);
    let mut replayer = Replayer::new(Position::paper_site());
    for frame in &capture {
        replayer.push(frame);
    }
    assert!(replayer.step_losses().is_empty());
    let (_, summary) = replayer.finish();
    assert_eq!(
        (summary.matched, summary.mismatched, summary.unchecked),
        (96, 0, 0)
    );
}

#[test]
fn the_csv_never_shows_an_undetermined_azimuth_and_reads_0_to_360() {
    let solution = NavSolution {
        attitude: [-0.5, 0.1, -1.0],
        attitude_std: [0.01, 0.01, f32::INFINITY],
        ..NavSolution::default()
    };
    let row = ReplayRow {
        solution,
        matches_probe: Some(true),
        in_step: true,
    };
    let mut determined = row;
    determined.solution.attitude_std[2] = 0.01;
    let mut placeholder = row;
    placeholder.solution.attitude = [f32::NAN; 3];
    let mut lost = row;
    lost.solution.flags = nav_flags::HEADING_LOST;
    let mut csv = Vec::new();
    write_csv(&[row, determined, placeholder, lost], &mut csv).unwrap();
    let text = String::from_utf8(csv).unwrap();
    let cells: Vec<Vec<&str>> = text.lines().map(|l| l.split(',').collect()).collect();
    let col = |name: &str| cells[0].iter().position(|c| *c == name).unwrap();
    let (az, status, tf) = (
        col("azimuth_deg"),
        col("azimuth_status"),
        col("toolface_deg"),
    );
    assert_eq!((cells[1][az], cells[1][status]), ("", "undetermined"));
    assert_eq!(cells[2][status], "determined");
    let azimuth: f64 = cells[2][az].parse().unwrap();
    assert!(
        (azimuth - (360.0 - 1f64.to_degrees())).abs() < 1e-4,
        "{azimuth}"
    );
    let toolface: f64 = cells[1][tf].parse().unwrap();
    assert!(
        (toolface - (360.0 - 0.5f64.to_degrees())).abs() < 1e-4,
        "{toolface}"
    );
    assert_eq!(
        (cells[3][az], cells[3][status], cells[3][tf]),
        ("", "n/a", "NaN")
    );
    assert_eq!((cells[4][az], cells[4][status]), ("", "lost"));
}

#[test]
fn a_replay_applies_the_probes_calibration() {
    use mwd_core::calibration::{ProbeCalibration, TriadCalibration};
    // The same still, level samples; a calibration claiming a body-x
    // accelerometer bias of 10 counts tilts the replayed roll by
    // atan(bias / g), as the probe with that calibration would.
    let site = Position::paper_site();
    let raws: Vec<Frame> = (0..120).map(raw).collect();
    let bias = 10.0 * f64::from(STANDARD_GRAVITY_M_S2) / 650.0;
    let triad = TriadCalibration {
        bias: [bias, 0.0, 0.0],
        ..TriadCalibration::IDENTITY
    };
    let calibration = ProbeCalibration {
        accel: [triad; 2],
        ..ProbeCalibration::default()
    };
    let (plain, _) = replay(&raws, site);
    let (calibrated, _) = replay_with(&raws, site, calibration);
    let roll = |rows: &[ReplayRow]| f64::from(rows[110].solution.attitude[0]);
    let expected = (bias / f64::from(STANDARD_GRAVITY_M_S2)).atan();
    assert!(roll(&plain).abs() < 1e-3, "{}", roll(&plain));
    assert!((roll(&calibrated).abs() - expected).abs() < 0.05 * expected);
}

/// A probe run that navigates, turns, stops for 30 s and turns again,
/// as the probe sends it (the station frame after its cycle's
/// navigation frame): the replay finishes the same station and finds it
/// identical; a changed station is caught.
#[test]
fn station_surveys_are_replayed_and_compared_bit_for_bit() {
    let site = Position::paper_site();
    let aligned = 1200;
    let mut navigator = Navigator::new(site);
    // the probe's filter as the replay's, keeping its links (not sent)
    navigator.track_station_links(true);
    let mut payloads = Vec::new();
    let mut probe_link = None;
    for n in 0..aligned + 1000 {
        let moving = (aligned..aligned + 100).contains(&n) || n >= aligned + 700;
        let frame = if moving { turning(n) } else { raw(n) };
        let Payload::Raw(r) = frame.payload else {
            unreachable!()
        };
        payloads.push(Payload::Raw(r));
        payloads.push(Payload::Nav(navigator.step(&r)));
        if let Some(station) = navigator.take_station() {
            probe_link = navigator.station_link().copied();
            payloads.push(Payload::Station(station));
        }
    }
    let stations: Vec<StationSurvey> = payloads
        .iter()
        .filter_map(|p| match p {
            Payload::Station(s) => Some(*s),
            _ => None,
        })
        .collect();
    assert_eq!(stations.len(), 1, "{stations:?}");
    // The settled survey: 40-80 still cycles before the last one,
    // aligned + 699 (`SURVEY_SETTLE_EPOCHS`).
    let before = aligned + 699 - stations[0].end_sample;
    assert!((40..=80).contains(&before), "{before}");
    let capture = numbered(0, payloads.clone());
    let mut replayer = Replayer::new(site);
    capture.iter().for_each(|f| {
        replayer.push(f);
    });
    let (rows, summary) = replayer.stations();
    assert_eq!(
        summary,
        StationSummary {
            replayed: 1,
            probe: 1,
            matched: 1,
            ..StationSummary::default()
        }
    );
    assert_eq!(rows[0].matches_probe, Some(true));
    // The replay's link is the probe's filter's (which it did not send).
    assert!(probe_link.is_some());
    assert_eq!(rows[0].link, probe_link);
    // One bit of the probe's toolface sigma changed: caught.
    let changed: Vec<Payload> = payloads
        .into_iter()
        .map(|p| match p {
            Payload::Station(mut s) => {
                s.angles_std[2] = f32::from_bits(s.angles_std[2].to_bits() ^ 1);
                Payload::Station(s)
            }
            p => p,
        })
        .collect();
    let mut replayer = Replayer::new(site);
    numbered(0, changed).iter().for_each(|f| {
        replayer.push(f);
    });
    let (_, summary) = replayer.stations();
    assert_eq!((summary.matched, summary.mismatched), (0, 1));
}

/// A probe configured with a tie-in starts from it after its first
/// navigating cycle: the replay given the same tie-in does too, and its
/// solutions and station are the probe's bit for bit; a replay without
/// it differs from there on.
#[test]
fn a_configured_tie_in_is_taken_where_the_probe_takes_it() {
    use mwd_core::conventions::DrillingAngles;
    let site = Position::paper_site();
    let tie_in = TieIn::new(
        DrillingAngles {
            inclination: std::f64::consts::FRAC_PI_2,
            azimuth: 2.0,
            toolface: 0.0,
        },
        DrillingAngles {
            inclination: 0.2f64.to_radians(),
            azimuth: 0.5f64.to_radians(),
            toolface: 0.2f64.to_radians(),
        },
    )
    .unwrap();
    // the probe's main loop: a step, its station, then the pending tie-in
    let mut navigator = Navigator::new(site);
    let mut pending = Some(tie_in);
    let mut payloads = Vec::new();
    let mut tied_at = None;
    for n in 0..2200 {
        let frame = if (1200..1300).contains(&n) || n >= 1900 {
            turning(n)
        } else {
            raw(n)
        };
        let Payload::Raw(r) = frame.payload else {
            unreachable!()
        };
        payloads.push(Payload::Raw(r));
        payloads.push(Payload::Nav(navigator.step(&r)));
        payloads.extend(navigator.take_station().map(Payload::Station));
        if let Some(t) = pending.filter(|_| navigator.is_navigating()) {
            navigator.start_from_tie_in(&t);
            pending = None;
            tied_at = Some(n);
        }
    }
    assert!(tied_at.is_some_and(|n| n < 1200), "{tied_at:?}");
    let capture = numbered(0, payloads);
    let replay = |tie_in: Option<TieIn>| {
        let mut replayer = Replayer::new(site).with_tie_in(tie_in);
        capture.iter().for_each(|f| {
            replayer.push(f);
        });
        let (_, stations) = replayer.stations();
        (*replayer.summary(), stations)
    };
    let (summary, stations) = replay(Some(tie_in));
    assert_eq!(summary.mismatched, 0, "{summary:?}");
    assert_eq!(summary.matched, summary.probe_solutions, "{summary:?}");
    assert_eq!(
        (stations.matched, stations.mismatched),
        (1, 0),
        "{stations:?}"
    );
    let (summary, stations) = replay(None);
    assert!(summary.mismatched > 0, "{summary:?}");
    assert_eq!(stations.mismatched, 1, "{stations:?}");
}

/// A long replay forgets the rows it has written (`write_settled`), and
/// still compares every solution: also those whose row was forgotten
/// before the probe's solution came (here 100 navigation frames sent late,
/// one of them different).
#[test]
fn a_replay_that_forgets_its_written_rows_compares_as_one_that_keeps_them() {
    let run = probe_run(300);
    let late =
        |f: &Frame| matches!(f.payload, Payload::Nav(n) if (100..200).contains(&n.sample_counter));
    let mut payloads: Vec<Payload> = run.iter().filter(|f| !late(f)).map(|f| f.payload).collect();
    payloads.extend(run.iter().filter(|f| late(f)).map(|f| {
        let mut p = f.payload;
        if let Payload::Nav(n) = &mut p {
            if n.sample_counter == 150 {
                n.attitude[2] += 1e-6;
            }
        }
        p
    }));
    let capture = numbered(0, payloads);
    let site = Position::paper_site();

    let mut keeping = Replayer::new(site);
    for frame in &capture {
        keeping.push(frame);
    }
    let (kept_rows, kept) = keeping.finish();

    let mut forgetting = Replayer::new(site);
    let mut csv = Vec::new();
    for (i, frame) in capture.iter().enumerate() {
        forgetting.push(frame);
        if i % 10 == 0 {
            forgetting.write_settled(Some(&mut csv), false).unwrap();
        }
    }
    forgetting.end_of_stream();
    forgetting.write_settled(Some(&mut csv), true).unwrap();
    assert_eq!(forgetting.rows_replayed(), 300);
    let last = forgetting.last_row().map(|r| r.solution.sample_counter);
    let (left, forgot) = forgetting.finish();

    assert_eq!(forgot, kept);
    assert_eq!((kept.matched, kept.mismatched, kept.unchecked), (299, 1, 0));
    assert!(left.is_empty(), "{} rows kept", left.len());
    assert_eq!(last, Some(299));
    // The same rows, written as they settled: the late ones before their
    // comparison was known.
    let mut whole = Vec::new();
    write_csv_rows(&kept_rows, &mut whole).unwrap();
    let solutions = |text: &[u8]| -> Vec<String> {
        String::from_utf8(text.to_vec())
            .unwrap()
            .lines()
            .map(|l| l.rsplit_once(',').unwrap().0.to_string())
            .collect()
    };
    assert_eq!(solutions(&csv), solutions(&whole));
}
