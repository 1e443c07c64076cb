//! The analysis subcommands end to end through the binary: `allan --json`
//! carries tau and oadev, `arfit` writes a model file that loads into the
//! core's `ArModel`, bad input gives an error with the line, not a panic.

use host_sim::analysis::ar_file::ArModelFile;
use host_sim::analysis::arfit::simulate_ar;
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

#[test]
fn allan_json_and_arfit_model_file() {
    let dir = std::env::temp_dir().join(format!("analysis-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let csv = dir.join("static.csv");
    let a = [0.3308, -0.0995, 0.2036, 0.3347];
    let x = simulate_ar(&a, 0.0034, 4000, 9);
    let g = simulate_ar(&[-0.8466, -0.1105, 0.2948, -0.1642], 7.1662e-7, 4000, 10);
    let mut text = String::from("ax,gy\n");
    for (u, v) in x.iter().zip(&g) {
        text += &format!("{u},{v}\n");
    }
    std::fs::write(&csv, text).unwrap();
    let path = csv.to_str().unwrap();

    let (ok, stdout, stderr) = host_sim(&[
        "allan",
        path,
        "--rate",
        "20",
        "--units",
        "m/s2,deg/s",
        "--json",
    ]);
    assert!(ok, "{stderr}");
    let json: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    let points = json["sensors"][0]["points"].as_array().unwrap();
    assert!(points.len() >= 10);
    assert_eq!(points[0]["tau"].as_f64(), Some(0.05));
    assert!(points[0]["oadev"].as_f64().unwrap() > 0.0);
    assert!(dir.join("static.allan.svg").exists());

    let (ok, stdout, stderr) = host_sim(&["arfit", path, "--rate", "20", "--units", "m/s2,deg/s"]);
    assert!(ok, "{stderr}");
    assert!(
        stdout.contains("Burg") && stdout.contains("BIC"),
        "{stdout}"
    );
    let file = ArModelFile::load(&dir.join("static.ar.json")).unwrap();
    let ax = file.get("ax").unwrap().to_core::<4>().unwrap();
    for (fit, truth) in ax.coefficients.iter().zip(a) {
        assert!((fit - truth).abs() < 0.08, "{:?}", ax.coefficients);
    }
    // gy was given in deg/s: its variance is stored in (rad/s)^2.
    let gy = file.get("gy").unwrap();
    let expected = 7.1662e-7 * mwd_core::conventions::DEG.powi(2);
    assert!(
        (gy.noise_variance / expected - 1.0).abs() < 0.1,
        "{}",
        gy.noise_variance
    );

    std::fs::write(&csv, "ax\n0.1\n0.2\nNaN\n").unwrap();
    let (ok, _, stderr) = host_sim(&["allan", path, "--rate", "20"]);
    assert!(!ok && stderr.contains("line 4"), "{stderr}");
    let (ok, _, stderr) = host_sim(&["allan", path, "--rate", "-1"]);
    assert!(!ok && stderr.contains("--rate"), "{stderr}");
    std::fs::remove_dir_all(&dir).ok();
}

/// `allan` reads the probe's own capture format too: a simulated `.bin`
/// gives the same sensors, in SI body axes, as its CSV twin.
#[test]
fn allan_reads_a_probe_capture() {
    let dir = std::env::temp_dir().join(format!("analysis-cli-bin-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bin = dir.join("static.bin");
    let path = bin.to_str().unwrap();
    let (ok, _, stderr) = host_sim(&["simulate", "--duration", "120", "-o", path]);
    assert!(ok, "{stderr}");
    let (ok, stdout, stderr) = host_sim(&[
        "allan",
        path,
        "--rate",
        "20",
        "--json",
        "--plot",
        dir.join("p.svg").to_str().unwrap(),
    ]);
    assert!(ok, "{stderr}");
    let json: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    let sensors = json["sensors"].as_array().unwrap();
    assert_eq!(sensors.len(), 5, "gyro x, gyro z, accel x y z: {stdout}");
    // The x gyro's deviation near 1 s (octave taus: 0.8 s): white ARW
    // 0.86 deg/sqrt(h) alone gives 2.8e-4 rad/s there; coloured noise and
    // quantisation add to it.
    let points = sensors[0]["points"].as_array().unwrap();
    let near_1s = points
        .iter()
        .min_by(|a, b| {
            let d = |p: &serde_json::Value| (p["tau"].as_f64().unwrap() - 1.0).abs();
            d(a).total_cmp(&d(b))
        })
        .expect("some tau");
    let oadev = near_1s["oadev"].as_f64().unwrap();
    assert!((2.0e-4..2.0e-3).contains(&oadev), "oadev near 1 s {oadev}");
    let garbage = dir.join("garbage.bin");
    std::fs::write(&garbage, [0x55u8; 300]).unwrap();
    let (ok, _, stderr) = host_sim(&["allan", garbage.to_str().unwrap(), "--rate", "20"]);
    assert!(
        !ok && stderr.contains("no valid raw-sample frame"),
        "{stderr}"
    );
    std::fs::remove_dir_all(&dir).ok();
}
