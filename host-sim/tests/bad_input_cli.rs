//! Bad input through the binary:
//! every case fails with a short sentence naming what is wrong, never
//! with a panic (exit 101) or a silent success, and text tables with a
//! byte-order mark or a quoted header read as the plain ones do.

mod common;

use common::{run as host_sim, s, Run};
use std::path::{Path, PathBuf};

fn scratch(name: &str) -> PathBuf {
    common::scratch("bad-input-cli", name)
}

/// A refusal: exit 1 (the command line's too), an error containing `needle`, short.
fn refused(run: &Run, needle: &str) {
    assert!(
        matches!(run.code, Some(1)),
        "exit {:?}: {}",
        run.code,
        run.stderr
    );
    assert!(
        run.stderr.contains(needle),
        "{needle:?} not in: {}",
        run.stderr
    );
    assert!(
        run.stderr.len() < 2000,
        "long stderr: {} bytes",
        run.stderr.len()
    );
}

#[test]
fn arguments_off_the_earth_or_without_bound_are_refused() {
    let dir = scratch("args");
    let out = dir.join("x.csv");
    for (args, needle) in [
        (
            &["--lat", "95"][..],
            "latitude must be a finite number from -90 to 90",
        ),
        (&["--lat", "nan"], "latitude"),
        (
            &["--duration", "1e9"],
            "duration must be a finite number from 0 to 172800 s",
        ),
        (&["--duration", "0"], "more than 0 s"),
        (
            &["--motion", "rotate", "--body-rate", "0,3"],
            "three numbers",
        ),
        (
            &["--motion", "rotate", "--body-rate", "0,0,1e6"],
            "300 deg/s",
        ),
    ] {
        let mut all = vec!["simulate", "-o", s(&out)];
        all.extend_from_slice(args);
        refused(&host_sim(&all), needle);
        assert!(!out.exists(), "{args:?} wrote a file");
    }
    let run = host_sim(&["replay", "--site", "nan", "0", "0", "x.bin"]);
    refused(&run, "latitude");
    // The help's x,y,z form is taken.
    let ok = host_sim(&[
        "simulate",
        "--motion",
        "rotate",
        "--body-rate",
        "0,0,3",
        "--duration",
        "1",
        "-o",
        s(&out),
    ]);
    assert_eq!(ok.code, Some(0), "{}", ok.stderr);
}

#[test]
fn a_huge_line_is_refused_after_a_bounded_read_with_a_short_error() {
    let dir = scratch("long");
    let file = dir.join("one-line.csv");
    std::fs::write(&file, "1,".repeat(2 << 20)).unwrap();
    for cmd in [
        &["allan", s(&file), "--rate", "20"][..],
        &["arfit", s(&file), "--rate", "20"],
        &["calibrate", s(&file)],
        &["align", s(&file)],
    ] {
        refused(&host_sim(cmd), "longer than 65536 bytes");
    }
    let nul = dir.join("nul.csv");
    std::fs::write(&nul, vec![0u8; 1 << 20]).unwrap();
    refused(&host_sim(&["allan", s(&nul), "--rate", "20"]), "NUL byte");
}

/// `simulate`'s CSV with a byte-order mark and a quoted header.
fn bom_and_quoted(dir: &Path) -> PathBuf {
    let plain = dir.join("plain.csv");
    let run = host_sim(&["simulate", "--duration", "20", "-o", s(&plain)]);
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    let text = std::fs::read_to_string(&plain).unwrap();
    let (header, rest) = text.split_once('\n').unwrap();
    let quoted: Vec<String> = header.split(',').map(|n| format!("\"{n}\"")).collect();
    let odd = dir.join("bom-quoted.csv");
    std::fs::write(&odd, format!("\u{feff}{}\n{rest}", quoted.join(","))).unwrap();
    odd
}

#[test]
fn a_byte_order_mark_and_a_quoted_header_read_as_plain_csv() {
    let dir = scratch("bom");
    let odd = bom_and_quoted(&dir);
    let plain = dir.join("plain.csv");
    let a = host_sim(&["align", s(&plain)]);
    let b = host_sim(&["align", s(&odd)]);
    assert_eq!(b.code, Some(0), "{}", b.stderr);
    assert!(a.stdout == b.stdout, "the same alignment");
    let a = host_sim(&["allan", s(&plain), "--rate", "20", "--json", "--no-plot"]);
    let b = host_sim(&["allan", s(&odd), "--rate", "20", "--json", "--no-plot"]);
    assert_eq!(b.code, Some(0), "{}", b.stderr);
    let sensors = |json: &str| {
        let v: serde_json::Value = serde_json::from_str(json).unwrap();
        v["sensors"].clone()
    };
    let names = |v: &serde_json::Value| {
        let list = v.as_array().unwrap().iter();
        list.map(|s| s["name"].as_str().unwrap().to_string())
            .collect::<Vec<_>>()
    };
    let (plain, odd) = (sensors(&a.stdout), sensors(&b.stdout));
    assert_eq!(names(&odd), names(&plain), "time and truth are not sensors");
    assert!(plain == odd, "the same analysis");
}

/// Roll and pitch of `align`'s first segment row.
fn segment_roll_pitch(report: &str) -> (f64, f64) {
    let row = report
        .lines()
        .find(|l| l.starts_with("1 "))
        .unwrap_or_else(|| panic!("no segment row in {report}"));
    let numbers: Vec<f64> = row
        .split_whitespace()
        .filter_map(|w| w.parse().ok())
        .collect();
    // seg, roll, pitch (the time span and +- bounds are not plain numbers).
    (numbers[1], numbers[2])
}

#[test]
fn align_reads_the_probes_own_capture() {
    let dir = scratch("bin");
    let (bin, csv) = (dir.join("run.bin"), dir.join("run.csv"));
    for out in [&bin, &csv] {
        let run = host_sim(&["simulate", "--duration", "30", "-o", s(out)]);
        assert_eq!(run.code, Some(0), "{}", run.stderr);
    }
    let from_bin = host_sim(&["align", s(&bin)]);
    assert_eq!(from_bin.code, Some(0), "{}", from_bin.stderr);
    let from_csv = host_sim(&["align", s(&csv)]);
    let (rb, pb) = segment_roll_pitch(&from_bin.stdout);
    let (rc, pc) = segment_roll_pitch(&from_csv.stdout);
    // The capture holds the same samples quantised to sensor counts.
    assert!(
        (rb - rc).abs() < 0.01 && (pb - pc).abs() < 0.01,
        "{rb} {pb} vs {rc} {pc}"
    );
    let garbage = dir.join("garbage.bin");
    std::fs::write(&garbage, b"time_s,gyro\n1,2\n").unwrap();
    refused(
        &host_sim(&["align", s(&garbage)]),
        "no valid raw-sample frame",
    );
}

#[test]
fn huge_values_give_finite_deviations_or_a_clear_failure() {
    let dir = scratch("huge");
    let file = dir.join("huge.csv");
    let mut text = String::from("time_s,gyro_x_rad_s\n");
    for i in 0..400u32 {
        // 1e200 with a +-1e199 wobble: squares overflow, deviations do not.
        let wobble = f64::from((i * 7919) % 13) - 6.0;
        text += &format!("{},{:e}\n", f64::from(i) * 0.05, 1e200 + 1e199 * wobble);
    }
    std::fs::write(&file, text).unwrap();
    let run = host_sim(&["allan", s(&file), "--rate", "20", "--json", "--no-plot"]);
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    let v: serde_json::Value = serde_json::from_str(&run.stdout).unwrap();
    let oadev = v["sensors"][0]["points"][0]["oadev"].as_f64();
    assert!(
        oadev.is_some_and(|d| d.is_finite() && d > 1e198),
        "{oadev:?}"
    );
    let model = dir.join("huge.ar.json");
    let run = host_sim(&["arfit", s(&file), "--rate", "20", "--output", s(&model)]);
    refused(&run, "not a finite number");
    assert!(!model.exists(), "no model of NaNs written");
}

#[test]
fn a_huge_json_file_is_refused_unread() {
    let dir = scratch("json");
    let big = dir.join("big.cal.json");
    std::fs::write(&big, " ".repeat(2 << 20)).unwrap();
    let csv = dir.join("run.csv");
    let run = host_sim(&["simulate", "--duration", "2", "-o", s(&csv)]);
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    refused(
        &host_sim(&["align", s(&csv), "--calibration-file", s(&big)]),
        "more than the 1048576",
    );
}
