//! `host-sim survey --offset` through the binary: the ISCWSA separation
//! factor of two parallel vertical wells recomputed by hand from the
//! exported covariances, the rule's violation flagged, SF undetermined
//! without covariances, and bad offset input refused.

mod common;

use common::{refused, s, Run, WELL1_SITE};
use std::path::PathBuf;

fn host_sim(args: &[&str]) -> Run {
    common::run(&[&["survey"], args].concat())
}

fn scratch(name: &str) -> PathBuf {
    common::scratch("survey-sep", name)
}

/// A vertical well, 0 to 1500 m every 100 m.
fn vertical(dir: &std::path::Path, name: &str) -> PathBuf {
    let mut text = String::from("md_m,inc_deg,azi_deg\n");
    for i in 0..=15 {
        text += &format!("{},0,0\n", 100 * i);
    }
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

/// Runs two vertical wells `north` m apart; returns the run and the JSON.
fn parallel(name: &str, north: &str, model: bool) -> (Run, serde_json::Value) {
    let dir = scratch(name);
    let a = vertical(&dir, "a.csv");
    let b = vertical(&dir, "b.csv");
    let json = dir.join("out.json");
    let mut args = vec![s(&a)];
    if model {
        // ISCWSA well 1's site, with the model
        args.extend_from_slice(&WELL1_SITE);
        args.extend_from_slice(&["--error-model", "ISCWSA MWD Rev5"]);
    }
    args.extend_from_slice(&[
        "--offset",
        s(&b),
        "--offset-tie-on-north",
        north,
        "--hole-radius-m",
        "0.108",
        "--offset-hole-radius-m",
        "0.156",
        "--json",
        s(&json),
    ]);
    let run = host_sim(&args);
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    let doc = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    (run, doc)
}

fn num(v: &serde_json::Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

#[test]
fn parallel_vertical_wells_give_the_hand_computed_sf() {
    let (run, doc) = parallel("parallel", "25", true);
    let stations = doc["stations"].as_array().unwrap();
    let mut min = (f64::INFINITY, 0.0);
    for st in stations {
        let md = num(&st["md_m"]);
        assert!((num(&st["ctc_m"]) - 25.0).abs() < 1e-6, "{st}");
        assert!((num(&st["offset_md_m"]) - md).abs() < 1e-4, "{st}");
        // the centre-to-centre direction is north: sigma_S^2 = NN + NN'
        let nn_ref = num(&st["nev_covariance_m2"][0]);
        let nn_off = num(&st["offset_nev_covariance_m2"][0]);
        let sigma_s = (nn_ref + nn_off).sqrt();
        assert!((num(&st["sigma_s_m"]) - sigma_s).abs() < 1e-9);
        // SF = (D - R_ref - R_off - S_m) / (k sqrt(sigma_S^2 + sigma_pa^2))
        let sf = (25.0 - 0.108 - 0.156 - 0.3) / (3.5 * (sigma_s * sigma_s + 0.25).sqrt());
        assert!((num(&st["sf"]) - sf).abs() < 1e-9 * sf, "{st}: {sf}");
        if sf < min.0 {
            min = (sf, md);
        }
    }
    // the errors grow with depth: the minimum is at the deepest station
    assert_eq!(min.1, 1500.0);
    let sep = &doc["separation"];
    assert!((num(&sep["min_sf"]) - min.0).abs() < 1e-12);
    assert_eq!(num(&sep["min_sf_md_m"]), min.1);
    assert_eq!(sep["violation"], min.0 < 1.0);
    assert!(
        run.stdout
            .contains(&format!("minimum SF {:.3} at MD 1500.00 m", min.0)),
        "{}",
        run.stdout
    );
}

#[test]
fn close_wells_violate_the_rule() {
    let (run, doc) = parallel("close", "3", true);
    assert_eq!(doc["separation"]["violation"], true);
    let stations = doc["stations"].as_array().unwrap();
    let violations = stations
        .iter()
        .filter(|st| st["sf_status"] == "violation")
        .count();
    assert!(violations > 0);
    for st in stations {
        let sf = num(&st["sf"]);
        assert_eq!(st["sf_status"] == "violation", sf < 1.0, "{st}");
    }
    assert!(
        run.stdout.contains(&format!(
            "VIOLATION of the separation rule (SF < 1) at {violations} stations"
        )),
        "{}",
        run.stdout
    );
    assert!(run.stdout.contains("SF<1"));
}

#[test]
fn without_covariance_sf_is_undetermined() {
    let (run, doc) = parallel("nomodel", "25", false);
    for st in doc["stations"].as_array().unwrap() {
        assert!((num(&st["ctc_m"]) - 25.0).abs() < 1e-6);
        assert!(st["sf"].is_null(), "{st}");
        assert_eq!(st["sf_status"], "undetermined");
    }
    assert!(doc["separation"]["min_sf"].is_null());
    assert!(
        run.stdout.contains("minimum SF undetermined"),
        "{}",
        run.stdout
    );
    assert!(run.stdout.contains("SF undetermined"));
}

#[test]
fn bad_offset_input_is_refused() {
    let dir = scratch("bad");
    let a = vertical(&dir, "a.csv");
    let radii = ["--hole-radius-m", "0.1", "--offset-hole-radius-m", "0.1"];
    let missing = dir.join("missing.csv");
    let mut args = vec![s(&a), "--offset", s(&missing)];
    args.extend_from_slice(&radii);
    refused(&host_sim(&args), "missing.csv");

    let bad = dir.join("bad.csv");
    std::fs::write(&bad, "md_m,inc_deg,azi_deg\n0,0,0\n100,0,0\n50,0,0\n").unwrap();
    let mut args = vec![s(&a), "--offset", s(&bad)];
    args.extend_from_slice(&radii);
    refused(&host_sim(&args), "MD must increase");

    let feet = dir.join("feet.csv");
    std::fs::write(&feet, "md_ft,inc_deg,azi_deg\n0,0,0\n100,0,0\n").unwrap();
    let mut args = vec![s(&a), "--offset", s(&feet)];
    args.extend_from_slice(&radii);
    refused(&host_sim(&args), "length unit");

    let b = vertical(&dir, "b.csv");
    refused(&host_sim(&[s(&a), "--offset", s(&b)]), "--hole-radius-m");
    refused(
        &host_sim(&[s(&a), "--offset", s(&b), "--hole-radius-m", "-1"]),
        "hole radius",
    );
    let mut args = vec![s(&a), "--offset", s(&b), "--offset-tie-on-md", "5"];
    args.extend_from_slice(&radii);
    refused(&host_sim(&args), "tie-on MD");
    let mut args = vec![s(&a), "--offset", s(&b), "--offset-error-model", "nonsense"];
    args.extend_from_slice(&radii);
    refused(&host_sim(&args), "unknown error model");
    // offset options without an offset well are a mistake, not ignored
    refused(
        &host_sim(&[s(&a), "--hole-radius-m", "0.1"]),
        "needs --offset",
    );
}
