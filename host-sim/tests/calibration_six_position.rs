//! Six-position calibration on simulated data with known errors.
//!
//! Stated noise bound: every estimate must lie within 4 of its own standard
//! errors (derived from the position means' scatter) of the truth. The
//! accelerometer noise is the SCC1300 datasheet's 5 mg-class (0.05 m/s^2
//! per sample), the gyro noise 0.063 deg/s per sample (0.02 deg/s/sqrt(Hz)
//! at 20 Hz), 2000 samples per position.

use host_sim::analysis::calibration::{
    calibrate_gyro, calibrate_triad, earth_rate_up, position_means, Face,
};
use host_sim::analysis::calibration_file::CalibrationFile;
use host_sim::analysis::tls::FitMethod;
use mwd_core::earth::Position;
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};

const G: f64 = 9.806;
const K: [[f64; 3]; 3] = [
    [1.004, 0.0021, -0.0013],
    [-0.0008, 0.9965, 0.0017],
    [0.0011, -0.0024, 1.0022],
];
const BIAS: [f64; 3] = [-0.007083, -0.020188, 0.002405]; // paper Table 3 magnitudes
const GYRO_BIAS: [f64; 2] = [-3.686e-4, -2.871e-4]; // rad/s, paper Table 3 X and Z

/// Rows of (position, ax, ay, az, gx, gz) for the six positions.
fn simulate(seed: u64, per_position: usize) -> Vec<[f64; 6]> {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let acc_noise = Normal::new(0.0, 0.05).unwrap();
    let gyro_noise = Normal::new(0.0, 0.063f64.to_radians()).unwrap();
    let lat = Position::paper_site().lat;
    let up = earth_rate_up(lat);
    let horizontal = 7.292115e-5 * lat.cos();
    let mut rows = Vec::new();
    for (code, face) in Face::ALL.iter().enumerate() {
        let f = face.reference_force(G);
        let (axis, sign) = face.axis();
        // Earth rate along body x and z: the up axis gets +-Omega sin L; a
        // horizontal axis some share of the horizontal component (the
        // heading of the tumble is arbitrary, here 30 deg off north).
        let rate = |body: usize| {
            if body == axis {
                sign * up
            } else {
                horizontal * 30f64.to_radians().cos()
            }
        };
        for _ in 0..per_position {
            let mut row = [(code + 1) as f64, 0.0, 0.0, 0.0, 0.0, 0.0];
            for i in 0..3 {
                row[1 + i] = BIAS[i]
                    + (0..3).map(|j| K[i][j] * f[j]).sum::<f64>()
                    + acc_noise.sample(&mut rng);
            }
            row[4] = GYRO_BIAS[0] + rate(0) + gyro_noise.sample(&mut rng);
            row[5] = GYRO_BIAS[1] + rate(2) + gyro_noise.sample(&mut rng);
            rows.push(row);
        }
    }
    rows
}

#[test]
#[allow(clippy::needless_range_loop)] // index-parallel arrays read more plainly
fn recovers_bias_scale_misalignment_and_gyro_bias() {
    for seed in [11u64, 12, 13] {
        let rows = simulate(seed, 2000);
        let pos: Vec<f64> = rows.iter().map(|r| r[0]).collect();
        let cols: Vec<Vec<f64>> = (1..6)
            .map(|c| rows.iter().map(|r| r[c]).collect())
            .collect();
        let refs: Vec<&[f64]> = cols.iter().map(Vec::as_slice).collect();
        let means = position_means(&pos, &refs).unwrap();
        for method in [FitMethod::Ls, FitMethod::Tls] {
            let t = calibrate_triad(&means, [0, 1, 2], G, method).unwrap();
            for i in 0..3 {
                let z = (t.coupling.h[i][3] - BIAS[i]) / t.bias_se[i];
                assert!(z.abs() < 4.0, "seed {seed} {method:?} bias {i}: z = {z}");
                for j in 0..3 {
                    let z = (t.coupling.h[i][j] - K[i][j]) / t.k_se[i][j];
                    assert!(z.abs() < 4.0, "seed {seed} {method:?} K[{i}][{j}]: z = {z}");
                }
            }
            // The correction built from the fit undoes the error model.
            let cal = t.coupling.to_triad_calibration().unwrap();
            let raw: [f64; 3] = std::array::from_fn(|i| BIAS[i] + K[i][2] * G);
            let c = cal.apply(raw);
            assert!(
                c[0].abs() < 0.01 && c[1].abs() < 0.01 && (c[2] - G).abs() < 0.01,
                "{c:?}"
            );
        }
        let up = earth_rate_up(Position::paper_site().lat);
        for (k, (col, axis)) in [(3usize, 0usize), (4, 2)].into_iter().enumerate() {
            let g = calibrate_gyro(&means, col, axis, up).unwrap();
            let z = (g.bias - GYRO_BIAS[k]) / g.bias_se;
            assert!(
                z.abs() < 4.0,
                "seed {seed} gyro {k}: bias {} vs {} (se {})",
                g.bias,
                GYRO_BIAS[k],
                g.bias_se
            );
            let zs = (g.scale - 1.0) / g.scale_se;
            assert!(
                zs.abs() < 4.0,
                "seed {seed} gyro {k}: scale {} +- {}",
                g.scale,
                g.scale_se
            );
        }
    }
}

#[test]
fn cli_writes_a_loadable_calibration() {
    let dir = std::env::temp_dir().join(format!("calib-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let csv = dir.join("tumble.csv");
    // The simulator's column names: calibrate's defaults.
    let mut text =
        String::from("position,accel_x_m_s2,accel_y_m_s2,accel_z_m_s2,gyro_x_rad_s,gyro_z_rad_s\n");
    for r in simulate(5, 400) {
        text += &format!("{},{},{},{},{},{}\n", r[0], r[1], r[2], r[3], r[4], r[5]);
    }
    std::fs::write(&csv, text).unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_host-sim"))
        .args(["calibrate", csv.to_str().unwrap(), "--gravity", "9.806"])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        stdout.contains("TLS") && stdout.contains("bias x"),
        "{stdout}"
    );
    let file = CalibrationFile::load(&dir.join("tumble.cal.json")).unwrap();
    let probe = file.to_probe();
    assert!((probe.accel[0].bias[1] - BIAS[1]).abs() < 0.01);
    assert!((probe.gyro[1].bias - GYRO_BIAS[1]).abs() < 1e-4);
    // A bad number is reported with its line, not a panic.
    let header = "position,accel_x_m_s2,accel_y_m_s2,accel_z_m_s2,gyro_x_rad_s,gyro_z_rad_s";
    std::fs::write(&csv, format!("{header}\n1,0,0,oops,0,0\n")).unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_host-sim"))
        .args(["calibrate", csv.to_str().unwrap()])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && stderr.contains("line 2") && stderr.contains("oops"),
        "{stderr}"
    );
    std::fs::remove_dir_all(&dir).ok();
}
