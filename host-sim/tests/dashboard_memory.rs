//! The dashboard's memory stays bounded over a long session: eight hours
//! at 20 Hz (576,000 samples, each with its navigation solution, plus a
//! station every 10 min and an event every hour) through the server-side
//! state leave every buffer at its bound, and an update for a new page is
//! no larger than those bounds allow. A page that reconnects gets what it
//! missed, or a fresh snapshot once that was dropped.
#![cfg(feature = "dashboard")]

use host_sim::dashboard::state::{DashboardState, Limits, SourceInfo, LIMITS};
use host_sim::survey::stations::{job_tie_on, SurveySetup};
use mwd_core::protocol::frame::{nav_mode, EventKind, NO_PART};
use mwd_core::protocol::{Event, Frame, NavSolution, Payload, RawSample, StationSurvey};
use serde_json::Value;

const SAMPLES: u32 = 8 * 3600 * 20;

fn state(limits: Limits) -> DashboardState {
    let info = SourceInfo {
        description: "test".into(),
        controls_disabled: None,
        calibration: vec![],
        job: None,
        depth: None,
        survey: SurveySetup::probe(job_tie_on(None), 45f64.to_radians()).unwrap(),
        well_plan: None,
    };
    DashboardState::new(info, 7, limits)
}

fn frames_of_sample(n: u32) -> Vec<Frame> {
    let time_us = u64::from(n) * 50_000;
    let seq = (n * 2) as u16;
    let mut frames = vec![
        Frame {
            seq,
            payload: Payload::Raw(RawSample {
                time_us,
                sample_counter: n,
                ..RawSample::default()
            }),
        },
        Frame {
            seq: seq.wrapping_add(1),
            payload: Payload::Nav(NavSolution {
                time_us,
                sample_counter: n,
                mode: nav_mode::NAVIGATING,
                attitude: [0.1, 0.2, 1.0],
                attitude_std: [0.001, 0.001, f32::INFINITY],
                ..NavSolution::default()
            }),
        },
    ];
    if n % (20 * 600) == 599 {
        frames.push(Frame {
            seq,
            payload: Payload::Station(StationSurvey {
                time_us,
                station: (n / 12_000 + 1) as u16,
                end_sample: n,
                angles: [1.6, 2.0, 0.5],
                angles_std: [0.001, f32::INFINITY, 0.001],
                ..StationSurvey::default()
            }),
        });
    }
    if n % (20 * 3600) == 0 {
        frames.push(Frame {
            seq,
            payload: Payload::Event(Event {
                time_us,
                kind: EventKind::Resync,
                part: NO_PART,
                code: 0,
                value: 1,
            }),
        });
    }
    frames
}

fn parse(text: &str) -> Value {
    serde_json::from_str(text).expect("the update is JSON")
}

#[test]
fn eight_hours_at_20_hz_stay_within_the_buffers_bounds() {
    let mut s = state(LIMITS);
    let mut peak = s.buffer_lengths();
    for n in 0..SAMPLES {
        for frame in frames_of_sample(n) {
            s.push_frame(&frame);
        }
        if n % 20_000 == 0 {
            let l = s.buffer_lengths();
            peak.sensors = peak.sensors.max(l.sensors);
            peak.long_sensors = peak.long_sensors.max(l.long_sensors);
        }
    }
    let l = s.buffer_lengths();
    assert_eq!(l.sensors, LIMITS.recent_samples);
    assert_eq!(l.attitude, LIMITS.recent_samples);
    assert!(peak.sensors <= LIMITS.recent_samples);
    // One long-window point per 10 s bucket: 8 h fit within 10 h.
    let buckets = SAMPLES as usize / LIMITS.bucket_samples;
    assert_eq!(l.long_sensors, buckets);
    assert_eq!(l.long_attitude, buckets);
    assert!(l.long_sensors <= LIMITS.long_points);
    assert_eq!(l.stations, 48);
    assert_eq!(l.events, 8);

    // A new page's snapshot holds exactly the bounded buffers.
    let snapshot = parse(&s.update_json(None));
    assert_eq!(snapshot["rest"]["reset"], true);
    assert_eq!(
        snapshot["sensors"].as_array().unwrap().len(),
        LIMITS.recent_samples
    );
    assert_eq!(snapshot["long_attitude"].as_array().unwrap().len(), buckets);
    // The undetermined azimuth is sent as no number.
    let last = snapshot["attitude"].as_array().unwrap().last().unwrap();
    assert!(last[3].is_null() && last[4].is_null(), "{last}");
    assert_eq!(snapshot["rest"]["latest"]["azimuth"], "undetermined");
    let station_azimuths: Vec<&Value> = snapshot["rest"]["stations"]["rows"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| &r["azimuth"])
        .collect();
    assert!(station_azimuths.iter().all(|a| *a == "undetermined"));
}

#[test]
fn beyond_the_long_window_the_oldest_points_go() {
    // Small bounds, the same code: 3 h of 20 Hz into a 1 h long window.
    let limits = Limits {
        recent_samples: 100,
        bucket_samples: 20,
        long_points: 3600,
        stations: 5,
        events: 3,
        commands: 2,
    };
    let mut s = state(limits);
    for n in 0..3 * 3600 * 20 {
        for frame in frames_of_sample(n) {
            s.push_frame(&frame);
        }
    }
    let l = s.buffer_lengths();
    assert_eq!((l.sensors, l.attitude), (100, 100));
    assert_eq!((l.long_sensors, l.long_attitude), (3600, 3600));
    assert_eq!((l.stations, l.events), (5, 3));
    for k in 0..4 {
        let n = s.command_sent(&format!("command {k}"));
        s.command_result(n, "ACK".into(), None);
    }
    assert_eq!(s.buffer_lengths().commands, 2);
    let snapshot = parse(&s.update_json(None));
    let note = snapshot["rest"]["stations"]["note"].as_str().unwrap();
    assert!(
        note.contains("13 earlier stations no longer held"),
        "{note}"
    );
    let commands = snapshot["rest"]["commands"].as_array().unwrap();
    assert_eq!(commands[1]["label"], "command 3");
    assert_eq!(commands[1]["result"], "ACK");
}

#[test]
fn a_reconnecting_page_gets_what_it_missed_or_a_snapshot() {
    let limits = Limits {
        recent_samples: 50,
        ..LIMITS
    };
    let mut s = state(limits);
    for n in 0..30 {
        for frame in frames_of_sample(n) {
            s.push_frame(&frame);
        }
    }
    let seen = s.event_id();
    for n in 30..40 {
        for frame in frames_of_sample(n) {
            s.push_frame(&frame);
        }
    }
    let update = parse(&s.update_json(Some(&seen)));
    assert_eq!(update["rest"]["reset"], false);
    let times: Vec<f64> = update["sensors"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r[0].as_f64().unwrap())
        .collect();
    assert_eq!(times.len(), 10);
    assert_eq!(times[0], 1.5);
    // Unchanged lists are not sent again.
    assert!(update["rest"]["events"].is_null());
    // Another server's id, or one whose data were dropped: a snapshot.
    let other = parse(&s.update_json(Some("8-3")));
    assert_eq!(other["rest"]["reset"], true);
    assert_eq!(other["sensors"].as_array().unwrap().len(), 40);
    for n in 40..200 {
        for frame in frames_of_sample(n) {
            s.push_frame(&frame);
        }
    }
    let late = parse(&s.update_json(Some(&seen)));
    assert_eq!(late["rest"]["reset"], true);
    assert_eq!(late["sensors"].as_array().unwrap().len(), 50);
    assert_eq!(
        parse(&s.update_json(Some("garbage")))["rest"]["reset"],
        true
    );
}
