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

/// A failed alignment is reported to the user as a sentence, not as the
/// core's error variant (`levelling samples 0..100: NotStatic`).
#[test]
fn a_failed_alignment_reads_as_a_sentence() {
    // The accelerometers read twice gravity: the tool cannot be at rest.
    let csv = temp_path("not-static.csv");
    let mut text =
        String::from("time_s,gyro_x_rad_s,gyro_z_rad_s,accel_x_m_s2,accel_y_m_s2,accel_z_m_s2\n");
    for i in 0..100 {
        text += &format!("{:.3},0,0,0,0,19.6\n", f64::from(i) * 0.05);
    }
    std::fs::write(&csv, text).expect("write the CSV");
    let (ok, _, err) = host_sim(&[
        "align",
        csv.to_str().expect("utf-8"),
        "--calibration",
        "none",
    ]);
    assert!(!ok, "{err}");
    assert!(err.contains("the tool is not at rest"), "{err}");
    assert!(!err.contains("NotStatic"), "{err}");
    let _ = std::fs::remove_file(csv);
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
    // What the probe sends (docs/protocol.md): a boot event (27 bytes on
    // the wire), then per sample a raw frame (51) and a navigation frame
    // (106).
    assert_eq!(bytes.len(), 27 + 100 * (51 + 106));
    let (ok, out, err) = host_sim(&["decode", path]);
    assert!(ok, "{err}");
    assert!(
        out.contains("raw sample 100, navigation 100, event 1"),
        "{out}"
    );
    assert!(
        out.contains("0 frames lost") && out.contains("0 CRC failures"),
        "{out}"
    );
    // Its navigation frames are the probe's own code's: a replay agrees.
    let (ok, out, err) = host_sim(&["replay", path]);
    assert!(ok, "{err}");
    assert!(
        out.contains("replay parity    100 identical, 0 different"),
        "{out}"
    );
    let _ = std::fs::remove_file(bin);
}

/// A calibration file (the format `host-sim calibrate` writes) sets the
/// simulated probe's deterministic errors, and the same file removes them
/// again in `align`.
#[test]
fn a_calibration_file_drives_simulate_and_align() {
    use host_sim::analysis::calibration_file::{
        CalibrationFile, GyroEntry, TriadEntry, FORMAT, VERSION,
    };
    use mwd_core::conventions::DEG;
    let triad = TriadEntry {
        columns: [
            "accel_x_m_s2".into(),
            "accel_y_m_s2".into(),
            "accel_z_m_s2".into(),
        ],
        bias: [0.05, -0.03, 0.02],
        correction: [[0.999, 0.001, 0.0], [0.0, 1.001, 0.0], [0.0, 0.0, 1.0]],
    };
    let gyro = |column: &str, axis: &str, bias: f64| GyroEntry {
        column: column.into(),
        axis: axis.into(),
        bias,
        scale: 1.0,
    };
    let file = CalibrationFile {
        format: FORMAT.into(),
        version: VERSION,
        method: "tls".into(),
        latitude_deg: mwd_core::earth::Position::paper_site().lat.to_degrees(),
        gravity: 9.8,
        accel: vec![triad],
        gyro: vec![
            gyro("gyro_x_rad_s", "x", 0.05 * DEG),
            gyro("gyro_z_rad_s", "z", -0.03 * DEG),
        ],
    };
    let cal = temp_path("probe.cal.json");
    file.save(&cal).expect("save calibration");
    let csv = temp_path("calibrated.csv");
    let (c, o) = (cal.to_str().expect("utf-8"), csv.to_str().expect("utf-8"));
    let (ok, _, err) = host_sim(&[
        "simulate",
        "--sensor",
        "ideal",
        "--calibration-file",
        c,
        "--pitch",
        "10",
        "--heading",
        "20",
        "--duration",
        "10",
        "-o",
        o,
    ]);
    assert!(ok, "{err}");
    // Without the calibration the 0.05 deg/s gyro bias ruins the heading;
    // with it the noise-free heading comes back exactly.
    let (ok, out, err) = host_sim(&[
        "align",
        o,
        "--noise-free",
        "--calibration-file",
        c,
        "--prior-heading",
        "40",
    ]);
    assert!(ok, "{err}");
    assert!((printed_azimuth(&out) - 20.0).abs() < 1e-3, "{out}");
    let (ok, out, _) = host_sim(&[
        "align",
        o,
        "--noise-free",
        "--calibration",
        "none",
        "--prior-heading",
        "40",
    ]);
    assert!(!ok || (printed_azimuth(&out) - 20.0).abs() > 1.0, "{out}");
    for f in [cal, csv] {
        let _ = std::fs::remove_file(f);
    }
}

/// The engineer's calibration loop: simulate a six-position tumble of the
/// SCC1300 (the paper's Table 3 biases plus a random residual), calibrate
/// it, and find the biases again within what the noise allows: 4 sigma of
/// the calibration's own scatter and the 1 mg / 2.1 deg/h residual biases
/// (bounds 0.04 m/s^2 and 22 deg/h). A swapped axis or sign would be off by
/// the full Table 3 value (up to 76 deg/h, 0.02 m/s^2 between axes).
#[test]
fn six_position_tumble_calibrates_back_to_the_simulated_errors() {
    use host_sim::analysis::calibration_file::CalibrationFile;
    use host_sim::sim::DeterministicErrors;
    let csv = temp_path("six.csv");
    let cal = temp_path("six.cal.json");
    let (c, j) = (csv.to_str().expect("utf-8"), cal.to_str().expect("utf-8"));
    let (ok, _, err) = host_sim(&[
        "simulate",
        "--motion",
        "six-position",
        "--dwell",
        "60",
        "--seed",
        "4",
        "-o",
        c,
    ]);
    assert!(ok, "{err}");
    let (ok, out, err) = host_sim(&[
        "calibrate",
        c,
        "--accel",
        "accel_x_m_s2,accel_y_m_s2,accel_z_m_s2",
        "--gyro",
        "gyro_x_rad_s:x",
        "--gyro",
        "gyro_z_rad_s:z",
        "--output",
        j,
    ]);
    assert!(ok, "{err}\n{out}");
    let probe = CalibrationFile::load(&cal)
        .expect("calibration written")
        .to_probe();
    let truth = DeterministicErrors::paper_table3();
    for axis in 0..3 {
        let error = probe.accel[0].bias[axis] - truth.accel_bias[axis];
        assert!(error.abs() < 0.04, "accel bias {axis} off by {error}");
    }
    let deg_h = mwd_core::conventions::DEG / 3600.0;
    for (gyro, axis) in [(0, 0), (1, 2)] {
        let error = (probe.gyro[gyro].bias - truth.gyro_bias[axis]) / deg_h;
        assert!(error.abs() < 22.0, "gyro {axis} bias off by {error} deg/h");
    }
    for f in [csv, cal] {
        let _ = std::fs::remove_file(f);
    }
}
