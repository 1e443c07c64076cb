//! ISCWSA MWD Rev 5 error model against the published diagnostic NEV
//! covariances of the three ISCWSA test wells (`tests/data/iscwsa/`).
//!
//! References: the workbooks' "Diagnostic Values" blocks (Copsegrove), and
//! the newer HPT Rev 5.1 diagnostics (selected rows: DEC-OH, XCLA, TOTAL).
//!
//! Tolerance: the references are printed to 4 decimals (m^2), i.e. each
//! carries up to 5e-5 m^2 of rounding; the test wells' TVDs and the
//! workbook's own intermediate rounding add a little more (the ISCWSA
//! workbook itself reproduces its diagnostic block only to 9.8e-5 m^2 on
//! well #1 and 4.6e-4 m^2 on well #2, tests/data/iscwsa/README.md). A value
//! passes if it is within `abs_tol` or within REL_TOL of the reference.

use host_sim::survey::iscwsa::{
    check_stations, load_term_table, run, run_with, Cov6, ErrorTerm, ModelResult, Options, Site,
    Station,
};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

fn data_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/data/iscwsa")
}

/// The term tables the `survey` command embeds (moved from tests/data/iscwsa).
fn tool_data_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("data")
}

struct Well {
    site: Site,
    stations: Vec<Station>,
    /// to metres
    unit: f64,
    /// (md as published, source) -> covariance
    reference: BTreeMap<(String, String), Cov6>,
}

fn load_well(key: &str) -> Result<Well, String> {
    let dir = data_dir();
    let text =
        std::fs::read_to_string(dir.join("wells.json")).map_err(|e| format!("wells.json: {e}"))?;
    let json: serde_json::Value =
        serde_json::from_str(&text).map_err(|e| format!("wells.json: {e}"))?;
    let w = json.get(key).ok_or(format!("wells.json: no {key}"))?;
    let f = |name: &str| -> Result<f64, String> {
        w.get(name)
            .and_then(serde_json::Value::as_f64)
            .ok_or(format!("wells.json {key}: no number {name}"))
    };
    let s = |name: &str| -> Result<String, String> {
        w.get(name)
            .and_then(serde_json::Value::as_str)
            .map(str::to_string)
            .ok_or(format!("wells.json {key}: no string {name}"))
    };
    if f("grid_convergence_deg")? != 0.0 {
        return Err("grid convergence not modelled".into());
    }
    let unit = match s("depth_units")?.as_str() {
        "m" => 1.0,
        "ft" => f("feet_to_metres")?,
        other => return Err(format!("unknown depth unit {other}")),
    };
    let site = Site {
        gravity: f("gravity_m_per_s2")?,
        b_total: f("b_total_nT")?,
        dip: f("dip_deg")?.to_radians(),
        declination: f("declination_deg")?.to_radians(),
        vertical_limit: f("vertical_inc_limit_deg")?.to_radians(),
        latitude: f("latitude_deg")?.to_radians(),
        gyro_noise_reduction: 1.0,
    };
    let mut stations = Vec::new();
    let survey = dir.join(s("survey_file")?);
    let mut rdr =
        csv::Reader::from_path(&survey).map_err(|e| format!("{}: {e}", survey.display()))?;
    for rec in rdr.records() {
        let rec = rec.map_err(|e| format!("{}: {e}", survey.display()))?;
        let v = |i: usize| -> Result<f64, String> {
            rec.get(i)
                .ok_or(format!("{}: short row", survey.display()))?
                .trim()
                .parse::<f64>()
                .map_err(|e| format!("{}: {e}", survey.display()))
        };
        stations.push(Station {
            md: v(0)? * unit,
            inc: v(1)?.to_radians(),
            azi: v(2)?.to_radians(),
            tvd: v(3)? * unit,
            toolface: None,
        });
    }
    let mut reference = BTreeMap::new();
    let cov = dir.join(s("diagnostic_covariance_file")?);
    let mut rdr = csv::Reader::from_path(&cov).map_err(|e| format!("{}: {e}", cov.display()))?;
    for rec in rdr.records() {
        let rec = rec.map_err(|e| format!("{}: {e}", cov.display()))?;
        let get = |i: usize| rec.get(i).ok_or(format!("{}: short row", cov.display()));
        let mut c = [0.0; 6];
        for (j, cj) in c.iter_mut().enumerate() {
            *cj = get(2 + j)?
                .trim()
                .parse()
                .map_err(|e| format!("{}: {e}", cov.display()))?;
        }
        reference.insert((get(0)?.trim().to_string(), get(1)?.trim().to_string()), c);
    }
    check_stations(&stations).map_err(|e| format!("{}: {e}", survey.display()))?;
    Ok(Well {
        site,
        stations,
        unit,
        reference,
    })
}

/// The Rev 5.10 term table (`mwd_rev5_model_terms.csv`) as published.
fn terms_5_10() -> Result<Vec<ErrorTerm>, String> {
    load_term_table(&tool_data_dir().join("mwd_rev5_model_terms.csv")).map_err(|e| e.to_string())
}

/// The term set the workbook diagnostic block was produced with: Rev 5.10
/// (XYM2 systematic, XYM4E random, enhanced XYM3E/XYM4E, XCLA/XCLH) but
/// DEC-OH 0.20 deg (tests/data/iscwsa/README.md, Doubt 1: the diagnostic
/// DEC-OH is exactly (0.20/0.21)^2 of the 5.10 value).
fn terms_diagnostic() -> Result<Vec<ErrorTerm>, String> {
    let mut terms = terms_5_10()?;
    let dec_oh = terms
        .iter_mut()
        .find(|t| t.code == "DEC-OH")
        .ok_or("no DEC-OH in the 5.10 table")?;
    if (dec_oh.magnitude - 0.21).abs() > 1e-12 {
        return Err(format!(
            "DEC-OH in the 5.10 table is {} deg, expected 0.21",
            dec_oh.magnitude
        ));
    }
    dec_oh.magnitude = 0.20;
    dec_oh.magnitude_si = 0.20_f64.to_radians();
    Ok(terms)
}

fn model(well: &Well) -> Result<ModelResult, String> {
    Ok(run_with(
        &terms_diagnostic()?,
        &well.stations,
        &well.site,
        Options::REV5_DIAGNOSTIC,
    ))
}

fn station_index(well: &Well, md_text: &str) -> Result<usize, String> {
    let md: f64 = md_text.parse().map_err(|e| format!("md {md_text}: {e}"))?;
    well.stations
        .iter()
        .position(|s| (s.md - md * well.unit).abs() < 1e-6)
        .ok_or(format!("no station at MD {md_text}"))
}

const EL: [&str; 6] = ["NN", "EE", "VV", "NE", "NV", "EV"];

/// Rounding of the references (5e-5) plus the workbook's own reproduction
/// error on well #1 (9.8e-5 m^2, README): 1e-4 m^2. Well #2 (feet, deep
/// and turning): the ISCWSA workbook itself reproduces the diagnostic block
/// only to 4.6e-4 m^2 there, so 5e-4 m^2.
fn abs_tol(well_key: &str) -> f64 {
    if well_key == "iscwsa_2" {
        5e-4
    } else {
        1e-4
    }
}
/// For the large elements: 0.5 % (the brief's aim is 1 %).
const REL_TOL: f64 = 5e-3;

/// Compares the computed covariance of `source` (or `TOTAL`) with every
/// reference row of it; prints one line per depth with each element's
/// relative error; returns the failures and the worst relative error over
/// elements with |ref| >= 0.01 m^2.
fn compare(
    well_key: &str,
    well: &Well,
    res: &ModelResult,
    source: &str,
    reference: &BTreeMap<(String, String), Cov6>,
) -> Result<(Vec<String>, f64), String> {
    let mut failures = Vec::new();
    let mut worst_rel: f64 = 0.0;
    for ((md, src), refc) in reference {
        if src != source {
            continue;
        }
        let k = station_index(well, md)?;
        let got = if source == "TOTAL" || source == "Totals" {
            res.total[k]
        } else {
            res.per_source.get(source).ok_or(format!(
                "{well_key}: {source} not computed (missing: {:?})",
                res.missing
            ))?[k]
        };
        let mut line = format!("{well_key} {source} MD {md}:");
        for j in 0..6 {
            let d = got[j] - refc[j];
            let rel = if refc[j] != 0.0 {
                d / refc[j].abs()
            } else {
                0.0
            };
            if refc[j].abs() >= 0.01 {
                worst_rel = worst_rel.max(rel.abs());
            }
            if d.abs() > abs_tol(well_key) && rel.abs() > REL_TOL {
                failures.push(format!(
                    "{well_key} {source} MD {md} {}: {} vs {} m2",
                    EL[j], got[j], refc[j]
                ));
            }
            line += &format!(
                " {} {:.4}/{:.4} ({:+.3}%)",
                EL[j],
                got[j],
                refc[j],
                100.0 * rel
            );
        }
        println!("{line}");
    }
    Ok((failures, worst_rel))
}

const WELLS: [&str; 3] = ["iscwsa_1", "iscwsa_2", "iscwsa_3"];

#[test]
fn every_source_matches_the_diagnostic_block_of_the_three_wells() {
    let mut failures = Vec::new();
    for w in WELLS {
        let well = load_well(w).unwrap_or_else(|e| panic!("{e}"));
        let res = model(&well).unwrap_or_else(|e| panic!("{e}"));
        assert!(
            res.missing.is_empty(),
            "{w}: not implemented: {:?}",
            res.missing
        );
        let mut srcs: Vec<&String> = well.reference.keys().map(|k| &k.1).collect();
        srcs.sort();
        srcs.dedup();
        // all 35 sources + TOTAL are tabulated
        assert_eq!(srcs.len(), 36, "{w}: {srcs:?}");
        for s in srcs {
            let (f, worst) =
                compare(w, &well, &res, s, &well.reference).unwrap_or_else(|e| panic!("{e}"));
            println!(
                "== {w} {s}: worst rel error (|ref| >= 0.01 m2) {:.3} %",
                100.0 * worst
            );
            failures.extend(f);
        }
    }
    assert!(
        failures.is_empty(),
        "{} values out of tolerance:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

fn load_hpt() -> Result<BTreeMap<(String, String, String), Cov6>, String> {
    let path = data_dir().join("mwd_rev5_1_hpt_diagnostics_selected_rows.csv");
    let mut rdr = csv::Reader::from_path(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut out = BTreeMap::new();
    for rec in rdr.records() {
        let rec = rec.map_err(|e| format!("{}: {e}", path.display()))?;
        let get = |i: usize| {
            rec.get(i)
                .map(str::trim)
                .ok_or(format!("{}: short row", path.display()))
        };
        let mut c = [0.0; 6];
        for (j, cj) in c.iter_mut().enumerate() {
            *cj = get(3 + j)?
                .parse()
                .map_err(|e| format!("{}: {e}", path.display()))?;
        }
        out.insert(
            (
                get(0)?.to_string(),
                get(1)?.to_string(),
                get(2)?.to_string(),
            ),
            c,
        );
    }
    Ok(out)
}

/// The HPT Rev 5.1 diagnostics were produced with the 5.10 table as
/// published (DEC-OH 0.21 deg) and the 5.10 XCLA sine term: DEC-OH, XCLA
/// and TOTAL rows.
#[test]
fn rev5_10_table_matches_the_hpt_5_1_diagnostics() {
    let hpt = load_hpt().unwrap_or_else(|e| panic!("{e}"));
    let terms = terms_5_10().unwrap_or_else(|e| panic!("{e}"));
    let mut failures = Vec::new();
    let mut rows = 0;
    for (n, w) in WELLS.iter().enumerate() {
        let well = load_well(w).unwrap_or_else(|e| panic!("{e}"));
        let res = run(&terms, &well.stations, &well.site);
        assert!(
            res.missing.is_empty(),
            "{w}: not implemented: {:?}",
            res.missing
        );
        // MD printed in metres (2 decimals) for all wells: re-key by the
        // station's MD in the well's own unit
        let mut reference = BTreeMap::new();
        for ((wn, md_m, src), c) in &hpt {
            if wn != &(n + 1).to_string() {
                continue;
            }
            let md: f64 = md_m.parse().unwrap_or_else(|e| panic!("md {md_m}: {e}"));
            let st = well
                .stations
                .iter()
                .find(|s| (s.md - md).abs() < 0.006)
                .unwrap_or_else(|| panic!("{w}: no station at {md_m} m"));
            reference.insert((format!("{}", st.md / well.unit), src.clone()), *c);
        }
        for s in ["DEC-OH", "XCLA", "TOTAL"] {
            let (f, worst) =
                compare(w, &well, &res, s, &reference).unwrap_or_else(|e| panic!("{e}"));
            println!(
                "== HPT {w} {s}: worst rel error (|ref| >= 0.01 m2) {:.3} %",
                100.0 * worst
            );
            failures.extend(f);
        }
        rows += reference.len();
    }
    // 15 depths x (DEC-OH, XCLA, TOTAL)
    assert_eq!(rows, 45);
    assert!(
        failures.is_empty(),
        "{} values out of tolerance:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

/// The XCLA variants differ where the azimuth turns hard: well #3, 4030 m,
/// NN 3.3030 (diagnostic block, |dA|) vs 3.2785 m^2 (HPT, sin |dA|).
#[test]
fn xcla_sine_term_separates_the_two_reference_generations() {
    let well = load_well("iscwsa_3").unwrap_or_else(|e| panic!("{e}"));
    let terms = terms_5_10().unwrap_or_else(|e| panic!("{e}"));
    let k = station_index(&well, "4030").unwrap_or_else(|e| panic!("{e}"));
    let nn = |o: Options| run_with(&terms, &well.stations, &well.site, o).per_source["XCLA"][k][0];
    assert!((nn(Options::REV5_DIAGNOSTIC) - 3.3030).abs() < 5e-5);
    assert!((nn(Options::REV5_10) - 3.2785).abs() < 5e-5);
}

/// The check can fail: the 5.10 table's DEC-OH (0.21 deg) is 10.25 % off
/// the diagnostic block wherever DEC-OH is not zero.
#[test]
fn unmodified_dec_oh_does_not_match_the_diagnostic_block() {
    let well = load_well("iscwsa_1").unwrap_or_else(|e| panic!("{e}"));
    let terms = terms_5_10().unwrap_or_else(|e| panic!("{e}"));
    let res = run(&terms, &well.stations, &well.site);
    let (failures, worst) = compare("iscwsa_1", &well, &res, "DEC-OH", &well.reference)
        .unwrap_or_else(|e| panic!("{e}"));
    assert!(!failures.is_empty());
    assert!((worst - 0.1025).abs() < 2e-3, "worst {worst}");
}

/// ISCWSA MWD Rev 4 (27 terms: DECG, DBHG, SAG, XYM3, XYM4 ...) against the
/// Rev 4 diagnostic block of well #1 (the only Rev 4 reference), with the
/// tie-on taken as exact (with the Rev 5 convention ABXY-TI1S is 2.6 % off
/// at 1200 m: 0.2396 vs 0.2336 m^2, see the next test).
#[test]
fn rev4_table_matches_the_rev4_diagnostic_block_of_well_1() {
    let mut well = load_well("iscwsa_1").unwrap_or_else(|e| panic!("{e}"));
    let path = data_dir().join("mwd_rev4_well1_diagnostic_cov.csv");
    let mut rdr =
        csv::Reader::from_path(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut reference = BTreeMap::new();
    for rec in rdr.records() {
        let rec = rec.unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let get = |i: usize| {
            rec.get(i)
                .map(str::trim)
                .unwrap_or_else(|| panic!("short row"))
        };
        let mut c = [0.0; 6];
        for (j, cj) in c.iter_mut().enumerate() {
            *cj = get(2 + j)
                .parse()
                .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        }
        reference.insert((get(0).to_string(), get(1).to_string()), c);
    }
    well.reference = reference;
    let terms = load_term_table(&data_dir().join("mwd_rev4_model_terms.csv"))
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(terms.len(), 27);
    let res = run_with(&terms, &well.stations, &well.site, Options::REV4);
    assert!(res.missing.is_empty(), "not implemented: {:?}", res.missing);
    let mut srcs: Vec<String> = well.reference.keys().map(|k| k.1.clone()).collect();
    srcs.sort();
    srcs.dedup();
    assert_eq!(srcs.len(), 28, "{srcs:?}");
    let mut failures = Vec::new();
    for s in &srcs {
        let (f, worst) =
            compare("iscwsa_1", &well, &res, s, &well.reference).unwrap_or_else(|e| panic!("{e}"));
        println!(
            "== Rev4 iscwsa_1 {s}: worst rel error (|ref| >= 0.01 m2) {:.3} %",
            100.0 * worst
        );
        failures.extend(f);
    }
    assert!(
        failures.is_empty(),
        "{} values out of tolerance:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

/// The tie-on convention is visible: Rev 5's convention on the Rev 4 data
/// misses ABXY-TI1S at 1200 m by (1200/1185)^2 - 1 = 2.5 %.
#[test]
fn tie_on_convention_matters_for_rev4() {
    let well = load_well("iscwsa_1").unwrap_or_else(|e| panic!("{e}"));
    let terms = load_term_table(&data_dir().join("mwd_rev4_model_terms.csv"))
        .unwrap_or_else(|e| panic!("{e}"));
    let k = station_index(&well, "1200").unwrap_or_else(|e| panic!("{e}"));
    let nn =
        |t: Options| run_with(&terms, &well.stations, &well.site, t).per_source["ABXY-TI1S"][k][0];
    // published Rev 4: 0.2336 m^2
    assert!((nn(Options::REV4) - 0.2336).abs() < 5e-5);
    assert!((nn(Options::REV5_DIAGNOSTIC) - 0.2336).abs() > 5e-3);
}

/// Dense regression: the WB5.10-#1 workbook's own calculated TOTALS (5.10
/// table as published, DEC-OH 0.21 deg) at all 268 stations of well #1.
/// These are unrounded doubles, so the tolerance is tighter: 1e-5 relative
/// (the survey file's TVDs, used by DSTG, are typed to 0.01 m) and 1e-4 m^2.
#[test]
fn rev5_10_totals_of_well_1_at_every_station() {
    let well = load_well("iscwsa_1").unwrap_or_else(|e| panic!("{e}"));
    let terms = terms_5_10().unwrap_or_else(|e| panic!("{e}"));
    let res = run(&terms, &well.stations, &well.site);
    let path = data_dir().join("mwd_rev5_well1_workbook_totals_nev.csv");
    let mut rdr =
        csv::Reader::from_path(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut n = 0;
    let mut worst_rel: f64 = 0.0;
    let mut worst_abs: f64 = 0.0;
    for (k, rec) in rdr.records().enumerate() {
        let rec = rec.unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let v: Vec<f64> = rec
            .iter()
            .map(|f| {
                f.trim()
                    .parse::<f64>()
                    .unwrap_or_else(|e| panic!("{}: {f:?}: {e}", path.display()))
            })
            .collect();
        assert_eq!(v.len(), 7);
        assert!(
            (v[0] - well.stations[k].md).abs() < 1e-9,
            "row {k}: MD {}",
            v[0]
        );
        for j in 0..6 {
            let d = (res.total[k][j] - v[1 + j]).abs();
            worst_abs = worst_abs.max(d);
            if v[1 + j].abs() > 1e-2 {
                worst_rel = worst_rel.max(d / v[1 + j].abs());
            }
        }
        n += 1;
    }
    println!("WB5.10-#1 TOTALS, {n} stations: worst abs {worst_abs:.3e} m2, worst rel (|ref| > 0.01) {worst_rel:.3e}");
    assert_eq!(n, well.stations.len());
    assert!(
        worst_rel < 1e-6 && worst_abs < 1e-4,
        "worst rel {worst_rel}, abs {worst_abs}"
    );
}

/// The OWSG gyro models (GYRO-MWD, GYRO-NS) load and run with every term
/// implemented. No published covariances exist for them on the test wells,
/// so this checks only what must hold: the tables read, the deg/hr
/// magnitudes converted, every covariance finite with non-negative
/// variances, and GYRO-NS (same terms, gyro magnitudes no larger) never
/// less accurate than GYRO-MWD. Well #1 is used up to the last station
/// within the models' 89 deg inclination range.
#[test]
fn owsg_gyro_models_run_on_well_1() {
    let mut well = load_well("iscwsa_1").unwrap_or_else(|e| panic!("{e}"));
    let last = well
        .stations
        .iter()
        .position(|s| s.inc > 89_f64.to_radians())
        .unwrap_or(well.stations.len());
    well.stations.truncate(last);
    assert!(well.stations.len() > 100);
    let load =
        |f: &str| load_term_table(&tool_data_dir().join(f)).unwrap_or_else(|e| panic!("{e}"));
    let mwd = load("owsg_gyro_mwd_terms.csv");
    let ns = load("owsg_gyro_ns_terms.csv");
    assert_eq!((mwd.len(), ns.len()), (18, 18));
    let rn = mwd
        .iter()
        .find(|t| t.code == "GXY-RN")
        .unwrap_or_else(|| panic!("no GXY-RN"));
    assert!((rn.magnitude_si - 0.6_f64.to_radians() / 3600.0).abs() < 1e-15);
    let a = run(&mwd, &well.stations, &well.site);
    let b = run(&ns, &well.stations, &well.site);
    assert!(
        a.missing.is_empty() && b.missing.is_empty(),
        "{:?} {:?}",
        a.missing,
        b.missing
    );
    for (k, (ca, cb)) in a.total.iter().zip(&b.total).enumerate() {
        assert!(ca.iter().chain(cb).all(|x| x.is_finite()), "station {k}");
        assert!(
            ca[..3].iter().chain(&cb[..3]).all(|&x| x >= 0.0),
            "station {k}"
        );
        assert!(cb[0] + cb[1] <= ca[0] + ca[1] + 1e-12, "station {k}");
    }
    let k = well.stations.len() - 1;
    println!(
        "OWSG on well #1 to MD {} m: GYRO-MWD NN {:.3} EE {:.3} VV {:.3} m2; GYRO-NS NN {:.3} EE {:.3} VV {:.3} m2",
        well.stations[k].md, a.total[k][0], a.total[k][1], a.total[k][2], b.total[k][0], b.total[k][1], b.total[k][2]
    );
}
