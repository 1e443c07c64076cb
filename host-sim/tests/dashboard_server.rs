//! `host-sim dashboard` served over loopback: the page and the embedded
//! uPlot, the update stream of a replayed capture to its end (with the
//! link's counts and an undetermined azimuth as the word), a reconnect
//! with Last-Event-ID that gets only what is new, refused commands while
//! replaying; and on a pty standing in for the probe, the commands' ACKs
//! on the page and every byte recorded to --save.
#![cfg(feature = "dashboard")]

mod common;

mod dashboard_common;

use std::path::Path;

use dashboard_common::{follow, raw_request, request, simulated_capture, start};
use serde_json::Value;

#[test]
fn a_replayed_capture_streams_to_its_end_and_a_reconnect_resumes() {
    let dir = common::scratch("dashboard", "replay");
    let capture = simulated_capture(&dir, 30);
    let d = start(&["--file", capture.to_str().unwrap(), "--speed", "200"]);

    let (status, page) = request(&d, "GET", "/");
    assert_eq!(status, 200);
    assert!(page.contains("/uPlot.js") && page.contains("id=\"azimuth\""));
    let (status, uplot) = request(&d, "GET", "/uPlot.js");
    assert_eq!(status, 200);
    let vendored = include_str!("../assets/dashboard/vendor/uplot/uPlot.iife.min.js");
    assert_eq!(uplot, vendored);

    let (id, last) = follow(&d.addr, None, |u| u["rest"]["finished"] == true);
    let rest = &last["rest"];
    assert_eq!(rest["finished"], true, "{rest}");
    // 30 s at 20 Hz: a boot event, 600 raw and 600 navigation frames.
    assert_eq!(rest["link"]["frames"], 1201, "{rest}");
    assert_eq!(rest["link"]["raw"], 600);
    assert_eq!(rest["link"]["lost"], 0);
    assert_eq!(rest["link"]["crc_errors"], 0);
    assert_eq!(rest["latest"]["azimuth"], "undetermined");
    assert!(rest["latest"]["inclination"]
        .as_str()
        .unwrap()
        .contains(" +- "));
    assert!(rest["source"]["controls_disabled"]
        .as_str()
        .unwrap()
        .contains("replaying"));

    // A page that saw everything gets nothing again; a new one all of it.
    let (_, resumed) = follow(&d.addr, Some(&id), |_| true);
    assert_eq!(resumed["rest"]["reset"], false);
    assert_eq!(resumed["sensors"].as_array().unwrap().len(), 0);
    let (_, fresh) = follow(&d.addr, None, |_| true);
    assert_eq!(fresh["rest"]["reset"], true);
    assert_eq!(fresh["sensors"].as_array().unwrap().len(), 600);

    let (status, why) = request(&d, "POST", "/api/align");
    assert_eq!(status, 409);
    assert!(why.contains("replaying"), "{why}");
    let (status, why) = request(&d, "POST", "/api/index/1/30");
    assert_eq!(status, 400);
    assert!(why.contains("2 to 36 positions"), "{why}");
    std::fs::remove_dir_all(dir).ok();
}

/// A capture of 100 s with three stations whose azimuth is determined,
/// and the depth log that pairs them with MD.
fn capture_with_stations(dir: &Path) -> (std::path::PathBuf, std::path::PathBuf) {
    use host_sim::formats::capture::CaptureWriter;
    use mwd_core::protocol::frame::station_flags;
    use mwd_core::protocol::{Payload, RawSample, StationSurvey};
    let mut writer = CaptureWriter::new(Vec::new());
    for n in 0..2000u32 {
        let time_us = u64::from(n) * 50_000;
        writer
            .write(&Payload::Raw(RawSample {
                time_us,
                sample_counter: n,
                ..RawSample::default()
            }))
            .unwrap();
        if n % 600 == 599 {
            writer
                .write(&Payload::Station(StationSurvey {
                    time_us,
                    station: (n / 600 + 1) as u16,
                    flags: station_flags::MAGNETIC_FREE,
                    start_sample: n - 100,
                    end_sample: n,
                    angles: [1.5, 2.0, 0.3],
                    angles_std: [0.001, 0.02, 0.002],
                    correlations: [0.0; 3],
                    still_quality: 1.0,
                }))
                .unwrap();
        }
    }
    let capture = dir.join("stations.bin");
    std::fs::write(&capture, writer.finish().unwrap()).unwrap();
    let depth = dir.join("depth.csv");
    std::fs::write(&depth, "time_s,md_m\n0,3000\n100,3030\n").unwrap();
    (capture, depth)
}

#[test]
fn with_a_depth_log_the_stations_get_positions_with_their_sigma() {
    let dir = common::scratch("dashboard", "stations");
    let (capture, depth) = capture_with_stations(&dir);
    let d = start(&[
        "--file",
        capture.to_str().unwrap(),
        "--speed",
        "1000",
        "--depth",
        depth.to_str().unwrap(),
    ]);
    let (_, last) = follow(&d.addr, None, |u| u["rest"]["finished"] == true);
    let stations = &last["rest"]["stations"];
    let rows = stations["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 3, "{stations}");
    // Station 1 (29.95 s) is the tie-on: MD from the log, at the origin.
    assert_eq!(rows[0]["md"], "3008.99 m");
    assert_eq!(rows[2]["md"], "3026.99 m");
    assert_eq!(rows[2]["azimuth"], "114.592 +- 1.146 deg (1 sigma)");
    for row in rows {
        let position = row["position"].as_str().unwrap();
        assert!(
            position.starts_with("N ") && position.matches(" +- ").count() == 3,
            "{position}"
        );
    }
    // Drilled along azimuth 2 rad at 86 deg inclination: north < 0, east > 0.
    let plan = stations["plan"].as_array().unwrap();
    assert_eq!(plan.len(), 3);
    let (east, north) = (plan[2][0].as_f64().unwrap(), plan[2][1].as_f64().unwrap());
    assert!(east > 0.0 && north < 0.0, "{east} {north}");
    assert_eq!(stations["section"].as_array().unwrap().len(), 3);
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn with_a_job_plan_the_stations_are_drawn_against_it_with_their_ellipses() {
    let dir = common::scratch("dashboard", "plan");
    let (capture, depth, job) = common::simulate_tied_in(&dir);
    // The tied-in job, with the plan the run drilled.
    let text = std::fs::read_to_string(&job).unwrap();
    let plan = common::plan("qemu-short.json");
    let with_plan = text.replacen(
        "\"site\"",
        &format!("\"plan\": {:?},\n  \"site\"", plan.to_str().unwrap()),
        1,
    );
    std::fs::write(&job, with_plan).unwrap();
    let d = start(&[
        "--file",
        common::s(&capture),
        "--speed",
        "1000",
        "--depth",
        common::s(&depth),
        "--job",
        common::s(&job),
    ]);
    follow(&d.addr, None, |u| u["rest"]["finished"] == true);
    // A new page's snapshot, with everything.
    let (_, last) = follow(&d.addr, None, |_| true);
    let stations = &last["rest"]["stations"];
    let placed = stations["plan"].as_array().unwrap().len();
    assert!(placed >= 2, "{stations}");
    // Every station placed has its ellipse in both views (its covariance
    // is valid), 2-sigma as the survey figures draw them.
    assert_eq!(stations["plan_ellipses"].as_array().unwrap().len(), placed);
    assert_eq!(
        stations["section_ellipses"].as_array().unwrap().len(),
        placed
    );
    assert_eq!(stations["ellipse_sigma"], 2.0);
    // The plan from its tie-on (N 420, E 310, TVD 2450) in both views; the
    // section along the azimuth to the plan's end.
    let well_plan = &stations["well_plan"];
    let plan_view = well_plan["plan"].as_array().unwrap();
    assert_eq!(plan_view.len(), 401);
    assert_eq!(plan_view[0], serde_json::json!([310.0, 420.0]));
    let section = well_plan["section"].as_array().unwrap();
    assert_eq!(section[0][1], 2450.0);
    let [n, e] = [
        plan_view[400][1].as_f64().unwrap(),
        plan_view[400][0].as_f64().unwrap(),
    ];
    let azimuth = stations["section_azimuth_deg"].as_f64().unwrap();
    assert!(
        (azimuth - e.atan2(n).to_degrees()).abs() < 1e-9,
        "{azimuth}"
    );
    // The first station sits on the plan's tie-on.
    assert_eq!(stations["plan"][0], plan_view[0]);
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn bad_inputs_are_refused_before_serving() {
    let dir = common::scratch("dashboard", "bad");
    let not_capture = dir.join("notes.bin");
    std::fs::write(&not_capture, "time_s,md_m\n0,1\n").unwrap();
    let run = common::run(&["dashboard", "--file", not_capture.to_str().unwrap()]);
    assert_eq!(run.code, Some(1));
    assert!(
        run.stderr.contains("is not a probe capture"),
        "{}",
        run.stderr
    );
    let capture = simulated_capture(&dir, 30);
    let run = common::run(&[
        "dashboard",
        "--file",
        capture.to_str().unwrap(),
        "--speed",
        "0",
    ]);
    assert_eq!(run.code, Some(1));
    assert!(run.stderr.contains("above 0"), "{}", run.stderr);
    let run = common::run(&[
        "dashboard",
        "--file",
        capture.to_str().unwrap(),
        "--depth",
        not_capture.with_extension("missing").to_str().unwrap(),
    ]);
    assert_eq!(run.code, Some(1));
    assert!(run.stderr.contains("notes.missing"), "{}", run.stderr);
    std::fs::remove_dir_all(dir).ok();
}

#[cfg(target_os = "linux")]
mod on_a_port {
    use super::*;
    use dashboard_common::probe::stand_in;
    use mwd_core::protocol::MAX_WIRE_LEN;
    use std::time::Duration;

    #[test]
    fn commands_are_acknowledged_on_the_page_and_the_bytes_recorded() {
        let dir = common::scratch("dashboard", "port");
        let job = dir.join("job.json");
        std::fs::write(
            &job,
            r#"{"format": "mwd-job", "version": 1,
                "site": {"latitude_deg": 30.5, "longitude_deg": 114.25, "height_m": 23.0}}"#,
        )
        .unwrap();
        let saved = dir.join("saved.bin");
        let probe = stand_in();
        let d = start(&[
            "--port",
            &probe.port,
            "--save",
            saved.to_str().unwrap(),
            "--job",
            job.to_str().unwrap(),
        ]);
        // Not from the page (another site's form, no token): refused.
        let host = format!("Host: {}\r\n", d.addr);
        let (status, _) = raw_request(&d.addr, "POST", "/api/align", &host);
        assert_eq!(status, 403);
        let (status, _) = request(&d, "POST", "/api/station");
        assert_eq!(status, 202);
        let (status, _) = request(&d, "POST", "/api/configure");
        assert_eq!(status, 202);
        let all_answered = |u: &Value| {
            u["rest"]["commands"].as_array().is_some_and(|c| {
                c.len() == 6
                    && c.iter()
                        .all(|c| c["result"] != "sent, waiting for the reply")
            })
        };
        let (_, update) = follow(&d.addr, None, all_answered);
        let commands = update["rest"]["commands"].as_array().unwrap();
        assert_eq!(commands.len(), 6, "{commands:?}");
        assert_eq!(commands[0]["label"], "take a station");
        for c in commands {
            assert_eq!(c["result"], "ACK, configuration version 3", "{c}");
        }
        assert_eq!(update["rest"]["source"]["config_version"], 3);
        assert_eq!(update["rest"]["source"]["controls_disabled"], Value::Null);
        assert!(update["rest"]["link"]["raw"].as_u64().unwrap() > 0);

        let sent = probe.stop();
        // The dashboard reads every 100 ms at most: give it time to record.
        std::thread::sleep(Duration::from_millis(500));
        drop(d);
        let recorded = std::fs::read(&saved).unwrap();
        // What was sent before the dashboard opened the port and set the
        // pty to raw mode may be lost or mangled by the line discipline
        // (the first few frames); from then on, every byte, in order.
        let common = recorded
            .iter()
            .rev()
            .zip(sent.iter().rev())
            .take_while(|(a, b)| a == b)
            .count();
        assert!(
            recorded.len() - common < 4 * MAX_WIRE_LEN && common * 2 > sent.len(),
            "{common} bytes in common at the end of {} recorded, {} sent",
            recorded.len(),
            sent.len()
        );
        std::fs::remove_dir_all(dir).ok();
    }
}
