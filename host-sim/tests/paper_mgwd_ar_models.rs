//! `paper mgwd --ar-models`: the model file `arfit` writes is what the
//! filter runs on. simulate -> arfit -> paper mgwd through the binary; the
//! report names each filter axis with the file's sensor and coefficients,
//! and a file the filter cannot use stops the run with a clear error.

use host_sim::analysis::ar_file::{ArModelFile, ArQuantity};
use std::path::Path;
use std::process::Command;

fn host_sim(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_host-sim"))
        .args(args)
        .output()
        .unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into(),
        String::from_utf8_lossy(&out.stderr).into(),
    )
}

/// `paper mgwd` with few consistency runs; `extra` after the model file.
fn mgwd(dir: &Path, models: &Path, extra: &[&str]) -> (bool, String, String) {
    let plots = dir.join("plots");
    let mut args = vec![
        "paper",
        "mgwd",
        "--runs",
        "2",
        "--plots",
        plots.to_str().unwrap(),
        "--ar-models",
        models.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    host_sim(&args)
}

#[test]
fn paper_mgwd_runs_on_the_models_arfit_fitted() {
    let dir = std::env::temp_dir().join(format!("mgwd-ar-models-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let csv = dir.join("static.csv");
    let (ok, _, stderr) = host_sim(&["simulate", "--duration", "600", "-o", csv.to_str().unwrap()]);
    assert!(ok, "{stderr}");
    let (ok, _, stderr) = host_sim(&["arfit", csv.to_str().unwrap(), "--rate", "20"]);
    assert!(ok, "{stderr}");
    let models = dir.join("static.ar.json");
    let file = ArModelFile::load(&models).unwrap();

    // The probe has no tool-axis gyro: without a fit of the derived rate the
    // run refuses, and says how to go on.
    let (ok, stdout, stderr) = mgwd(&dir, &models, &[]);
    assert!(!ok && stdout.is_empty(), "{stdout}");
    assert!(
        stderr.contains("no model for gyro y") && stderr.contains("--paper-derived-rate"),
        "{stderr}"
    );

    let (ok, stdout, stderr) = mgwd(&dir, &models, &["--paper-derived-rate"]);
    assert!(ok, "{stderr}");
    assert!(
        stdout.contains(&format!(
            "AR(4) noise models loaded from {} (20 Hz)",
            models.display()
        )),
        "{stdout}"
    );
    // Each axis from its own sensor (the CSV's order is gyro x, gyro z,
    // accel x, y, z; the filter's is accel x, y, z, gyro x, y, z), with the
    // file's first coefficient.
    for (label, sensor) in [
        ("accel x", "accel_x_m_s2"),
        ("accel y", "accel_y_m_s2"),
        ("accel z", "accel_z_m_s2"),
        ("gyro x", "gyro_x_rad_s"),
        ("gyro z", "gyro_z_rad_s"),
    ] {
        let a1 = file.get(sensor).unwrap().coefficients[0];
        let line = stdout
            .lines()
            .find(|l| l.trim_start().starts_with(&format!("{label} ")))
            .unwrap_or_else(|| panic!("no line for {label}: {stdout}"));
        assert!(
            line.contains(&format!("<- {sensor} (YuleWalker)")),
            "{line}"
        );
        assert!(line.contains(&format!("[{a1:>8.4}")), "{a1} in {line}");
    }
    assert!(
        stdout.contains("gyro y (accelerometer-derived rate)  <- paper Table 5"),
        "{stdout}"
    );
    assert!(stdout.contains("Tables 4-5 AR(4) noise only"), "{stdout}");
    assert!(stdout.contains("2/2 inside"), "{stdout}");

    // Without the option the report says the paper's models ran.
    let plots = dir.join("plots");
    let (ok, stdout, stderr) = host_sim(&[
        "paper",
        "mgwd",
        "--runs",
        "1",
        "--plots",
        plots.to_str().unwrap(),
    ]);
    assert!(ok, "{stderr}");
    assert!(
        stdout.contains("AR(4) noise models: the paper's Tables 4-5"),
        "{stdout}"
    );

    // Files the filter cannot use: each a clear error, a non-zero exit.
    let bad = dir.join("bad.ar.json");
    let refuse = |content: &str, expected: &[&str]| {
        std::fs::write(&bad, content).unwrap();
        let (ok, stdout, stderr) = mgwd(&dir, &bad, &["--paper-derived-rate"]);
        assert!(!ok && stdout.is_empty(), "{stdout}");
        assert!(stderr.starts_with("error: "), "{stderr}");
        for e in expected {
            assert!(stderr.contains(e), "{e:?} not in {stderr}");
        }
        assert!(!stderr.contains("panicked"), "{stderr}");
    };
    refuse("time_s,ax\n0.05,1\n", &["bad.ar.json"]);
    refuse(
        "{\"format\": \"mwd-calibration\", \"version\": 1, \"models\": []}",
        &["not a mwd-ar-models v1 file"],
    );
    let mut f = file.clone();
    f.models.retain(|m| m.sensor != "accel_y_m_s2");
    refuse(
        &serde_json::to_string(&f).unwrap(),
        &["no model for accel y", "accel_x_m_s2"],
    );
    let mut f = file.clone();
    f.models[0].coefficients = vec![0.0, 0.0, 0.0, 1.5];
    refuse(
        &serde_json::to_string(&f).unwrap(),
        &["gyro_x_rad_s", "not stationary"],
    );
    let mut f = file.clone();
    f.models[2].coefficients.pop();
    f.models[2].order = 3;
    refuse(
        &serde_json::to_string(&f).unwrap(),
        &["accel_x_m_s2", "order 3"],
    );
    // A quantity mismatch reads as a sentence, not as the enum's variants.
    let mut f = file.clone();
    let accel_x = f.models.iter_mut().find(|m| m.sensor == "accel_x_m_s2");
    accel_x.unwrap().quantity = ArQuantity::AngularRate;
    refuse(
        &serde_json::to_string(&f).unwrap(),
        &["accel_x_m_s2: the file has an angular rate where accel x needs a specific force"],
    );
    let mut f = file.clone();
    f.models[1].sensor = "accel_z_m_s2".into();
    refuse(
        &serde_json::to_string(&f).unwrap(),
        &["2 models map onto accel z"],
    );
    // Fitted at another rate: arfit's own file at 10 Hz.
    let (ok, _, stderr) = host_sim(&[
        "arfit",
        csv.to_str().unwrap(),
        "--rate",
        "10",
        "--output",
        bad.to_str().unwrap(),
    ]);
    assert!(ok, "{stderr}");
    let (ok, _, stderr) = mgwd(&dir, &bad, &["--paper-derived-rate"]);
    assert!(!ok && stderr.contains("fitted at 10 Hz"), "{stderr}");
    let (ok, _, stderr) = mgwd(&dir, &dir.join("missing.json"), &[]);
    assert!(!ok && stderr.contains("cannot read"), "{stderr}");
    std::fs::remove_dir_all(&dir).ok();
}
