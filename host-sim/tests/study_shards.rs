//! `study lateral --shard K/N` and `study merge`: a small study run in 4
//! shards and merged writes the same table, JSON, CSV, station CSV and
//! plots as the study in one process, byte for byte once the timings
//! (wall and CPU times, speeds) are set aside; the merge refuses a missing
//! or repeated shard, a shard of another configuration and a file that is
//! not a shard.
mod common;

use common::{read, refused, run, s, scratch, succeeded};
use std::path::Path;

/// The JSON keys and CSV columns that hold a time or a speed: the only
/// fields in which two processes' outputs of the same study differ.
const TIMING_KEYS: [&str; 6] = [
    "wall_s",
    "run_wall_s",
    "run_cpu_s",
    "cpu_s",
    "epochs_per_core_second",
    "epochs_per_thread_wall_second",
];

/// The 100 m lateral drilled fast, one grade, two runs and a 2 x 2
/// sweep: 7 jobs of every kind (covariance analysis, Monte Carlo, sweep).
const STUDY: [&str; 16] = [
    "study",
    "lateral",
    "--well",
    "100m",
    "--grades",
    "scc1300",
    "--runs",
    "2",
    "--first-seed",
    "5",
    "--rop",
    "500",
    "--connection-still",
    "120",
    "--sweep",
    "2",
];

/// `--json`, `--csv`, `--stations-csv` and `--plots` into `dir`.
fn outputs(dir: &Path) -> Vec<String> {
    [
        ("--json", "study.json"),
        ("--csv", "study.csv"),
        ("--stations-csv", "stations.csv"),
        ("--plots", "plots"),
    ]
    .iter()
    .flat_map(|(flag, name)| [flag.to_string(), s(&dir.join(name)).to_string()])
    .collect()
}

/// The standard output without its timings: the first line's wall time,
/// the last column of the tables that end in a speed or a CPU time.
fn untimed_text(text: &str) -> String {
    let mut timing_table = false;
    let mut out = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let mut line = line.to_string();
        if n == 0 {
            let cut = line
                .rfind("; ")
                .expect("the first line ends in its wall time");
            line.truncate(cut);
        } else if line.ends_with("epochs/s/core (CPU)") || line.ends_with("CPU (s)") {
            timing_table = true;
        } else if line.trim().is_empty() {
            timing_table = false;
        } else if timing_table && !line.starts_with('-') {
            let cut = line.trim_end().rfind(' ').expect("a table row");
            line.truncate(cut);
            // the value's own width (its digits) pads the column before it
            line.truncate(line.trim_end().len());
        }
        out.push(line);
    }
    out.join("\n")
}

/// Pretty JSON without its timing values (one key a line).
fn untimed_json(text: &str) -> String {
    let timing = |line: &str| {
        TIMING_KEYS
            .iter()
            .any(|k| line.trim_start().starts_with(&format!("\"{k}\":")))
    };
    text.lines()
        .map(|l| if timing(l) { "<timing>" } else { l })
        .collect::<Vec<_>>()
        .join("\n")
}

/// A CSV without its timing columns' values.
fn untimed_csv(text: &str) -> String {
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().expect("a header").split(',').collect();
    let mut out = vec![header.join(",")];
    for line in lines {
        assert!(!line.contains('"'), "no quoted field in this study: {line}");
        let cells: Vec<&str> = line
            .split(',')
            .enumerate()
            .map(|(i, c)| {
                if TIMING_KEYS.contains(&header[i]) {
                    "<timing>"
                } else {
                    c
                }
            })
            .collect();
        out.push(cells.join(","));
    }
    out.join("\n")
}

#[test]
fn four_shards_merged_equal_the_study_in_one_process() {
    let dir = scratch("study-shards", "merge");
    let (single, merged) = (dir.join("single"), dir.join("merged"));
    for d in [&single, &merged] {
        std::fs::create_dir_all(d).expect("a scratch folder");
    }
    let study: Vec<String> = STUDY.iter().map(|a| a.to_string()).collect();
    let threads = |n: usize| vec!["--threads".to_string(), n.to_string()];
    let one = succeeded(&[study.clone(), threads(2), outputs(&single)].concat());
    let shard = |k: usize| dir.join(format!("shard-{k}.json"));
    for k in 1..=4 {
        // a shard's threads are its own: they change no result
        let mut shard_args = [study.clone(), threads(1 + k % 2)].concat();
        shard_args.extend([
            "--shard".into(),
            format!("{k}/4"),
            "--shard-file".into(),
            s(&shard(k)).into(),
        ]);
        let out = succeeded(&shard_args);
        let mine = if k < 4 { 2 } else { 1 };
        let said = format!("shard {k}/4: {mine} of the study's 7 jobs");
        assert!(out.stdout.contains(&said), "{}", out.stdout);
    }
    // any order
    let mut merge: Vec<String> = vec!["study".into(), "merge".into()];
    merge.extend([3, 1, 4, 2].map(|k| s(&shard(k)).to_string()));
    let together = succeeded(&[merge.clone(), outputs(&merged)].concat());

    // the figures' paths, which the plots' lines name, aside
    assert_eq!(
        untimed_text(&together.stdout.replace(s(&merged), "OUT")),
        untimed_text(&one.stdout.replace(s(&single), "OUT"))
    );
    assert_eq!(
        untimed_json(&read(&merged.join("study.json"))),
        untimed_json(&read(&single.join("study.json")))
    );
    assert_eq!(
        untimed_csv(&read(&merged.join("study.csv"))),
        untimed_csv(&read(&single.join("study.csv")))
    );
    // no timing in the station rows nor the plots: every byte
    assert_eq!(
        std::fs::read(merged.join("stations.csv")).expect("stations"),
        std::fs::read(single.join("stations.csv")).expect("stations")
    );
    let mut figures: Vec<_> = std::fs::read_dir(single.join("plots"))
        .expect("plots")
        .map(|e| e.expect("entry").file_name())
        .collect();
    figures.sort();
    assert!(figures.len() >= 4, "{figures:?}");
    for f in &figures {
        assert_eq!(
            std::fs::read(merged.join("plots").join(f)).expect("the merged figure"),
            std::fs::read(single.join("plots").join(f)).expect("the figure"),
            "{f:?}"
        );
    }

    // refusals: a shard missing, one given twice, one of another study,
    // a file that is no shard
    let names = |ks: &[usize]| -> Vec<String> {
        let mut a: Vec<String> = vec!["study".into(), "merge".into()];
        a.extend(ks.iter().map(|&k| s(&shard(k)).to_string()));
        a
    };
    let attempt = |a: Vec<String>| run(&a.iter().map(String::as_str).collect::<Vec<_>>());
    refused(&attempt(names(&[1, 2, 4])), "shard 3/4 missing");
    refused(&attempt(names(&[1, 2, 2, 3, 4])), "shard 2/4 given twice");
    let mut other: serde_json::Value =
        serde_json::from_str(&read(&shard(2))).expect("a shard is JSON");
    other["configuration"]["first_seed"] = 6.into();
    let other_path = dir.join("other-seed.json");
    std::fs::write(&other_path, other.to_string()).expect("written");
    let mut a = names(&[1, 3, 4]);
    a.push(s(&other_path).into());
    let out = attempt(a);
    refused(&out, "is a shard of another study");
    refused(&out, "first_seed");
    let mut a = names(&[1, 2, 3, 4]);
    a.push(s(&single.join("study.json")).into());
    refused(&attempt(a), "study.json is not a lateral study shard");

    let help = run(&["study", "lateral", "--help"]);
    assert!(help.stdout.contains("--shard <K/N>"), "{}", help.stdout);
    let _ = std::fs::remove_dir_all(&dir);
}
