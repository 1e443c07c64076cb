//! The `simulate` and `align` subcommands end to end, as an engineer runs
//! them: write a CSV, align it, read the printed result.
use std::process::Command;

fn host_sim(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_host-sim"))
        .args(args)
        .output()
        .expect("host-sim runs");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn temp_path(name: &str) -> std::path::PathBuf {
    std::env::temp_dir().join(format!("host-sim-{}-{name}", std::process::id()))
}

/// The azimuth printed on the first heading line of `align`.
fn printed_azimuth(stdout: &str) -> f64 {
    let line = stdout
        .lines()
        .find(|l| l.trim_start().starts_with("azimuth"))
        .expect("an azimuth line");
    line.split_whitespace()
        .nth(1)
        .and_then(|v| v.trim_end_matches(',').parse().ok())
        .expect("a number after `azimuth`")
}

#[test]
fn noise_free_simulation_aligns_to_the_truth() {
    let csv = temp_path("ideal.csv");
    let path = csv.to_str().expect("utf-8 temp path");
    let (ok, _, err) = host_sim(&[
        "simulate",
        "--sensor",
        "ideal",
        "--roll",
        "30",
        "--pitch",
        "10",
        "--heading",
        "20",
        "--duration",
        "10",
        "-o",
        path,
    ]);
    assert!(ok, "simulate failed: {err}");
    let (ok, out, err) = host_sim(&[
        "align",
        path,
        "--calibration",
        "none",
        "--noise-free",
        "--prior-heading",
        "40",
    ]);
    assert!(ok, "align failed: {err}");
    let azimuth = printed_azimuth(&out);
    assert!((azimuth - 20.0).abs() < 1e-3, "azimuth {azimuth}\n{out}");
    assert!(out.contains("30.0000"), "roll not printed as 30:\n{out}");
    let _ = std::fs::remove_file(csv);
}

#[test]
fn align_rejects_a_file_that_is_not_a_sample_csv() {
    let bad = temp_path("bad.csv");
    std::fs::write(&bad, "hello,world\n1,2\n").expect("write temp file");
    let (ok, _, err) = host_sim(&["align", bad.to_str().expect("utf-8")]);
    assert!(!ok);
    assert!(err.contains("not a probe sample CSV"), "{err}");
    let (ok, _, err) = host_sim(&["align", "/nonexistent/file.csv"]);
    assert!(!ok && err.contains("opening"), "{err}");
    let _ = std::fs::remove_file(bad);
}

#[test]
fn demo_prints_the_alignment_next_to_the_truth() {
    let (ok, out, err) = host_sim(&["demo"]);
    assert!(ok, "demo failed: {err}");
    assert!(out.contains("first 5 s") && out.contains("Toolface indexing"));
    assert!(out.contains("truth"));
}

#[test]
fn a_sensor_model_file_round_trips_through_simulate_and_align() {
    let (ok, json, err) = host_sim(&["simulate", "--print-sensor-model"]);
    assert!(ok, "{err}");
    // A quieter sensor: no noise at all, but the paper's deterministic
    // biases, removed again by `--calibration model`.
    let quiet = json
        .replace("\"quantize\": true", "\"quantize\": false")
        .replace(
            "\"arw_deg_per_sqrt_h\": 0.86",
            "\"arw_deg_per_sqrt_h\": 0.0",
        );
    let model = temp_path("model.json");
    std::fs::write(&model, quiet).expect("write model");
    let csv = temp_path("model.csv");
    let (m, c) = (model.to_str().expect("utf-8"), csv.to_str().expect("utf-8"));
    let (ok, _, err) = host_sim(&["simulate", "--sensor-model", m, "--duration", "5", "-o", c]);
    assert!(ok, "{err}");
    let (ok, out, err) = host_sim(&["align", c, "--sensor-model", m, "--calibration", "model"]);
    assert!(ok, "{err}\n{out}");
    assert!(out.contains("truth"));
    let broken = temp_path("broken.json");
    std::fs::write(&broken, "{\"gyro\": 1}").expect("write");
    let (ok, _, err) = host_sim(&[
        "simulate",
        "--sensor-model",
        broken.to_str().expect("utf-8"),
        "-o",
        c,
    ]);
    assert!(!ok && err.contains("not a sensor model JSON"), "{err}");
    for f in [model, csv, broken] {
        let _ = std::fs::remove_file(f);
    }
}

#[test]
fn simulate_writes_a_binary_capture_that_decodes_cleanly() {
    let bin = temp_path("capture.bin");
    let path = bin.to_str().expect("utf-8");
    let (ok, _, err) = host_sim(&["simulate", "--duration", "5", "-o", path]);
    assert!(ok, "{err}");
    let bytes = std::fs::read(&bin).expect("capture written");
    // 100 raw-sample frames of 51 bytes on the wire (docs/protocol.md).
    assert_eq!(bytes.len(), 100 * 51);
    let (ok, out, err) = host_sim(&["decode", path]);
    assert!(ok, "{err}");
    assert!(out.contains("raw sample 100"), "{out}");
    assert!(
        out.contains("0 frames lost") && out.contains("0 CRC failures"),
        "{out}"
    );
    let _ = std::fs::remove_file(bin);
}
