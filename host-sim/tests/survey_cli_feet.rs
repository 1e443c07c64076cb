//! `host-sim survey` on a survey in feet: ISCWSA test well #2 (Gulf of
//! Mexico, published in feet) through the binary, against the published
//! ISCWSA Rev 5.1 diagnostic covariances of well #2.
//!
//! The station file is written by the test from the golden data
//! (`tests/data/iscwsa/well2_survey.csv`, `md_ft,inc_deg,azi_true_deg,tvd_ft`)
//! as `md_ft,inc_deg,azi_deg`; the site is read from `wells.json`.
//!
//! Reference: the CLI's "ISCWSA MWD Rev5" is the Rev 5.10 table as
//! published (DEC-OH 0.21 deg, XCLA with the 5.10 sine term), so its
//! numbers are those of the HPT Rev 5.1 diagnostics
//! (`mwd_rev5_1_hpt_diagnostics_selected_rows.csv`, TOTAL rows of well 2 at
//! the seven tabulated depths 2000 ... 12500 ft, printed with MD in metres)
//! — not the older workbook diagnostic block, which was made with DEC-OH
//! 0.20 deg and differs by up to 1.7 % in EE (tests/data/iscwsa/README.md).
//!
//! Tolerance: the one `host-sim/tests/iscwsa_error_model.rs` uses for well
//! #2: a value passes within 5e-4 m^2 (the references carry 5e-5 m^2 of
//! rounding, and the ISCWSA workbook itself reproduces the well #2 block
//! only to 4.6e-4 m^2) or within 0.5 % of the reference; and every value
//! within 1 % (the acceptance the task quoted; no source for it was found
//! in the test data, tests/data/iscwsa/README.md "What was not found").

mod common;

use common::s;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

fn data_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/data/iscwsa")
}

/// As `host-sim/tests/iscwsa_error_model.rs` (well #2).
const ABS_TOL_M2: f64 = 5e-4;
const REL_TOL: f64 = 5e-3;

fn close(got: f64, want: f64) -> bool {
    (got - want).abs() <= ABS_TOL_M2 || (got - want).abs() <= REL_TOL * want.abs()
}

/// Well #2's entry of wells.json.
fn well2_site() -> serde_json::Value {
    let text = std::fs::read_to_string(data_dir().join("wells.json")).expect("wells.json");
    let json: serde_json::Value = serde_json::from_str(&text).expect("wells.json parses");
    json["iscwsa_2"].clone()
}

fn num(v: &serde_json::Value, key: &str) -> f64 {
    v[key]
        .as_f64()
        .unwrap_or_else(|| panic!("wells.json iscwsa_2: no number {key}"))
}

/// The golden survey rows: (md_ft, inc_deg, azi_deg, tvd_ft), as text for
/// the first three (written to the station file unchanged).
fn golden_survey() -> Vec<[String; 4]> {
    let site = well2_site();
    let file = site["survey_file"].as_str().expect("survey_file");
    let text = std::fs::read_to_string(data_dir().join(file)).expect("well 2 survey");
    let mut lines = text.lines();
    assert_eq!(
        lines.next(),
        Some("md_ft,inc_deg,azi_true_deg,tvd_ft"),
        "{file}: header"
    );
    lines
        .map(|l| {
            let f: Vec<&str> = l.split(',').map(str::trim).collect();
            assert_eq!(f.len(), 4, "{file}: {l}");
            std::array::from_fn(|i| f[i].to_string())
        })
        .collect()
}

/// HPT Rev 5.1 TOTAL rows of well 2: md_m (as printed) -> [nn, ee, vv, ne,
/// nv, ev] m^2.
fn hpt_totals_well2() -> BTreeMap<String, [f64; 6]> {
    let path = data_dir().join("mwd_rev5_1_hpt_diagnostics_selected_rows.csv");
    let text = std::fs::read_to_string(&path).expect("HPT rows");
    let mut out = BTreeMap::new();
    for l in text.lines().skip(1) {
        let f: Vec<&str> = l.split(',').map(str::trim).collect();
        if f[0] == "2" && f[2] == "TOTAL" {
            let c: [f64; 6] = std::array::from_fn(|j| f[3 + j].parse().expect("number"));
            out.insert(f[1].to_string(), c);
        }
    }
    out
}

#[test]
fn iscwsa_well_2_in_feet() {
    let site = well2_site();
    assert_eq!(site["depth_units"].as_str(), Some("ft"));
    assert_eq!(num(&site, "grid_convergence_deg"), 0.0);
    assert_eq!(site["azimuth_reference"].as_str(), Some("TRUE"));
    let ft = num(&site, "feet_to_metres");
    assert_eq!(ft, 0.3048);
    // the golden data's vertical limit and gravity are the CLI's fixed ones
    assert_eq!(num(&site, "vertical_inc_limit_deg"), 0.0001);
    assert_eq!(num(&site, "gravity_m_per_s2"), 9.80665);

    let survey = golden_survey();
    assert_eq!(survey.len(), 131);
    let dir = common::scratch("survey-cli-feet", "well2");
    let stations = dir.join("well2_stations.csv");
    let mut text = String::from("md_ft,inc_deg,azi_deg\n");
    for r in &survey {
        text += &format!("{},{},{}\n", r[0], r[1], r[2]);
    }
    std::fs::write(&stations, text).expect("write stations");
    let out = dir.join("out.csv");
    let arg = |key: &str| num(&site, key).to_string();
    // the tie-on is the survey's first station (MD 0, TVD 0, at the origin)
    let tie_md = survey[0][0].clone();
    let tie_tvd = survey[0][3].clone();
    let (lat, b, dip, dec) = (
        arg("latitude_deg"),
        arg("b_total_nT"),
        arg("dip_deg"),
        arg("declination_deg"),
    );
    let run = common::run(&[
        "survey",
        s(&stations),
        "--error-model",
        "ISCWSA MWD Rev5",
        "--lat",
        &lat,
        "--b-total-nt",
        &b,
        "--dip-deg",
        &dip,
        "--declination-deg",
        &dec,
        "--tie-on-md",
        &tie_md,
        "--tie-on-tvd",
        &tie_tvd,
        "--csv",
        s(&out),
    ]);
    assert_eq!(run.code, Some(0), "{}", run.stderr);

    let csv = std::fs::read_to_string(&out).expect("CSV written");
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().expect("header").split(',').collect();
    let col = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .unwrap_or_else(|| panic!("no column {name} in {header:?}"))
    };
    // the outputs are in metres whatever the input unit: the header says so
    let (c_md, c_tvd) = (col("md_m"), col("tvd_m"));
    let (c_sn, c_se, c_sv) = (
        col("sigma_north_m"),
        col("sigma_east_m"),
        col("sigma_vert_m"),
    );
    let (c_major, c_minor, c_conf) = (
        col("ellipse_semi_major_m"),
        col("ellipse_semi_minor_m"),
        col("confidence"),
    );
    let rows: Vec<Vec<f64>> = lines
        .map(|l| {
            l.split(',')
                .map(|f| {
                    if f.is_empty() || f == "true" {
                        0.0
                    } else {
                        f.parse().unwrap_or_else(|e| panic!("{f:?} in {l}: {e}"))
                    }
                })
                .collect()
        })
        .collect();
    assert_eq!(rows.len(), survey.len());

    // feet in, metres out: MD exactly converted; TVD by minimum curvature
    // against the workbook's typed TVD: within 0.05 ft, not 0.005 — minimum
    // curvature from the file's angles (typed to 0.01 deg) gives TVDs up to
    // 0.034 ft (at 9300 ft) from the typed ones, computed by the workbook
    // from its own unrounded path
    for (r, g) in rows.iter().zip(&survey) {
        let md_ft: f64 = g[0].parse().expect("md");
        let tvd_ft: f64 = g[3].parse().expect("tvd");
        assert!((r[c_md] - md_ft * ft).abs() < 1e-9, "MD {md_ft} ft");
        assert!(
            (r[c_tvd] - tvd_ft * ft).abs() < 0.05 * ft,
            "MD {md_ft} ft: TVD {} m vs typed {} m",
            r[c_tvd],
            tvd_ft * ft
        );
    }

    let reference = hpt_totals_well2();
    assert_eq!(reference.len(), 7, "{reference:?}");
    let mut failures = Vec::new();
    let (mut worst_rel, mut worst_abs): (f64, f64) = (0.0, 0.0);
    for (md_m, c) in &reference {
        let md: f64 = md_m.parse().expect("md");
        let r = rows
            .iter()
            .find(|r| (r[c_md] - md).abs() < 0.006)
            .unwrap_or_else(|| panic!("no station at {md_m} m"));
        // sigma_* are 1-sigma, m: squared to the reference's m^2
        let k = (-2.0 * (1.0 - r[c_conf]).ln()).sqrt();
        let (nn, ee, ne) = (c[0], c[1], c[3]);
        let half = (0.5 * (nn - ee)).hypot(ne);
        let checks = [
            ("NN", r[c_sn].powi(2), nn),
            ("EE", r[c_se].powi(2), ee),
            ("VV", r[c_sv].powi(2), c[2]),
            // the ellipse's 1-sigma semi-axes squared are the eigenvalues of
            // the NE block: this brings NE into the comparison
            ("major", (r[c_major] / k).powi(2), 0.5 * (nn + ee) + half),
            ("minor", (r[c_minor] / k).powi(2), 0.5 * (nn + ee) - half),
        ];
        for (what, got, want) in checks {
            let d = (got - want).abs();
            worst_abs = worst_abs.max(d);
            worst_rel = worst_rel.max(d / want.abs());
            println!(
                "well 2 MD {md_m} m ({:.2} ft) {what}: {got:.4} vs {want:.4} m2 ({:+.3} %)",
                md / ft,
                100.0 * (got - want) / want
            );
            if !close(got, want) {
                failures.push(format!("MD {md_m} m {what}: {got} vs {want} m2"));
            }
        }
    }
    println!(
        "well 2 through the CLI: worst difference {worst_abs:.2e} m2, worst relative {:.3} %",
        100.0 * worst_rel
    );
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    // and the +-1 % acceptance the brief quotes (every compared value here
    // is >= 0.24 m^2, so the relative test is meaningful at each)
    assert!(worst_rel < 0.01, "worst relative {worst_rel}");
}
