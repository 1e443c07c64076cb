//! `host-sim drill`: the example job run from another directory, end to
//! end (capture, depth log, survey with the bit, outputs, the summary
//! against the truth); `survey CAPTURE --job` of its capture lists the
//! same survey and writes the same exports; jobs that cannot run are
//! refused by name.
mod common;

use common::{refused, run, s, scratch};
use std::path::{Path, PathBuf};
use std::process::Command;

fn example_job() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/lateral-100m/job.json")
}

#[test]
fn the_example_job_runs_from_another_directory_and_surveys_to_the_bit() {
    let dir = scratch("drill", "example");
    let out = Command::new(env!("CARGO_BIN_EXE_host-sim"))
        .current_dir(&dir)
        .args(["drill", "--job", s(&example_job()), "--out", "run"])
        .output()
        .expect("host-sim runs");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{stdout}\n{stderr}");
    let run_dir = dir.join("run");
    for name in [
        "capture.bin",
        "depth.csv",
        "truth.csv",
        "stations.csv",
        "listing.txt",
        "survey.json",
        "trajectory.xml",
        "plan.svg",
        "plan.png",
        "section.svg",
        "section.png",
    ] {
        assert!(run_dir.join(name).is_file(), "{name} missing: {stdout}");
    }
    // the probe ran with the job's calibration: its stations replay bit
    // for bit with it, so the survey has the stations' links
    assert!(
        stdout.contains("station links: from the capture's replay"),
        "{stdout}"
    );
    assert!(stdout.contains("calibrated by"), "{stdout}");
    assert!(!stdout.contains("UNCALIBRATED"), "{stdout}");
    assert!(stdout.contains("positioned beyond the tie-on"), "{stdout}");
    let bit_line = stdout
        .lines()
        .find(|l| l.starts_with("bit at TD"))
        .unwrap_or_else(|| panic!("no bit line: {stdout}"));
    assert!(
        bit_line.contains("95 % ellipse") && bit_line.contains("off the truth by"),
        "{bit_line}"
    );
    // The bit: TD is the depth log's end plus 12 m, ahead of the last station.
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(run_dir.join("survey.json")).unwrap())
            .unwrap();
    let stations = json["stations"].as_array().unwrap();
    assert!(
        stations.iter().all(|st| st["qc"]["result"].is_string()),
        "every exported station carries its QC"
    );
    let last_md = stations.last().unwrap()["md_m"].as_f64().unwrap();
    let bit = &json["bit_projection"];
    let bit_md = bit["md_m"].as_f64().unwrap();
    assert!(bit_md > last_md + 12.0, "{bit_md} after {last_md}");
    let cov = bit["nev_covariance_m2"].as_array().unwrap();
    assert_eq!(cov.len(), 6);
    let last_cov = stations.last().unwrap()["nev_covariance_m2"][0]
        .as_f64()
        .unwrap();
    assert!(
        cov[0].as_f64().unwrap() > last_cov,
        "the bit is less certain"
    );
    let csv = std::fs::read_to_string(run_dir.join("stations.csv")).unwrap();
    assert!(csv.lines().last().unwrap().starts_with("bit,,"), "{csv}");
    // every station checked against the site's gravity and earth rate,
    // each gravity within a few mg of the site's (a still, calibrated probe)
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let (qc, error) = (col("qc"), col("gravity_error_m_s2"));
    for line in csv.lines().skip(1).filter(|l| !l.starts_with("bit")) {
        let cells: Vec<&str> = line.split(',').collect();
        assert_ne!(cells[qc], "not checked", "{line}");
        let e: f64 = cells[error].parse().unwrap();
        assert!(e.abs() < 0.1, "{line}");
    }
    let listing_text = std::fs::read_to_string(run_dir.join("listing.txt")).unwrap();
    assert!(
        listing_text.contains("station QC:")
            && listing_text.contains("stations checked out of tolerance"),
        "{listing_text}"
    );

    // The same capture surveyed by `survey CAPTURE --job`: the same listing,
    // and the station-file survey's exports.
    let (json_out, witsml_out, plots) = (dir.join("s.json"), dir.join("s.xml"), dir.join("plots"));
    let surveyed = run(&[
        "survey",
        s(&run_dir.join("capture.bin")),
        "--depth",
        s(&run_dir.join("depth.csv")),
        "--job",
        s(&example_job()),
        "--json",
        s(&json_out),
        "--witsml",
        s(&witsml_out),
        "--plot",
        s(&plots),
    ]);
    assert_eq!(surveyed.code, Some(0), "{}", surveyed.stderr);
    let listing = std::fs::read_to_string(run_dir.join("listing.txt")).unwrap();
    assert!(
        surveyed.stdout.starts_with(&listing),
        "{}\n---\n{listing}",
        surveyed.stdout
    );
    assert_eq!(
        std::fs::read(&json_out).unwrap(),
        std::fs::read(run_dir.join("survey.json")).unwrap()
    );
    assert!(std::fs::read_to_string(&witsml_out)
        .unwrap()
        .contains("<trajectoryStation"));
    assert!(plots.join("plan.png").is_file());

    // A 200 s hole in the depth log around station 2: that station alone
    // flagged in the listing, the CSV, the JSON and the WITSML.
    let time = col("time_s");
    let station_2 = csv.lines().nth(2).unwrap().split(',').collect::<Vec<_>>()[time]
        .parse::<f64>()
        .unwrap();
    let log = std::fs::read_to_string(run_dir.join("depth.csv")).unwrap();
    let holed: String = log
        .lines()
        .filter(|l| {
            l.split(',')
                .next()
                .and_then(|t| t.parse::<f64>().ok())
                .is_none_or(|t| (t - station_2).abs() > 100.0)
        })
        .map(|l| format!("{l}\n"))
        .collect();
    let holed_log = dir.join("holed.csv");
    std::fs::write(&holed_log, holed).unwrap();
    let (csv_out, json_out, witsml_out) =
        (dir.join("h.csv"), dir.join("h.json"), dir.join("h.xml"));
    let survey_holed = |limit: &str| {
        run(&[
            "survey",
            s(&run_dir.join("capture.bin")),
            "--depth",
            s(&holed_log),
            "--job",
            s(&example_job()),
            "--depth-gap-limit",
            limit,
            "--csv",
            s(&csv_out),
            "--json",
            s(&json_out),
            "--witsml",
            s(&witsml_out),
        ])
    };
    let flagged = survey_holed("30");
    assert_eq!(flagged.code, Some(0), "{}", flagged.stderr);
    let gap = "depth interpolated across a gap";
    let flagged_lines: Vec<&str> = flagged
        .stdout
        .lines()
        .filter(|l| l.ends_with(gap))
        .collect();
    assert_eq!(flagged_lines.len(), 1, "{}", flagged.stdout);
    assert!(
        flagged_lines[0].trim_start().starts_with("2 "),
        "{}",
        flagged.stdout
    );
    assert!(
        flagged.stdout.contains(&format!("{gap}: station 2 (")),
        "{}",
        flagged.stdout
    );
    let csv_text = std::fs::read_to_string(&csv_out).unwrap();
    let flags: Vec<&str> = csv_text
        .lines()
        .skip(1)
        .map(|l| l.rsplit(',').next().unwrap())
        .collect();
    assert_eq!(flags.iter().filter(|f| **f == gap).count(), 1, "{csv_text}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json_out).unwrap()).unwrap();
    let with_flag: Vec<usize> = json["stations"]
        .as_array()
        .unwrap()
        .iter()
        .enumerate()
        .filter(|(_, st)| st["flags"] == serde_json::json!([gap]))
        .map(|(k, _)| k)
        .collect();
    assert_eq!(with_flag.len(), 1, "{json}");
    let witsml = std::fs::read_to_string(&witsml_out).unwrap();
    assert_eq!(
        witsml
            .matches(&format!("<comments>{gap}</comments>"))
            .count(),
        1
    );
    // A limit longer than the hole: no flag anywhere.
    let unflagged = survey_holed("1000");
    assert_eq!(unflagged.code, Some(0), "{}", unflagged.stderr);
    assert!(!unflagged.stdout.contains(gap), "{}", unflagged.stdout);
    assert!(!std::fs::read_to_string(&csv_out).unwrap().contains(gap));
}

#[test]
fn a_job_that_cannot_be_drilled_is_refused_by_name() {
    let dir = scratch("drill", "refused");
    let job = std::fs::read_to_string(example_job()).unwrap();
    let write = |name: &str, text: &str| {
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        path
    };
    // no plan; a plan that is not there (paths are the job file's folder's)
    let no_plan = write(
        "no-plan.json",
        &job.replace(
            "\"plan\": \"../../host-sim/data/plans/lateral-100m.json\",",
            "",
        )
        .replace("\"calibration_file\": \"probe-cal.json\",", ""),
    );
    let out = dir.join("out");
    refused(
        &run(&["drill", "--job", s(&no_plan), "--out", s(&out)]),
        "names no plan",
    );
    let missing = write(
        "missing-plan.json",
        &job.replace(
            "../../host-sim/data/plans/lateral-100m.json",
            "nowhere.json",
        )
        .replace("\"calibration_file\": \"probe-cal.json\",", ""),
    );
    refused(
        &run(&["drill", "--job", s(&missing), "--out", s(&out)]),
        "nowhere.json",
    );
    let unknown = write("unknown.json", &job.replace("\"plan\"", "\"plann\""));
    refused(
        &run(&["drill", "--job", s(&unknown), "--out", s(&out)]),
        "plann",
    );
    assert!(!out.exists(), "nothing written for a refused job");
}

/// A job without a calibration: the probe's parts run with their
/// deterministic errors uncorrected, which its station sigmas (the
/// calibrated residual's) do not cover. The summary counts the flagged
/// stations, every output says so on top and flags every station.
#[test]
fn a_job_without_a_calibration_flags_every_station_uncalibrated() {
    let dir = scratch("drill", "uncalibrated");
    let job = std::fs::read_to_string(example_job())
        .unwrap()
        .replace("\"calibration_file\": \"probe-cal.json\",", "")
        .replace(
            "../../host-sim/data/plans/lateral-100m.json",
            s(&common::plan("qemu-short.json")),
        );
    assert!(!job.contains("calibration_file"), "{job}");
    let job_path = dir.join("job.json");
    std::fs::write(&job_path, job).unwrap();
    let run_dir = dir.join("run");
    let out = run(&["drill", "--job", s(&job_path), "--out", s(&run_dir)]);
    assert_eq!(out.code, Some(0), "{}\n{}", out.stdout, out.stderr);
    assert!(out
        .stdout
        .contains("uncalibrated (the job has no calibration file)"));
    let listing = std::fs::read_to_string(run_dir.join("listing.txt")).unwrap();
    assert!(listing.starts_with("UNCALIBRATED: "), "{listing}");
    // every station's line (and the bit's) ends with the flag
    let lines: Vec<&str> = listing
        .lines()
        .filter(|l| {
            // a station's or the bit's row: its angles have sigmas
            let first = l.split_whitespace().next().unwrap_or("");
            (first == "bit" || first.parse::<u16>().is_ok()) && l.contains("+-")
        })
        .collect();
    assert!(lines.len() >= 3, "{listing}");
    for l in &lines {
        assert!(l.ends_with("  uncalibrated"), "{l}");
    }
    let stations = lines.len() - 1;
    assert!(
        out.stdout.contains(&format!(
            "UNCALIBRATED: {stations} of {stations} stations flagged \"uncalibrated\""
        )),
        "{}",
        out.stdout
    );
    let csv = std::fs::read_to_string(run_dir.join("stations.csv")).unwrap();
    let mut rows = csv.lines();
    assert!(rows.next().unwrap().ends_with(",flag"), "{csv}");
    assert!(rows.all(|r| r.ends_with(",uncalibrated")), "{csv}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(run_dir.join("survey.json")).unwrap())
            .unwrap();
    assert!(json["uncalibrated_note"]
        .as_str()
        .is_some_and(|n| n.starts_with("UNCALIBRATED: ")));
    let positioned = json["stations"].as_array().unwrap();
    assert!(!positioned.is_empty(), "{json}");
    for st in positioned {
        assert_eq!(st["flags"], serde_json::json!(["uncalibrated"]), "{st}");
    }
    let xml = std::fs::read_to_string(run_dir.join("trajectory.xml")).unwrap();
    assert_eq!(
        xml.matches("<comments>uncalibrated</comments>").count(),
        positioned.len(),
        "{xml}"
    );
    assert!(xml.contains("<comments>UNCALIBRATED: "), "{xml}");
}
