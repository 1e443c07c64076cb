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
        // residual (run-to-run) bias of each cross-axis gyro, constant over
        // the run: projected through the toolface (probe_weighting.rs)
        ("PRB-GXB", gx.residual_bias * RAD_PER_S_TO_DEG_PER_HR),
        ("PRB-GZB", gz.residual_bias * RAD_PER_S_TO_DEG_PER_HR),
        // white + coloured + Gauss-Markov noise of the station mean, the
        // worse of the two cross-axis gyros (their AR(4) fits differ): the
        // weighting function takes equal noise on both axes
        (
            "PRB-GN",
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
    use super::super::stations::{SiteTerms, StationTrig};
    use super::super::weighting::{horizontal_earth_rate, weighting};
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
        assert_eq!(prop("PRB-GXB"), Propagation::Systematic);
        assert_eq!(prop("PRB-GZB"), Propagation::Systematic);
        assert_eq!(prop("AXYZ-ZB"), Propagation::Systematic);
        assert_eq!(prop("PRB-GN"), Propagation::Random);
        assert_eq!(prop("AXYZ-ZN"), Propagation::Random);
    }

    /// A straight 1000 m hold from a tie-on at MD 0 (34 stations, about
    /// 30 m apart), with the toolface of each station from `toolface`.
    fn hold(inc_deg: f64, azi_deg: f64, toolface: impl Fn(usize) -> Option<f64>) -> Vec<Station> {
        let (inc, azi) = (inc_deg.to_radians(), azi_deg.to_radians());
        (0..34)
            .map(|k| {
                let md = k as f64 * 1000.0 / 33.0;
                Station {
                    md,
                    inc,
                    azi,
                    tvd: md * inc.cos(),
                    toolface: toolface(k),
                }
            })
            .collect()
    }

    fn psd(m: &Matrix3<f64>, what: &str) {
        let e = SymmetricEigen::new(*m).eigenvalues;
        let scale = m.trace().abs().max(1e-300);
        assert!(e.iter().all(|&x| x >= -1e-9 * scale), "{what}: {e}");
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

    /// The case the OWSG functions cannot take (they divide by cos I): a
    /// horizontal lateral heading north gets a finite, symmetric, positive
    /// semi-definite covariance at every station, whose horizontal part
    /// grows along the hole, at the equator and at 60 deg latitude.
    #[test]
    fn lateral_at_90_deg_heading_north_has_a_covariance() {
        let probe = load_term_table(&data(PROBE_MODEL_CSV)).unwrap();
        for lat in [0.0f64, 60.0] {
            let site = Site {
                latitude: lat.to_radians(),
                ..site()
            };
            let stations = hold(90.0, 0.0, |_| None);
            check_stations(&stations).unwrap();
            let r = run(&probe, &stations, &site);
            assert!(r.missing.is_empty(), "missing {:?}", r.missing);
            let mut prev = 0.0;
            for (k, c) in r.total.iter().enumerate().skip(1) {
                assert!(c.iter().all(|x| x.is_finite()), "lat {lat}, station {k}");
                let m = cov_matrix(c);
                assert_eq!(m, m.transpose());
                psd(&m, &format!("lat {lat}, station {k}"));
                // the cross-hole (east) variance grows with MD
                assert!(c[1] > prev, "lat {lat}, station {k}");
                prev = c[1];
            }
        }
    }

    /// Heading east (or within 5.7 deg of it) at 90 deg the azimuth is
    /// undetermined: no number from the first such station on, while 84
    /// deg (S = cos 84 deg = 0.105) still gets a finite covariance.
    #[test]
    fn lateral_heading_east_is_undetermined() {
        let probe = load_term_table(&data(PROBE_MODEL_CSV)).unwrap();
        for azi in [90.0, 85.0, 95.0, 270.0, 265.0] {
            let r = run(&probe, &hold(90.0, azi, |_| None), &site());
            assert!(
                r.total
                    .iter()
                    .skip(1)
                    .all(|c| c[0].is_nan() && c[1].is_nan()),
                "azimuth {azi}"
            );
            assert!(!probe_weighting::azimuth_determined(
                90f64.to_radians(),
                f64::to_radians(azi)
            ));
        }
        for azi in [84.0, 96.0, 264.0] {
            let r = run(&probe, &hold(90.0, azi, |_| None), &site());
            assert!(
                r.total
                    .iter()
                    .skip(1)
                    .all(|c| c.iter().all(|x| x.is_finite())),
                "azimuth {azi}"
            );
        }
        // turning east part way: finite before, NaN from the first
        // undetermined station on (never an extrapolated number)
        let mut st = hold(90.0, 0.0, |_| None);
        for s in st.iter_mut().skip(20) {
            s.azi = 90f64.to_radians();
        }
        let r = run(&probe, &st, &site());
        assert!(r.total[..20]
            .iter()
            .all(|c| c.iter().all(|x| x.is_finite())));
        assert!(r.total[20..].iter().all(|c| c[0].is_nan()));
    }

    /// The weights against closed forms: near vertical they are the OWSG
    /// GXY functions (SPE 90408 Table 1) up to sign, with the toolface
    /// turning body x/z into right/high side; the least-squares noise
    /// weight is never larger than GXY-RN's (the closed-form solution
    /// divides the high-side channel by cos I; least squares weighs both).
    #[test]
    fn weights_against_the_owsg_closed_forms() {
        let site = site();
        let wt = |name: &str, inc: f64, azi: f64, tf: Option<f64>| {
            let s = Station {
                md: 100.0,
                inc: inc.to_radians(),
                azi: azi.to_radians(),
                tvd: 50.0,
                toolface: tf.map(f64::to_radians),
            };
            weighting(
                name,
                &s,
                &StationTrig::of(&s, &site),
                30.0,
                &SiteTerms::of(&site),
            )
            .unwrap()
            .w[2]
        };
        for azi in [0.0, 30.0, 135.0, 250.0] {
            let tol = |x: f64| {
                1e-9 * x
                    .abs()
                    .max(1.0 / horizontal_earth_rate(&SiteTerms::of(&site)))
            };
            // vertical, toolface 0: body x is the right side, z the high side
            let (b1, b2) = (wt("GXY-B1", 0.0, azi, None), wt("GXY-B2", 0.0, azi, None));
            assert!((wt("PRB-GXB", 0.0, azi, Some(0.0)) + b2).abs() < tol(b2));
            assert!((wt("PRB-GZB", 0.0, azi, Some(0.0)) + b1).abs() < tol(b1));
            // toolface 90 deg: body z on the right side, x on the low side
            assert!((wt("PRB-GZB", 0.0, azi, Some(90.0)) + b2).abs() < tol(b2));
            assert!((wt("PRB-GXB", 0.0, azi, Some(90.0)) - b1).abs() < tol(b1));
            let rn = wt("GXY-RN", 0.0, azi, None);
            assert!((wt("PRB-GN", 0.0, azi, None) - rn).abs() < tol(rn));
            for inc in [10.0, 45.0, 80.0, 88.0, 120.0] {
                let ls = wt("PRB-GN", inc, azi, None);
                let rn = wt("GXY-RN", inc, azi, None).abs();
                assert!(ls <= rn * (1.0 + 1e-12), "inc {inc} azi {azi}: {ls} > {rn}");
                // the toolface-free bound is the largest weight over toolface
                let bound = wt("PRB-GXB", inc, azi, None);
                assert!((bound - ls).abs() < 1e-12 * ls);
                let max = (0..360)
                    .map(|tf| wt("PRB-GXB", inc, azi, Some(tf as f64)).abs())
                    .fold(0.0, f64::max);
                assert!(max <= bound && max > 0.999 * bound, "inc {inc} azi {azi}");
            }
        }
    }

    /// Along a lateral whose toolface turns from station to station, the
    /// toolface-free bias terms bound the toolface-aware ones: the
    /// difference of the two covariances is positive semi-definite.
    #[test]
    fn toolface_free_bias_bounds_any_toolface() {
        let terms: Vec<ErrorTerm> = load_term_table(&data(PROBE_MODEL_CSV))
            .unwrap()
            .into_iter()
            .filter(|t| t.code == "PRB-GXB" || t.code == "PRB-GZB")
            .collect();
        assert_eq!(terms.len(), 2);
        for azi in [0.0, 40.0, 75.0] {
            for (name, tf) in [
                ("fixed 0", (|_| 0.0) as fn(usize) -> f64),
                ("fixed 70", |_| 70f64.to_radians()),
                ("turning", |k| (k as f64 * 47.0).to_radians()),
            ] {
                let with = run(&terms, &hold(90.0, azi, |k| Some(tf(k))), &site());
                let free = run(&terms, &hold(90.0, azi, |_| None), &site());
                for k in 1..with.total.len() {
                    let d = cov_matrix(&free.total[k]) - cov_matrix(&with.total[k]);
                    psd(&d, &format!("azi {azi}, {name}, station {k}"));
                }
            }
        }
    }

    /// The table of docs/probe-tool-model.md (not a check): horizontal
    /// 1-sigma at the end of a 1000 m lateral at 90 deg (tie-on at MD 0,
    /// 34 stations), all terms, without a toolface (bias bound) and with a
    /// constant one; and the gyro noise (PRB-GN) alone.
    /// `cargo test -p host-sim --lib probe_model -- --ignored --nocapture`
    #[test]
    #[ignore]
    fn print_lateral_table() {
        let probe = load_term_table(&data(PROBE_MODEL_CSV)).unwrap();
        println!("| lat (deg) | azi (deg) | S | no toolface (m) | toolface 0 (m) | gyro noise alone (m) |");
        println!("| --- | --- | --- | --- | --- | --- |");
        let horizontal = |c: &Cov6| {
            let v = (c[0] + c[1]).sqrt();
            if v.is_finite() {
                format!("{v:.1}")
            } else {
                "undetermined".to_string()
            }
        };
        for lat in [0.0f64, 30.0, 60.0] {
            for azi in [0.0f64, 30.0, 60.0, 80.0, 84.0, 85.0, 90.0] {
                let site = Site {
                    latitude: lat.to_radians(),
                    ..site()
                };
                let free = run(&probe, &hold(90.0, azi, |_| None), &site);
                let tf0 = run(&probe, &hold(90.0, azi, |_| Some(0.0)), &site);
                let s = probe_weighting::azimuth_sensitivity(1.0, azi.to_radians().sin());
                println!(
                    "| {lat} | {azi} | {s:.3} | {} | {} | {} |",
                    horizontal(free.total.last().unwrap()),
                    horizontal(tf0.total.last().unwrap()),
                    horizontal(free.per_source["PRB-GN"].last().unwrap()),
                );
            }
        }
    }

    /// The SCC1300 at one 120 s station is beyond the first-order limit
    /// everywhere: the smallest single-station azimuth sigma (equator,
    /// S = 1, toolface known) is sqrt(5.04^2 + 2.1^2) / 15.04 deg/h = 0.36
    /// rad = 20.8 deg > 10 deg. Checked over latitude 0-80 deg, every
    /// inclination and azimuth (10 deg steps, where determined), with and
    /// without a toolface.
    #[test]
    fn scc1300_single_station_sigma_is_beyond_the_first_order_limit_everywhere() {
        use super::super::probe_weighting as pw;
        let mags: std::collections::BTreeMap<_, _> = sensor_term_magnitudes().into_iter().collect();
        let per_h = |x: f64| x.to_radians() / 3600.0;
        let e = pw::GyroErrors {
            noise: per_h(mags["PRB-GN"]),
            bias_x: per_h(mags["PRB-GXB"]),
            bias_z: per_h(mags["PRB-GZB"]),
        };
        let mut smallest = f64::INFINITY;
        for lat in (0..=80).step_by(10) {
            for inc in (0..=180).step_by(10) {
                for azi in (0..360).step_by(10) {
                    for tf in [None, Some(0.0), Some(1.0), Some(2.5)] {
                        let (i, a) = (f64::from(inc).to_radians(), f64::from(azi).to_radians());
                        let lat = f64::from(lat).to_radians();
                        let Some(sigma) = pw::single_station_azimuth_sigma(i, a, tf, lat, 1.0, &e)
                        else {
                            continue;
                        };
                        assert!(sigma > pw::first_order_azimuth_limit(i, a));
                        smallest = smallest.min(sigma);
                    }
                }
            }
        }
        assert!(
            (smallest.to_degrees() - 20.79).abs() < 0.01,
            "{}",
            smallest.to_degrees()
        );
    }

    /// The gyro grade that passes (docs/probe-tool-model.md): a lateral at
    /// 90 deg heading north at 45 deg latitude, no toolface, is determined
    /// iff sqrt(N^2 + 2 B^2) <= 10 deg x 10.636 deg/h = 1.856 deg/h.
    #[test]
    fn gyro_grade_that_passes_heading_north_at_45_deg() {
        use super::super::probe_weighting as pw;
        let per_h = |x: f64| x.to_radians() / 3600.0;
        let (inc, azi, lat) = (90_f64.to_radians(), 0.0, 45_f64.to_radians());
        let limit = pw::first_order_azimuth_limit(inc, azi);
        assert_eq!(limit, 10_f64.to_radians());
        for (noise, bias) in [(1.856, 0.0), (1.716, 0.5), (1.202, 1.0), (0.0, 1.3125)] {
            for (k, passes) in [(0.995, true), (1.005, false)] {
                let e = pw::GyroErrors {
                    noise: per_h(noise * k),
                    bias_x: per_h(bias * k),
                    bias_z: per_h(bias * k),
                };
                let sigma = pw::single_station_azimuth_sigma(inc, azi, None, lat, 1.0, &e).unwrap();
                assert_eq!(sigma <= limit, passes, "N {noise} B {bias} x {k}");
            }
        }
    }
}
