//! `host-sim survey` streams a station file when only the listing and the
//! CSV are asked for (constant memory, `survey::streamed`), and holds it in
//! memory when a whole-survey output (JSON, WITSML, figures, an offset
//! well) is. The two must give the same bytes: the listing (less the
//! in-memory run's lines about the files it wrote) and the CSV, on ISCWSA
//! test well #1 under several models and options, and on a 10,001-station
//! well.

mod common;

use common::{s, well1, Run, WELL1_SITE};
use std::path::{Path, PathBuf};

fn survey(args: &[&str]) -> Run {
    common::run(&[&["survey"], args].concat())
}

fn scratch(name: &str) -> PathBuf {
    common::scratch("survey-streamed", name)
}

/// The listing and CSV of the streamed run and of the in-memory run (made
/// so by asking for `--json` too) of `stations` with `extra`.
fn both_ways(name: &str, stations: &Path, extra: &[&str]) -> [(String, Vec<u8>); 2] {
    let dir = scratch(name);
    let run = |csv: &Path, json: Option<&Path>| {
        let mut args = vec![s(stations), "--csv", s(csv)];
        args.extend_from_slice(extra);
        if let Some(j) = json {
            args.extend_from_slice(&["--json", s(j)]);
        }
        let r = survey(&args);
        assert_eq!(r.code, Some(0), "{name}: {}", r.stderr);
        (r.stdout, std::fs::read(csv).unwrap())
    };
    let streamed = run(&dir.join("streamed.csv"), None);
    let held = run(&dir.join("held.csv"), Some(&dir.join("held.json")));
    [streamed, held]
}

#[test]
fn the_streamed_survey_is_the_survey_held_in_memory() {
    let mwd: Vec<&str> = [&["--error-model", "ISCWSA MWD Rev5"][..], &WELL1_SITE].concat();
    let cases: Vec<(&str, Vec<&str>)> = vec![
        ("positions only", vec![]),
        ("mwd", mwd.clone()),
        // the model stops being valid beyond 89 deg: no covariance after
        (
            "gyro beyond its validity",
            vec!["--error-model", "GYRO-MWD", "--lat", "60"],
        ),
        (
            "tie-on with its sigma, feet, a section azimuth",
            [
                &mwd[..],
                &[
                    "--tie-on-north",
                    "100",
                    "--tie-on-east",
                    "-50",
                    "--tie-on-tvd",
                    "10",
                    "--tie-on-sigma",
                    "2",
                    "3",
                    "1",
                    "--units",
                    "ft",
                    "--vsec-azimuth-deg",
                    "30",
                ],
            ]
            .concat(),
        ),
    ];
    for (name, extra) in cases {
        let [(streamed_text, streamed_csv), (held_text, held_csv)] =
            both_ways(name, &well1(), &extra);
        assert!(streamed_csv.len() > 1000, "{name}");
        assert!(streamed_csv == held_csv, "{name}: the CSVs differ");
        assert_eq!(streamed_text, held_text, "{name}: the listings differ");
    }
    let [(_, gyro_csv), _] = both_ways(
        "gyro check",
        &well1(),
        &["--error-model", "GYRO-MWD", "--lat", "60"],
    );
    let text = String::from_utf8(gyro_csv).unwrap();
    assert!(text.contains(",false\n") && text.contains(",true\n"));
}

/// A 10,001-station well (a build, a turn and a long tangent, as a
/// lateral's station file would be) under the MWD model.
#[test]
fn ten_thousand_stations_stream_as_they_are_held() {
    let dir = scratch("10001");
    let path = dir.join("stations.csv");
    let mut text = String::from("md_m,inc_deg,azi_deg\n");
    for k in 0..=10_000u32 {
        // 1 m apart: 10 km, within the 20,000 m a station file may reach
        let md = f64::from(k);
        let inc = (f64::from(k) * 0.05).min(88.0);
        let azi = (30.0 + f64::from(k) * 0.05).rem_euclid(360.0);
        text += &format!("{md},{inc},{azi}\n");
    }
    std::fs::write(&path, text).unwrap();
    let [(streamed_text, streamed_csv), (held_text, held_csv)] = both_ways(
        "10001",
        &path,
        &[&["--error-model", "ISCWSA MWD Rev5"][..], &WELL1_SITE].concat(),
    );
    assert_eq!(streamed_text.lines().count(), 10_001 + 4);
    assert!(streamed_csv == held_csv, "the CSVs differ");
    assert!(streamed_text == held_text, "the listings differ");
}
