//! `host-sim survey --error-model PROBE-SCC1300` through the binary: the
//! probe's own tool model (docs/probe-tool-model.md) gives a horizontal
//! lateral heading north a covariance, flags one heading east as
//! undetermined, and is listed among the known models.

mod common;

use common::{s, Run};
use std::path::{Path, PathBuf};

fn host_sim(args: &[&str]) -> Run {
    common::run(&[&["survey"], args].concat())
}

/// A station file of a 1000 m lateral at 90 deg from a tie-on at MD 0,
/// stations 30 m apart (the last at 1000 m); `azi(md)` gives each
/// station's azimuth, `toolface(k)` an optional toolface column.
fn lateral(
    name: &str,
    azi: impl Fn(f64) -> f64,
    toolface: Option<&dyn Fn(usize) -> f64>,
) -> PathBuf {
    let dir = common::scratch("survey-probe-cli", name);
    let path = dir.join("stations.csv");
    let mut text = String::from("md_m,inc_deg,azi_deg");
    if toolface.is_some() {
        text += ",toolface_deg";
    }
    text += "\n";
    let mut mds: Vec<f64> = (0..34).map(|k| k as f64 * 30.0).collect();
    mds.push(1000.0);
    for (k, md) in mds.into_iter().enumerate() {
        text += &format!("{md},90,{}", azi(md));
        if let Some(tf) = toolface {
            text += &format!(",{}", tf(k));
        }
        text += "\n";
    }
    std::fs::write(&path, text).unwrap();
    path
}

/// Rows of the output CSV as (header, rows).
fn csv_rows(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines
        .map(|l| l.split(',').map(String::from).collect())
        .collect();
    (header, rows)
}

fn col(header: &[String], name: &str) -> usize {
    header
        .iter()
        .position(|h| h == name)
        .unwrap_or_else(|| panic!("no column {name}"))
}

/// Runs the probe model on `stations` at latitude 45 deg, CSV out.
fn probe(stations: &Path, name: &str) -> (Run, Vec<String>, Vec<Vec<String>>) {
    let out = common::scratch("survey-probe-cli", name).join("out.csv");
    let run = host_sim(&[
        s(stations),
        "--lat",
        "45",
        "--error-model",
        "PROBE-SCC1300",
        "--csv",
        s(&out),
    ]);
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    assert!(!run.stderr.contains("panicked"), "{}", run.stderr);
    let (h, r) = csv_rows(&out);
    (run, h, r)
}

/// The OWSG gyro models stop at 89 deg; the probe model gives a lateral
/// at 90 deg heading north a covariance at every station, the cross-hole
/// (east) sigma growing along the hole, and no validity note.
#[test]
fn lateral_heading_north_gets_covariances() {
    let (run, h, rows) = probe(&lateral("north", |_| 0.0, None), "north");
    assert!(!run.stdout.contains("outside the model's validity"));
    assert!(!run.stdout.contains("note:"), "{}", run.stdout);
    let (valid, se) = (col(&h, "error_model_valid"), col(&h, "sigma_east_m"));
    let mut prev = 0.0;
    for (k, r) in rows.iter().enumerate() {
        assert_eq!(r[valid], "true", "station {k}");
        let sigma: f64 = r[se].parse().unwrap();
        assert!(sigma.is_finite(), "station {k}");
        if k > 0 {
            assert!(sigma > prev, "station {k}: {sigma} after {prev}");
        }
        prev = sigma;
    }
    // GYRO-MWD refuses the same file from the tie-on on (89 deg limit)
    let gyro = host_sim(&[
        s(&lateral("north-owsg", |_| 0.0, None)),
        "--lat",
        "45",
        "--error-model",
        "GYRO-MWD",
    ]);
    assert_eq!(gyro.code, Some(0), "{}", gyro.stderr);
    assert!(gyro.stdout.contains("stated for inclinations up to 89 deg"));
}

/// Heading east the horizontal probe cannot gyrocompass: every station is
/// flagged, no number is printed for any, the note gives the reason.
#[test]
fn lateral_heading_east_is_flagged_undetermined() {
    let (run, h, rows) = probe(&lateral("east", |_| 90.0, None), "east");
    assert!(
        run.stdout.contains("azimuth undetermined"),
        "{}",
        run.stdout
    );
    assert!(run.stdout.contains("outside the model's validity"));
    assert!(run.stdout.contains("(station 0)"), "{}", run.stdout);
    let (valid, sn) = (col(&h, "error_model_valid"), col(&h, "sigma_north_m"));
    assert!(rows.iter().all(|r| r[valid] == "false" && r[sn].is_empty()));
}

/// A lateral turning from north to east: covariances up to the first
/// station within 5.7 deg of east, none from there on.
#[test]
fn lateral_turning_east_is_flagged_from_the_first_undetermined_station() {
    // azimuth 0 at 0 and 30 m, then 3 deg per 30 m: 84 deg at 870 m
    // (S = 0.105, still determined), 87 deg at 900 m (S = 0.052)
    let azi = |md: f64| ((md - 30.0).max(0.0) / 10.0).min(90.0);
    let (run, h, rows) = probe(&lateral("turn", azi, None), "turn");
    let (valid, md) = (col(&h, "error_model_valid"), col(&h, "md_m"));
    let first_bad = rows.iter().position(|r| r[valid] == "false").unwrap();
    assert_eq!(rows[first_bad][md].parse::<f64>().unwrap(), 900.0);
    assert!(rows[..first_bad].iter().all(|r| r[valid] == "true"));
    assert!(rows[first_bad..].iter().all(|r| r[valid] == "false"));
    assert!(
        run.stdout.contains("no uncertainty from MD 900.00 m"),
        "{}",
        run.stdout
    );
}

/// With the toolface column the bias terms are projected per gyro; without
/// it they take a bound valid for any toolface, so the sigmas are no
/// smaller.
#[test]
fn toolface_column_is_used_and_the_bound_covers_it() {
    let tf = |k: usize| (k * 47 % 360) as f64;
    let (_, h, with) = probe(&lateral("tf", |_| 30.0, Some(&tf)), "tf");
    let (_, _, without) = probe(&lateral("no-tf", |_| 30.0, None), "no-tf");
    let major = col(&h, "ellipse_semi_major_m");
    let (a, b): (f64, f64) = (
        with.last().unwrap()[major].parse().unwrap(),
        without.last().unwrap()[major].parse().unwrap(),
    );
    assert!(a.is_finite() && a > 0.0);
    assert!(a <= b, "with toolface {a} m, bound {b} m");
    assert!(a < 0.99 * b, "the toolface changed nothing: {a} vs {b}");
}

/// The model is among the names `--error-model` lists (the message of an
/// unknown name), and its name is matched ignoring case.
#[test]
fn model_listing_includes_the_probe_model() {
    let stations = lateral("names", |_| 0.0, None);
    let run = host_sim(&[s(&stations), "--error-model", "NO SUCH MODEL"]);
    assert!(matches!(run.code, Some(1 | 2)), "{:?}", run.code);
    assert!(run.stderr.contains("unknown error model"), "{}", run.stderr);
    assert!(run.stderr.contains("PROBE-SCC1300"), "{}", run.stderr);
    let lower = host_sim(&[s(&stations), "--error-model", "probe-scc1300"]);
    assert_eq!(lower.code, Some(0), "{}", lower.stderr);
    assert!(lower.stdout.contains("error model PROBE-SCC1300"));
}
