//! One drilling capture with a tie-in job, through every place that turns
//! the probe's frames into surveyed stations: `survey CAPTURE --job` and
//! the dashboard list the same stations at the same MD and positions (from
//! the job's tie-on), with the same angle sigmas; and where both chain the
//! stations without the replay's links, the same position sigmas. (The
//! drilling studies collect their stations with the same
//! `survey::stations::StationCollector`, in process.)

mod common;

use std::collections::HashMap;

use common::{run, s, scratch, simulate_tied_in};
use host_sim::dashboard::state::{DashboardState, SourceInfo, LIMITS};
use host_sim::formats::capture::read_capture;
use host_sim::formats::depth_log::DepthLog;
use host_sim::survey::job::Job;
use host_sim::survey::stations::{job_tie_on, SurveySetup};
use serde_json::Value;

/// The rows of a CSV, by column name.
fn table(text: &str) -> Vec<HashMap<String, String>> {
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().expect("a header").split(',').collect();
    lines
        .map(|l| {
            header
                .iter()
                .zip(l.split(','))
                .map(|(k, v)| (k.to_string(), v.to_string()))
                .collect()
        })
        .collect()
}

/// "N 1.23 +- 0.05 m, E ..., TVD ..." as the dashboard writes a position.
fn position_text(row: &HashMap<String, String>) -> String {
    let n = |k: &str| row[k].parse::<f64>().expect(k);
    format!(
        "N {:.2} +- {:.2} m, E {:.2} +- {:.2} m, TVD {:.2} +- {:.2} m",
        n("north_m"),
        n("sigma_north_m"),
        n("east_m"),
        n("sigma_east_m"),
        n("tvd_m"),
        n("sigma_vert_m")
    )
}

/// Only the positions of `position_text`, without their sigmas.
fn without_sigmas(text: &str) -> String {
    text.split(", ")
        .map(|part| part.split(" +- ").next().unwrap_or(part).to_string())
        .collect::<Vec<_>>()
        .join(", ")
}

#[test]
fn the_capture_survey_and_the_dashboard_place_the_same_stations_from_the_job_tie_on() {
    let dir = scratch("station-collector", "tied-in");
    let (bin, depth, job) = simulate_tied_in(&dir);

    // The capture survey: with the job (the replay's links), and with the
    // same tie-on given by flags (no tie-in, so no links).
    let survey = |extra: &[&str], name: &str| {
        let csv = dir.join(name);
        let mut args = vec!["survey", s(&bin), "--depth", s(&depth), "--csv", s(&csv)];
        args.extend_from_slice(extra);
        let out = run(&args);
        assert_eq!(out.code, Some(0), "{}", out.stderr);
        table(&std::fs::read_to_string(&csv).unwrap())
    };
    let linked = survey(&["--job", s(&job)], "linked.csv");
    let unlinked = survey(
        &[
            "--tie-on-md",
            "3000",
            "--tie-on-tvd",
            "2450",
            "--tie-on-north",
            "420",
            "--tie-on-east",
            "310",
        ],
        "unlinked.csv",
    );
    assert!(linked.len() >= 2, "stations: {}", linked.len());

    // The dashboard, fed the same capture with the same job and depth log.
    let job_file = Job::load(&job).unwrap();
    let depth_log = DepthLog::read(std::fs::File::open(&depth).unwrap()).unwrap();
    let info = SourceInfo {
        description: "test".into(),
        controls_disabled: None,
        calibration: vec![],
        job: None,
        depth: Some(depth_log),
        survey: SurveySetup::probe(job_tie_on(Some(&job_file)), job_file.site.lat).unwrap(),
        well_plan: None,
    };
    let mut state = DashboardState::new(info, 1, LIMITS);
    for frame in &read_capture(&bin).unwrap().frames {
        state.push_frame(frame);
    }
    let snapshot: Value = serde_json::from_str(&state.update_json(None)).unwrap();
    let rows = snapshot["rest"]["stations"]["rows"].as_array().unwrap();
    let note = snapshot["rest"]["stations"]["note"].as_str().unwrap();
    assert!(note.contains("job's tie-on (MD 3000.00 m"), "{note}");

    // Every surveyed station, on the page at the same MD and position.
    let positioned: Vec<&Value> = rows.iter().filter(|r| r["md"].is_string()).collect();
    assert_eq!(positioned.len(), linked.len());
    for ((page, with_links), without_links) in positioned.iter().zip(&linked).zip(&unlinked) {
        assert_eq!(page["number"].to_string(), with_links["station"]);
        assert_eq!(
            page["md"],
            format!("{:.2} m", with_links["md_m"].parse::<f64>().unwrap())
        );
        let shown = page["position"].as_str().unwrap();
        assert_eq!(
            without_sigmas(shown),
            without_sigmas(&position_text(with_links))
        );
        assert_eq!(shown, position_text(without_links));
        let inc = with_links["inc_deg"].parse::<f64>().unwrap();
        let s_inc = with_links["sigma_inc_deg"].parse::<f64>().unwrap();
        let page_inc = page["inclination"].as_str().unwrap();
        assert_eq!(page_inc, format!("{inc:.3} +- {s_inc:.3} deg"));
    }
    // The first station sits at the job's tie-on, not at the surface.
    assert!(
        positioned[0]["position"]
            .as_str()
            .unwrap()
            .starts_with("N 420.00"),
        "{}",
        positioned[0]["position"]
    );
}
