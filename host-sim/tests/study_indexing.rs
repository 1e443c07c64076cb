//! `host-sim study indexing`: the table per grade and number of dwells,
//! its JSON, and the refusals.

mod common;
use common::{read, run, succeeded};

#[test]
fn the_table_gives_each_grade_and_indexing_and_the_json_the_same_runs() {
    let dir = std::env::temp_dir().join(format!("study-indexing-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let json = dir.join("indexing.json");
    let args = [
        "study",
        "indexing",
        "--runs",
        "4",
        "--first-seed",
        "5",
        "--threads",
        "1",
        "--grades",
        "scc1300,navigation",
        "--dwells",
        "1,2",
        "--json",
    ]
    .map(String::from)
    .into_iter()
    .chain([json.display().to_string()])
    .collect::<Vec<_>>();
    let out = succeeded(&args);
    let rows: Vec<&str> = out
        .stdout
        .lines()
        .filter(|l| l.starts_with("scc1300") || l.starts_with("navigation"))
        .collect();
    assert_eq!(rows.len(), 4, "{}", out.stdout);
    // A 300 s station of the SCC1300 finds no azimuth, indexed or not: no
    // number is printed for it.
    for row in &rows[..2] {
        assert!(row.contains(" 0/4 ") && row.contains(" - "), "{row}");
    }
    // A navigation-grade gyro finds it in every run.
    for row in &rows[2..] {
        assert!(row.contains(" 4/4 "), "{row}");
    }
    let summaries: serde_json::Value = serde_json::from_str(&read(&json)).unwrap();
    let list = summaries.as_array().unwrap();
    assert_eq!(list.len(), 4);
    assert_eq!(list[3]["positions"], 2);
    assert_eq!(list[3]["determined"], 4);
    assert!(list[0]["azimuth_rms_deg"].is_null());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn dwells_and_still_times_out_of_range_are_refused() {
    for bad in [
        ["--dwells", "7"],
        ["--dwells", "0"],
        ["--still-s", "5"],
        ["--inclination-deg", "181"],
        ["--grades", "no-such-grade"],
    ] {
        let mut args = vec!["study", "indexing", "--runs", "1"];
        args.extend(bad);
        let out = run(&args);
        assert_eq!(out.code, Some(1), "{bad:?}: {}", out.stderr);
        assert!(!out.stderr.is_empty() && out.stdout.is_empty(), "{bad:?}");
    }
}
