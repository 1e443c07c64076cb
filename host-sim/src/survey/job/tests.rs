//! The job file's reading and checks.

use super::*;

const JOB: &str = r#"{"format": "mwd-job", "version": 1,
    "site": {"latitude_deg": 30.0, "longitude_deg": 270.0, "height_m": 12.5},
    "tie_in": {"inclination_deg": 88.0, "azimuth_deg": 271.0, "toolface_deg": 15.0,
               "inclination_sigma_deg": 0.1, "azimuth_sigma_deg": 1.5,
               "toolface_sigma_deg": 0.3}}"#;

#[test]
fn a_job_becomes_the_commands_that_configure_the_probe() {
    let job = Job::parse(JOB, Path::new(".")).unwrap();
    assert_eq!(job.site, Position::from_degrees(30.0, -90.0, 12.5));
    let commands = job.commands();
    assert_eq!(commands.len(), 4);
    assert!(matches!(commands[1].1, Command::SetTieIn { .. }));
    assert!(
        commands[1].0.contains("271.000 +- 1.500 deg"),
        "{}",
        commands[1].0
    );
    assert_eq!(
        commands[3].1,
        Command::SetCalibration {
            part: 1,
            accel: Default::default(),
            gyro: Default::default()
        }
    );
}

#[test]
fn bad_jobs_are_refused_with_the_reason() {
    let refused = |text: &str, needle: &str| {
        let e = format!("{:#}", Job::parse(text, Path::new(".")).unwrap_err());
        assert!(e.contains(needle), "{e}");
    };
    refused(&JOB.replace("88.0", "0.5"), "vertical");
    refused(
        &JOB.replace("\"height_m\": 12.5", "\"height_m\": 1e9"),
        "height",
    );
    refused(&JOB.replace("mwd-job", "other"), "version 1");
    refused(&JOB.replace("\"site\"", "\"sight\""), "mwd-job v1");
    refused(
        &JOB.replace("}}", "}, \"calibration_file\": \"/nonexistent/cal.json\"}"),
        "cal.json",
    );
    let with_survey = |survey: &str| JOB.replace("}}", &format!("}}, \"survey\": {survey}}}"));
    refused(&with_survey(r#"{"length_unit": "yd"}"#), "\"yd\"");
    refused(&with_survey(r#"{"tie_on": {"md": 1e7}}"#), "tie_on.md");
    refused(
        &with_survey(r#"{"error_model": "NOPE"}"#),
        "unknown error model",
    );
    refused(&with_survey(r#"{"tie_on": {"mdd": 1}}"#), "mdd");
}

const STILL: &str = r#"{"z_enter": 3.5, "z_stay": 6.0, "enter_epochs": 40,
    "max_station_samples": 1200, "zupt_velocity_sigma": 0.02}"#;

fn with_still(still: &str) -> String {
    JOB.replace("}}", &format!("}}, \"still\": {still}}}"))
}

#[test]
fn a_jobs_still_settings_are_sent_last_and_only_if_given() {
    let job = Job::parse(&with_still(STILL), Path::new(".")).unwrap();
    let expected = StillSettings {
        z_enter: 3.5,
        z_stay: 6.0,
        enter_epochs: 40,
        max_station_samples: 1200,
        zupt_velocity_sigma: 0.02,
    };
    assert_eq!(job.still, Some(expected));
    let commands = job.commands();
    assert_eq!(commands.len(), 5);
    let (label, command) = &commands[4];
    assert_eq!(*command, Command::SetStillSettings(expected));
    assert!(label.contains("enter_epochs 40"), "{label}");
    let plain = Job::parse(JOB, Path::new(".")).unwrap();
    assert_eq!(plain.still, None);
    assert!(plain
        .commands()
        .iter()
        .all(|(_, c)| !matches!(c, Command::SetStillSettings(_))));
}

#[test]
fn still_settings_out_of_the_probes_ranges_are_refused_by_name() {
    let refused = |from: &str, to: &str, needle: &str| {
        let text = with_still(&STILL.replace(from, to));
        let e = format!("{:#}", Job::parse(&text, Path::new(".")).unwrap_err());
        assert!(e.contains(needle), "{from} -> {to}: {e}");
    };
    refused(
        "\"z_enter\": 3.5",
        "\"z_enter\": 1.5",
        "still entering quantile",
    );
    // Staying must be easier than entering.
    refused(
        "\"z_stay\": 6.0",
        "\"z_stay\": 3.0",
        "still staying quantile",
    );
    refused(
        "\"enter_epochs\": 40",
        "\"enter_epochs\": 0",
        "still entering epochs",
    );
    refused(
        "\"enter_epochs\": 40",
        "\"enter_epochs\": 70000",
        "still entering epochs",
    );
    refused("1200", "-5", "longest station");
    refused("1200", "5000000000", "longest station");
    refused("1200", "100", "longest station");
    refused("0.02", "2.0", "station ZUPT velocity sigma");
    refused("0.02", "-0.02", "station ZUPT velocity sigma");
    refused(", \"zupt_velocity_sigma\": 0.02", "", "zupt_velocity_sigma");
    refused("\"z_enter\"", "\"z_entre\"", "z_entre");
    refused("3.5", "\"3.5\"", "expected f64");
}

#[test]
fn the_survey_part_is_read_in_its_unit_and_converted() {
    let job = Job::parse(
        &JOB.replace(
            "}}",
            r#"}, "survey": {"length_unit": "ft", "error_model": "gyro-mwd",
                  "tie_on": {"md": 1000.0, "north": -10.0}}}"#,
        ),
        Path::new("."),
    )
    .unwrap();
    let t = job.survey.tie_on;
    assert_eq!(
        (t.unit, t.md, t.north),
        (LengthUnit::Foot, Some(1000.0), Some(-10.0))
    );
    assert_eq!((t.tvd, t.east), (None, None));
    let m = t.in_unit(LengthUnit::Metre);
    assert!((m.md.unwrap() - 304.8).abs() < 1e-12, "{m:?}");
    assert!((m.north.unwrap() + 3.048).abs() < 1e-12, "{m:?}");
    assert_eq!(t.in_unit(LengthUnit::Foot), t);
    assert_eq!(job.survey.error_model.as_deref(), Some("gyro-mwd"));
    let plain = Job::parse(JOB, Path::new(".")).unwrap();
    assert_eq!(plain.survey, SurveyJob::default());
}

fn with_tie_on(tie_on: &str) -> String {
    JOB.replace(
        "}}",
        &format!(r#"}}, "survey": {{"length_unit": "ft", "tie_on": {tie_on}}}}}"#),
    )
}

#[test]
fn the_tie_ons_uncertainty_is_read_as_sigmas_or_a_covariance_and_converted() {
    let job = Job::parse(
        &with_tie_on(r#"{"md": 1000.0, "sigma": {"north": 10.0, "east": 5.0, "tvd": 2.0}}"#),
        Path::new("."),
    )
    .unwrap();
    // [nn, ee, vv, ne, nv, ev] in ft^2
    assert_eq!(
        job.survey.tie_on.covariance,
        Some([100.0, 25.0, 4.0, 0.0, 0.0, 0.0])
    );
    let m = job
        .survey
        .tie_on
        .in_unit(LengthUnit::Metre)
        .covariance
        .unwrap();
    let ft2 = 0.3048f64.powi(2);
    for (got, want) in m.iter().zip([100.0, 25.0, 4.0, 0.0, 0.0, 0.0]) {
        assert!((got - want * ft2).abs() < 1e-12, "{m:?}");
    }
    let full = Job::parse(
        &with_tie_on(
            r#"{"covariance": {"nn": 4.0, "ne": 1.0, "nv": 0.5, "ee": 2.0, "ev": -0.25, "vv": 1.0}}"#,
        ),
        Path::new("."),
    )
    .unwrap();
    assert_eq!(
        full.survey.tie_on.covariance,
        Some([4.0, 2.0, 1.0, 1.0, 0.5, -0.25])
    );
    let plain = Job::parse(&with_tie_on(r#"{"md": 1000.0}"#), Path::new(".")).unwrap();
    assert_eq!(plain.survey.tie_on.covariance, None);
}

#[test]
fn a_tie_on_uncertainty_that_is_not_one_is_refused_by_name() {
    let refused = |tie_on: &str, needle: &str| {
        let e = format!(
            "{:#}",
            Job::parse(&with_tie_on(tie_on), Path::new(".")).unwrap_err()
        );
        assert!(e.contains(needle), "{tie_on}: {e}");
    };
    refused(
        r#"{"sigma": {"north": -1.0, "east": 1.0, "tvd": 1.0}}"#,
        "sigma.north",
    );
    refused(r#"{"sigma": {"north": 1.0, "east": 1.0}}"#, "tvd");
    refused(
        r#"{"sigma": {"north": 1.0, "east": 1.0, "tvd": 1.0},
            "covariance": {"nn": 1.0, "ne": 0.0, "nv": 0.0, "ee": 1.0, "ev": 0.0, "vv": 1.0}}"#,
        "not both",
    );
    // |ne| > sqrt(nn ee): a direction with a negative variance
    refused(
        r#"{"covariance": {"nn": 1.0, "ne": 2.0, "nv": 0.0, "ee": 1.0, "ev": 0.0, "vv": 1.0}}"#,
        "not a covariance",
    );
    refused(
        r#"{"covariance": {"nn": 1e300, "ne": 0.0, "nv": 0.0, "ee": 1.0, "ev": 0.0, "vv": 1.0}}"#,
        "covariance.nn",
    );
}

#[test]
fn a_longitude_past_360_is_refused_not_wrapped() {
    let with_longitude = |deg: &str| {
        let text = JOB.replace(
            "\"longitude_deg\": 270.0",
            &format!("\"longitude_deg\": {deg}"),
        );
        assert_ne!(text, JOB);
        Job::parse(&text, Path::new("."))
    };
    let east = with_longitude("360").unwrap();
    assert_eq!(east.site, Position::from_degrees(30.0, 0.0, 12.5));
    for deg in ["400", "360.5", "1e300"] {
        let error = format!("{:#}", with_longitude(deg).unwrap_err());
        assert!(error.contains("longitude"), "{deg}: {error}");
    }
}
