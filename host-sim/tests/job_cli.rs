//! The job file read by `host-sim survey` and `host-sim replay` (`--job`,
//! host-sim/src/job.rs): a job gives the same results as the flags it
//! stands for, flags given override it, and a bad job is refused with a
//! sentence, never a panic.

mod common;

use common::{refused, run, s};
use std::path::{Path, PathBuf};

fn scratch(name: &str) -> PathBuf {
    common::scratch("job-cli", name)
}

/// A job at latitude 60 deg with a survey part; `survey` is its JSON.
fn write_job(dir: &Path, name: &str, survey: &str, extra: &str) -> PathBuf {
    let path = dir.join(name);
    let text = format!(
        r#"{{"format": "mwd-job", "version": 1,
            "site": {{"latitude_deg": 60.0, "longitude_deg": 5.25, "height_m": 40.0}}
            {extra}, "survey": {survey}}}"#
    );
    std::fs::write(&path, text).unwrap();
    path
}

/// The outputs of a command that must succeed (exit `code`).
fn ok(args: &[&str], code: i32) -> String {
    let out = run(args);
    assert_eq!(out.code, Some(code), "{args:?}: {}", out.stderr);
    assert!(!out.stderr.contains("panicked"), "{}", out.stderr);
    out.stdout
}

/// A CSV file's cell `column` of data row `row`.
fn cell(path: &Path, row: usize, column: &str) -> f64 {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    let i = head.iter().position(|h| *h == column).unwrap();
    let line = lines.nth(row).unwrap();
    line.split(',').nth(i).unwrap().parse().unwrap()
}

const STATIONS: &str = "md_m,inc_deg,azi_deg\n1000,10,45\n1100,12,47\n1250,15,50\n";
const SURVEY: &str = r#"{"length_unit": "m", "error_model": "GYRO-MWD",
    "tie_on": {"md": 1000.0, "tvd": 950.0, "north": 20.0, "east": -5.0}}"#;

#[test]
fn a_station_survey_takes_the_jobs_site_tie_on_and_model_and_flags_override_them() {
    let dir = scratch("stations");
    let stations = dir.join("stations.csv");
    std::fs::write(&stations, STATIONS).unwrap();
    let job = write_job(&dir, "job.json", SURVEY, "");
    let csv = |name: &str| dir.join(name);
    let (from_job, from_flags) = (csv("job.csv"), csv("flags.csv"));
    ok(
        &[
            "survey",
            s(&stations),
            "--job",
            s(&job),
            "--csv",
            s(&from_job),
        ],
        0,
    );
    let flags = [
        "--tie-on-md",
        "1000",
        "--tie-on-north",
        "20",
        "--tie-on-east",
        "-5",
        "--error-model",
        "GYRO-MWD",
    ];
    let with_flags = |tvd: &str, lat: &str, out: &Path| {
        let mut args = vec!["survey", s(&stations), "--lat", lat, "--tie-on-tvd", tvd];
        args.extend_from_slice(&flags);
        args.extend_from_slice(&["--csv", s(out)]);
        ok(&args, 0);
    };
    with_flags("950", "60", &from_flags);
    let read = |p: &Path| std::fs::read_to_string(p).unwrap();
    assert_eq!(read(&from_job), read(&from_flags));
    assert_eq!(cell(&from_job, 0, "tvd_m"), 950.0);
    assert!(cell(&from_job, 2, "sigma_north_m") > 0.0);
    // The site's latitude reaches the gyro model: another latitude,
    // another uncertainty.
    let elsewhere = csv("lat0.csv");
    with_flags("950", "0", &elsewhere);
    assert_ne!(read(&elsewhere), read(&from_job));

    // A flag overrides the job's value, --site its site.
    let (overridden, expected) = (csv("override.csv"), csv("expected.csv"));
    ok(
        &[
            "survey",
            s(&stations),
            "--job",
            s(&job),
            "--tie-on-tvd",
            "900",
            "--site",
            "0",
            "5.25",
            "40",
            "--csv",
            s(&overridden),
        ],
        0,
    );
    with_flags("900", "0", &expected);
    assert_eq!(read(&overridden), read(&expected));

    // A job in feet on a file in metres: converted.
    let feet = write_job(
        &dir,
        "feet.json",
        r#"{"length_unit": "ft", "tie_on": {"tvd": 1000.0, "north": -10.0}}"#,
        "",
    );
    let converted = csv("feet.csv");
    ok(
        &[
            "survey",
            s(&stations),
            "--job",
            s(&feet),
            "--csv",
            s(&converted),
        ],
        0,
    );
    assert!((cell(&converted, 0, "tvd_m") - 304.8).abs() < 1e-9);
    assert!((cell(&converted, 0, "north_m") + 3.048).abs() < 1e-9);
}

#[test]
fn bad_jobs_and_conflicting_flags_are_refused_with_a_sentence() {
    let dir = scratch("bad");
    let stations = dir.join("stations.csv");
    std::fs::write(&stations, STATIONS).unwrap();
    let survey = |job: &Path, extra: &[&str]| {
        run(&[&["survey", s(&stations), "--job", s(job)], extra].concat())
    };
    refused(&survey(&dir.join("missing.json"), &[]), "missing.json");
    let not_json = dir.join("not.json");
    std::fs::write(&not_json, "site = 1").unwrap();
    refused(&survey(&not_json, &[]), "not a mwd-job v1 JSON file");
    let bad_unit = write_job(&dir, "unit.json", r#"{"length_unit": "yd"}"#, "");
    refused(&survey(&bad_unit, &[]), "length_unit");
    let bad_md = write_job(&dir, "md.json", r#"{"tie_on": {"md": 990.0}}"#, "");
    refused(&survey(&bad_md, &[]), "tie-on MD 990");
    let good = write_job(&dir, "good.json", SURVEY, "");
    // The job's site is overridden with --site, not a part of it.
    refused(&survey(&good, &["--lat", "10"]), "--lat");
    // A capture survey has the probe's own model: a job naming another is
    // refused before any file is read.
    let capture = run(&[
        "survey",
        s(&dir.join("run.bin")),
        "--depth",
        s(&dir.join("depth.csv")),
        "--job",
        s(&good),
    ]);
    refused(&capture, "not the probe's (PROBE-SCC1300)");
    let replay = run(&["replay", s(&dir.join("run.bin")), "--job", s(&bad_unit)]);
    refused(&replay, "length_unit");
}

#[test]
fn a_replay_takes_the_jobs_site_and_calibration() {
    let dir = scratch("replay");
    let capture = dir.join("run.bin");
    ok(&["simulate", "--duration", "6", "-o", s(&capture)], 0);
    std::fs::write(
        dir.join("cal.json"),
        r#"{"format": "mwd-calibration", "version": 1, "method": "tls",
            "latitude_deg": 60.0, "gravity": 9.819,
            "accel": [{"columns": ["ax", "ay", "az"], "bias": [0.01, -0.02, 0.003],
                       "correction": [[1.01, 0.001, 0.0], [0.0, 0.99, 0.002], [0.0, 0.0, 1.0]]}],
            "gyro": [{"column": "gz", "axis": "z", "bias": 1e-5, "scale": 1.0}]}"#,
    )
    .unwrap();
    let job = write_job(
        &dir,
        "job.json",
        "{}",
        r#", "calibration_file": "cal.json""#,
    );
    let replay = |extra: &[&str], name: &str| {
        let csv = dir.join(name);
        let out = ok(
            &[&["replay", s(&capture), "--csv", s(&csv)], extra].concat(),
            0,
        );
        (std::fs::read_to_string(&csv).unwrap(), out)
    };
    let (from_job, printed) = replay(&["--job", s(&job)], "job.csv");
    let cal = dir.join("cal.json");
    let flags = ["--site", "60", "5.25", "40", "--calibration-file", s(&cal)];
    let (from_flags, _) = replay(&flags, "flags.csv");
    assert_eq!(from_job, from_flags, "{printed}");
    // The job changed the solutions: the probe's own replay differs.
    let (plain, _) = replay(&[], "plain.csv");
    assert_ne!(from_job, plain);
    // --site overrides the job's site (the calibration still the job's).
    let (overridden, _) = replay(
        &["--job", s(&job), "--site", "45.77755", "126.687898", "124"],
        "override.csv",
    );
    let (expected, _) = replay(&["--calibration-file", s(&cal)], "expected.csv");
    assert_eq!(overridden, expected);
}

/// A job's still settings reach the replay's navigator: the defaults
/// written out give the same solutions as no settings (to the bit, as the
/// probe's parity check needs), a longer entering delay others. A
/// toolface turn after the 60 s alignment, then the still period whose
/// detection the delay shifts (the probe still through the alignment's end
/// is still from its first navigating cycle, whatever the delay).
#[test]
fn a_replay_takes_the_jobs_still_settings() {
    let dir = scratch("still");
    let capture = dir.join("run.bin");
    let simulate = [
        "simulate",
        "--motion",
        "toolface",
        "--dwell",
        "62",
        "--step",
        "90",
        "--duration",
        "127",
    ];
    ok(&[&simulate[..], &["-o", s(&capture)]].concat(), 0);
    let still = |epochs: u32| {
        format!(
            r#", "still": {{"z_enter": 3.09, "z_stay": 5.199, "enter_epochs": {epochs},
                "max_station_samples": 6000, "zupt_velocity_sigma": 0.01}}"#
        )
    };
    let replay = |job: &Path, name: &str| {
        let csv = dir.join(name);
        ok(
            &["replay", s(&capture), "--job", s(job), "--csv", s(&csv)],
            0,
        );
        std::fs::read_to_string(&csv).unwrap()
    };
    let plain = replay(&write_job(&dir, "plain.json", "{}", ""), "plain.csv");
    let defaults = replay(
        &write_job(&dir, "defaults.json", "{}", &still(20)),
        "defaults.csv",
    );
    assert_eq!(plain, defaults);
    let slower = replay(
        &write_job(&dir, "slower.json", "{}", &still(60)),
        "slower.csv",
    );
    assert_ne!(plain, slower);
}
