//! `study drilling-coverage --shard K/N` and `study merge`: a small
//! coverage study run in 4 shards and merged prints the same table and
//! writes the same JSON as the study in one process, byte for byte once
//! the wall time is set aside; the merge refuses a missing or repeated
//! shard, a shard of another configuration, a shard of another study
//! among them and the lateral study's outputs.
mod common;

use common::{plan, read, refused, run, s, scratch, succeeded};
use std::path::Path;

/// The table without its wall time (the only figure two processes of one
/// study print differently).
fn untimed_text(text: &str) -> String {
    text.lines()
        .filter(|l| !l.starts_with("wall time"))
        .collect::<Vec<_>>()
        .join("\n")
}

/// Pretty JSON without its wall time (one key a line).
fn untimed_json(text: &str) -> String {
    text.lines()
        .filter(|l| !l.trim_start().starts_with("\"wall_s\":"))
        .collect::<Vec<_>>()
        .join("\n")
}

/// The 100 m lateral drilled fast (500 m/h, 2 min connections): a run in
/// seconds.
fn fast_plan(dir: &Path) -> String {
    let mut p: serde_json::Value =
        serde_json::from_str(&read(&plan("lateral-100m.json"))).expect("a plan is JSON");
    p["drilling"]["rop_m_per_h"] = 500.0.into();
    p["drilling"]["connection_still_s"] = 120.0.into();
    let path = dir.join("fast-100m.json");
    std::fs::write(&path, p.to_string()).expect("written");
    s(&path).to_string()
}

#[test]
fn four_coverage_shards_merged_equal_the_study_in_one_process() {
    let dir = scratch("coverage-shards", "merge");
    let study: Vec<String> = [
        "study",
        "drilling-coverage",
        "--plan",
        &fast_plan(&dir),
        "--runs",
        "4",
        "--first-seed",
        "5",
        "--scalar",
        "f64",
    ]
    .map(String::from)
    .to_vec();
    let threads = |n: usize| vec!["--threads".to_string(), n.to_string()];
    let single_json = dir.join("single.json");
    let one = succeeded(
        &[
            study.clone(),
            threads(2),
            vec!["--json".into(), s(&single_json).into()],
        ]
        .concat(),
    );
    let shard = |k: usize| dir.join(format!("shard-{k}.json"));
    for k in 1..=4 {
        // a shard's threads are its own: they change no result (the
        // merge reports the largest, 2, as the single process)
        let mut args = [study.clone(), threads(1 + k % 2)].concat();
        args.extend([
            "--shard".into(),
            format!("{k}/4"),
            "--shard-file".into(),
            s(&shard(k)).into(),
        ]);
        let out = succeeded(&args);
        let said = format!("drilling coverage shard {k}/4: 1 of the study's 4 runs");
        assert!(out.stdout.contains(&said), "{}", out.stdout);
    }
    let merge = |ks: &[usize]| -> Vec<String> {
        let mut a: Vec<String> = vec!["study".into(), "merge".into()];
        a.extend(ks.iter().map(|&k| s(&shard(k)).to_string()));
        a
    };
    let merged_json = dir.join("merged.json");
    let together = succeeded(
        &[
            merge(&[3, 1, 4, 2]),
            vec!["--json".into(), s(&merged_json).into()],
        ]
        .concat(),
    );
    assert!(
        together.stdout.starts_with("drilling coverage: "),
        "{}",
        together.stdout
    );
    assert_eq!(untimed_text(&together.stdout), untimed_text(&one.stdout));
    assert_eq!(
        untimed_json(&read(&merged_json)),
        untimed_json(&read(&single_json))
    );

    // refusals: a shard missing, one given twice, one of another
    // configuration, one of another study, the lateral study's outputs
    let attempt = |a: Vec<String>| run(&a.iter().map(String::as_str).collect::<Vec<_>>());
    refused(&attempt(merge(&[1, 2, 4])), "shard 3/4 missing");
    refused(&attempt(merge(&[1, 2, 2, 3, 4])), "shard 2/4 given twice");
    let mut other: serde_json::Value =
        serde_json::from_str(&read(&shard(2))).expect("a shard is JSON");
    other["configuration"]["uncalibrated"] = true.into();
    let other_path = dir.join("uncalibrated.json");
    std::fs::write(&other_path, other.to_string()).expect("written");
    let mut a = merge(&[1, 3, 4]);
    a.push(s(&other_path).into());
    let out = attempt(a);
    refused(&out, "is a shard of another study");
    refused(&out, "uncalibrated");
    let lateral = dir.join("lateral-shard.json");
    std::fs::write(
        &lateral,
        r#"{"format": "host-sim lateral study shard", "version": 2}"#,
    )
    .expect("written");
    let mut a = merge(&[1, 2, 3, 4]);
    a.push(s(&lateral).into());
    let out = attempt(a);
    refused(
        &out,
        "lateral-shard.json is not a drilling-coverage study shard",
    );
    refused(&out, "\"host-sim lateral study shard\"");
    let mut a = merge(&[1, 2, 3, 4]);
    a.extend(["--csv".into(), s(&dir.join("x.csv")).into()]);
    refused(
        &attempt(a),
        "--csv: a drilling-coverage study writes its table and --json only",
    );
    assert!(!dir.join("x.csv").exists());

    let help = run(&["study", "drilling-coverage", "--help"]);
    assert!(help.stdout.contains("--shard <K/N>"), "{}", help.stdout);
    let _ = std::fs::remove_dir_all(&dir);
}
