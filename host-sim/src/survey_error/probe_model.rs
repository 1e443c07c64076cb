//! The probe's own tool model (`host-sim/data/probe_scc1300_terms.csv`,
//! derived in `docs/probe-tool-model.md`): the sensor terms' magnitudes
//! follow from the error budget in `mwd_core::sensor_noise`; the tests
//! check that the file and the budget agree.

use mwd_core::sensor_noise::ImuNoise;
use mwd_core::timing::SAMPLE_RATE_HZ;

/// Still time assumed at a survey station, s.
pub const STATION_STILL_TIME_S: f64 = 120.0;

/// Path of the probe tool model, relative to the workspace root.
pub const PROBE_MODEL_CSV: &str = "host-sim/data/probe_scc1300_terms.csv";

const RAD_PER_S_TO_DEG_PER_HR: f64 = 180.0 / std::f64::consts::PI * 3600.0;

/// The sensor terms of the probe model as `(code, magnitude in the table's
/// unit)`, computed from [`ImuNoise::scc1300`] and
/// [`STATION_STILL_TIME_S`].
pub fn sensor_term_magnitudes() -> Vec<(&'static str, f64)> {
    let n = ImuNoise::scc1300();
    let samples = (STATION_STILL_TIME_S * SAMPLE_RATE_HZ).round() as usize;
    let dt = 1.0 / SAMPLE_RATE_HZ;
    // body x right, y forward along the tool, z up: the two cross-axis
    // gyros are x and z (the y rate is accelerometer-derived), the
    // along-tool accelerometer (the OWSG "Z" accelerometer) is y
    let [gx, _, gz] = n.gyro;
    let accel = n.accel[1];
    vec![
        // residual (run-to-run) gyro bias, constant over the run
        (
            "GXY-B1S",
            gx.residual_bias.max(gz.residual_bias) * RAD_PER_S_TO_DEG_PER_HR,
        ),
        (
            "GXY-B2S",
            gx.residual_bias.max(gz.residual_bias) * RAD_PER_S_TO_DEG_PER_HR,
        ),
        // white + coloured + Gauss-Markov noise of the station mean, the
        // worse of the two cross-axis gyros (their AR(4) fits differ)
        (
            "GXY-RN",
            gx.mean_sigma(samples, dt).max(gz.mean_sigma(samples, dt)) * RAD_PER_S_TO_DEG_PER_HR,
        ),
        // residual bias of the along-tool accelerometer
        ("AXYZ-ZB", accel.residual_bias),
        // accelerometer noise of the station mean
        ("AXYZ-ZN", accel.mean_sigma(samples, dt)),
    ]
}

#[cfg(test)]
mod tests {
    use super::super::*;
    use super::*;
    use nalgebra::{Matrix3, SymmetricEigen};
    use std::path::PathBuf;

    fn data(name: &str) -> PathBuf {
        PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("..")
            .join(name)
    }

    fn site() -> Site {
        Site {
            gravity: 9.80665,
            b_total: 50_000.0,
            dip: 72_f64.to_radians(),
            declination: 0.0,
            vertical_limit: 1e-4_f64.to_radians(),
            latitude: 60_f64.to_radians(),
            gyro_noise_reduction: 1.0,
        }
    }

    /// The file's sensor terms carry the magnitudes the error budget gives.
    #[test]
    fn file_magnitudes_follow_the_sensor_budget() {
        let terms = load_term_table(&data(PROBE_MODEL_CSV)).unwrap();
        for (code, expected) in sensor_term_magnitudes() {
            let t = terms
                .iter()
                .find(|t| t.code == code)
                .unwrap_or_else(|| panic!("{code} not in {PROBE_MODEL_CSV}"));
            assert!(
                (t.magnitude - expected).abs() <= 1e-12 * expected.abs(),
                "{code}: file {} vs budget {expected}",
                t.magnitude
            );
        }
        // the systematic gyro and accelerometer biases, the random noise
        let prop = |c: &str| terms.iter().find(|t| t.code == c).unwrap().propagation;
        assert_eq!(prop("GXY-B1S"), Propagation::Systematic);
        assert_eq!(prop("GXY-B2S"), Propagation::Systematic);
        assert_eq!(prop("AXYZ-ZB"), Propagation::Systematic);
        assert_eq!(prop("GXY-RN"), Propagation::Random);
        assert_eq!(prop("AXYZ-ZN"), Propagation::Random);
    }

    /// A 1000 m lateral at 88 deg inclination, 30 m stations.
    fn lateral() -> Vec<Station> {
        let inc = 88_f64.to_radians();
        let azi = 45_f64.to_radians();
        let mut md = 0.0;
        let mut out = Vec::new();
        while md <= 1000.0 + 1e-9 {
            out.push(Station {
                md,
                inc,
                azi,
                tvd: md * inc.cos(),
            });
            md += 1000.0 / 33.0;
        }
        out
    }

    fn matrix(c: &Cov6) -> Matrix3<f64> {
        Matrix3::new(c[0], c[3], c[4], c[3], c[1], c[5], c[4], c[5], c[2])
    }

    #[test]
    #[ignore]
    fn print_magnitudes() {
        let n = ImuNoise::scc1300();
        let k = (STATION_STILL_TIME_S * SAMPLE_RATE_HZ) as usize;
        for (i, g) in n.gyro.iter().enumerate() {
            println!(
                "gyro {i}: {:e} deg/h",
                g.mean_sigma(k, 0.05) * RAD_PER_S_TO_DEG_PER_HR
            );
        }
        for (i, a) in n.accel.iter().enumerate() {
            println!("accel {i}: {:e} m/s2", a.mean_sigma(k, 0.05));
        }
        for (c, m) in sensor_term_magnitudes() {
            println!("{c} {m:e}");
        }
    }

    #[test]
    fn lateral_at_88_deg_is_finite_psd_and_wider_than_gyro_ns() {
        let stations = lateral();
        check_stations(&stations).unwrap();
        let probe = load_term_table(&data(PROBE_MODEL_CSV)).unwrap();
        let ns = load_term_table(&data("host-sim/data/owsg_gyro_ns_terms.csv")).unwrap();
        let rp = run(&probe, &stations, &site());
        let rn = run(&ns, &stations, &site());
        assert!(rp.missing.is_empty(), "missing {:?}", rp.missing);
        assert!(rn.missing.is_empty());
        for (k, (cp, cn)) in rp.total.iter().zip(&rn.total).enumerate().skip(1) {
            assert!(cp.iter().all(|x| x.is_finite()), "station {k}");
            let p = matrix(cp);
            assert_eq!(p, p.transpose());
            let ep = SymmetricEigen::new(p).eigenvalues;
            let scale = p.trace();
            assert!(ep.iter().all(|&e| e >= -1e-9 * scale), "station {k}: {ep}");
            // larger than GYRO-NS: the difference is PSD, the trace larger
            let d = SymmetricEigen::new(p - matrix(cn)).eigenvalues;
            assert!(d.iter().all(|&e| e >= -1e-9 * scale), "station {k}: {d}");
            assert!(p.trace() > matrix(cn).trace());
        }
        let last = rp.total.last().unwrap();
        let ns_last = rn.total.last().unwrap();
        println!(
            "1000 m at 88 deg: probe horizontal 1-sigma {:.1} m, GYRO-NS {:.1} m",
            (last[0] + last[1]).sqrt(),
            (ns_last[0] + ns_last[1]).sqrt()
        );
    }

    /// The table of docs/probe-tool-model.md (not a check): horizontal
    /// 1-sigma at the end of a 1000 m straight hold, probe vs OWSG models.
    /// `cargo test -p host-sim --lib probe_model -- --ignored --nocapture`
    #[test]
    #[ignore]
    fn print_hold_sweep() {
        let probe = load_term_table(&data(PROBE_MODEL_CSV)).unwrap();
        let ns = load_term_table(&data("host-sim/data/owsg_gyro_ns_terms.csv")).unwrap();
        let mwd = load_term_table(&data("host-sim/data/owsg_gyro_mwd_terms.csv")).unwrap();
        for lat in [0.0f64, 60.0] {
            for inc in [0.0f64, 30.0, 60.0, 80.0, 88.0, 89.9] {
                for azi in [0.0f64, 45.0, 90.0] {
                    let (i, a) = (inc.to_radians(), azi.to_radians());
                    let st: Vec<Station> = (0..34)
                        .map(|k| {
                            let md = k as f64 * 1000.0 / 33.0;
                            Station {
                                md,
                                inc: i,
                                azi: a,
                                tvd: md * i.cos(),
                            }
                        })
                        .collect();
                    let site = Site {
                        latitude: lat.to_radians(),
                        ..site()
                    };
                    let h = |t: &[ErrorTerm]| {
                        let c = *run(t, &st, &site).total.last().unwrap();
                        (c[0] + c[1]).sqrt()
                    };
                    println!(
                        "| {lat} | {inc} | {azi} | {:.1} | {:.1} | {:.1} |",
                        h(&probe),
                        h(&mwd),
                        h(&ns)
                    );
                }
            }
        }
    }
}
