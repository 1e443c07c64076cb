//! `host-sim survey --error-model PROBE-SCC1300` and `--error-model-file`
//! through the binary: the probe's own tool model (docs/probe-tool-model.md)
//! flags a horizontal lateral heading north as undetermined at the SCC1300's
//! noise (the first-order model does not hold there), gives it covariances
//! with a gyro 100 times better (a table written from the shipped one),
//! flags one heading east as undetermined whatever the gyro, and is listed
//! among the known models.

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

/// Runs `host-sim survey` on `stations` at latitude 45 deg with these
/// model options, CSV out; it must succeed.
fn survey(stations: &Path, name: &str, model: &[&str]) -> (Run, Vec<String>, Vec<Vec<String>>) {
    let out = common::scratch("survey-probe-cli", name).join("out.csv");
    let run = host_sim(&[&[s(stations), "--lat", "45", "--csv", s(&out)], model].concat());
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    assert!(!run.stderr.contains("panicked"), "{}", run.stderr);
    let (h, r) = csv_rows(&out);
    (run, h, r)
}

/// The shipped PROBE-SCC1300 model.
fn probe(stations: &Path, name: &str) -> (Run, Vec<String>, Vec<Vec<String>>) {
    survey(stations, name, &["--error-model", "PROBE-SCC1300"])
}

/// The shipped probe table with every gyro term (`PRB-G*`) `factor` times
/// smaller, written with the csv crate (the table has quoted fields).
fn better_gyro_table(name: &str, factor: f64) -> PathBuf {
    let shipped = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/probe_scc1300_terms.csv");
    let mut rdr = csv::Reader::from_path(&shipped).unwrap();
    let header = rdr.headers().unwrap().clone();
    let wt = header.iter().position(|h| h == "Wt.Fn.").unwrap();
    let mag = header.iter().position(|h| h == "Magnitude").unwrap();
    let path = common::scratch("survey-probe-cli", name).join("terms.csv");
    let mut w = csv::Writer::from_path(&path).unwrap();
    w.write_record(&header).unwrap();
    let mut changed = 0;
    for rec in rdr.records() {
        let rec = rec.unwrap();
        let mut fields: Vec<String> = rec.iter().map(String::from).collect();
        if fields[wt].starts_with("PRB-G") {
            let m: f64 = fields[mag].parse().unwrap();
            fields[mag] = (m / factor).to_string();
            changed += 1;
        }
        w.write_record(&fields).unwrap();
    }
    w.flush().unwrap();
    assert_eq!(changed, 3, "PRB-GXB, PRB-GZB, PRB-GN");
    path
}

/// The same model with a gyro `factor` times better.
fn better_probe(stations: &Path, name: &str, factor: f64) -> (Run, Vec<String>, Vec<Vec<String>>) {
    let table = better_gyro_table(name, factor);
    survey(stations, name, &["--error-model-file", s(&table)])
}

/// The SCC1300 at one 120 s station: a lateral at 90 deg heading north at
/// 45 deg latitude has a single-station azimuth sigma of 31.5 deg (noise
/// 5.04 deg/h, two biases of 2.1 deg/h at their toolface bound, over a
/// horizontal earth rate of 10.6 deg/h), beyond the 10 deg to which the
/// first-order model holds: every station is flagged, no number printed,
/// the note gives the reason and the figure.
#[test]
fn scc1300_lateral_heading_north_is_undetermined_first_order() {
    let (run, h, rows) = probe(&lateral("north", |_| 0.0, None), "north");
    assert!(
        run.stdout.contains("first-order model not valid"),
        "{}",
        run.stdout
    );
    assert!(
        run.stdout
            .contains("single-station azimuth sigma 31.5 deg > 10.00 deg"),
        "{}",
        run.stdout
    );
    assert!(run.stdout.contains("(station 0)"), "{}", run.stdout);
    let (valid, sn) = (col(&h, "error_model_valid"), col(&h, "sigma_north_m"));
    assert!(rows.iter().all(|r| r[valid] == "false" && r[sn].is_empty()));
    // JSON carries the flag and the reason too
    let json = common::scratch("survey-probe-cli", "north-json").join("out.json");
    let run = host_sim(&[
        s(&lateral("north-json", |_| 0.0, None)),
        "--lat",
        "45",
        "--error-model",
        "PROBE-SCC1300",
        "--json",
        s(&json),
    ]);
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    let text = std::fs::read_to_string(&json).unwrap();
    assert!(text.contains("first-order model not valid"), "{text}");
    assert!(text.contains("\"error_model_valid\": false"));
    assert!(!text.contains("\"error_model_valid\": true"));
}

/// With a gyro 100 times better (0.05 deg/h noise, 0.021 deg/h biases:
/// single-station sigma 0.32 deg) the same lateral gets a covariance at
/// every station, the cross-hole (east) sigma growing along the hole, and
/// no validity note; the OWSG gyro models stop at 89 deg.
#[test]
fn better_gyro_lateral_heading_north_gets_covariances() {
    let (run, h, rows) = better_probe(&lateral("north-100", |_| 0.0, None), "north-100", 100.0);
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

/// Heading east the horizontal probe cannot gyrocompass, whatever its
/// gyro: every station is flagged by the sensitivity rule, no number is
/// printed for any, the note gives the reason.
#[test]
fn lateral_heading_east_is_flagged_undetermined() {
    for (name, factor) in [("east", None), ("east-100", Some(100.0))] {
        let stations = lateral(name, |_| 90.0, None);
        let (run, h, rows) = match factor {
            None => probe(&stations, name),
            Some(f) => better_probe(&stations, name, f),
        };
        assert!(
            run.stdout.contains("azimuth undetermined"),
            "{}",
            run.stdout
        );
        assert!(!run.stdout.contains("first-order model not valid"));
        assert!(run.stdout.contains("outside the model's validity"));
        assert!(run.stdout.contains("(station 0)"), "{}", run.stdout);
        let (valid, sn) = (col(&h, "error_model_valid"), col(&h, "sigma_north_m"));
        assert!(rows.iter().all(|r| r[valid] == "false" && r[sn].is_empty()));
    }
}

/// A lateral turning from north to east, gyro 1000 times better than the
/// SCC1300 (single-station sigma 0.03 deg at north): covariances up to the
/// first station within 5.7 deg of east, none from there on. With a gyro
/// only 100 times better the first-order rule stops it earlier, near the
/// fold (at 78 deg azimuth, 810 m, sigma 1.5 deg is beyond the limit of
/// 0.98 deg there).
#[test]
fn lateral_turning_east_is_flagged_from_the_first_undetermined_station() {
    // azimuth 0 at 0 and 30 m, then 3 deg per 30 m: 84 deg at 870 m
    // (S = 0.105, still determined), 87 deg at 900 m (S = 0.052)
    let azi = |md: f64| ((md - 30.0).max(0.0) / 10.0).min(90.0);
    let stations = lateral("turn", azi, None);
    let (run, h, rows) = better_probe(&stations, "turn", 1000.0);
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
    assert!(run.stdout.contains("azimuth undetermined"));
    let (run, h, rows) = better_probe(&stations, "turn-100", 100.0);
    let first_bad = rows
        .iter()
        .position(|r| r[col(&h, "error_model_valid")] == "false")
        .unwrap();
    let at: f64 = rows[first_bad][col(&h, "md_m")].parse().unwrap();
    assert_eq!(at, 810.0, "first flagged at MD {at}");
    assert!(
        run.stdout.contains("first-order model not valid"),
        "{}",
        run.stdout
    );
}

/// With the toolface column the bias terms are projected per gyro; without
/// it they take a bound valid for any toolface, so the sigmas are no
/// smaller (gyro 100 times better than the SCC1300, so that the model
/// holds).
#[test]
fn toolface_column_is_used_and_the_bound_covers_it() {
    let tf = |k: usize| (k * 47 % 360) as f64;
    let (_, h, with) = better_probe(&lateral("tf", |_| 30.0, Some(&tf)), "tf", 100.0);
    let (_, _, without) = better_probe(&lateral("no-tf", |_| 30.0, None), "no-tf", 100.0);
    let major = col(&h, "ellipse_semi_major_m");
    let (a, b): (f64, f64) = (
        with.last().unwrap()[major].parse().unwrap(),
        without.last().unwrap()[major].parse().unwrap(),
    );
    assert!(a.is_finite() && a > 0.0);
    assert!(a <= b, "with toolface {a} m, bound {b} m");
    assert!(a < 0.99 * b, "the toolface changed nothing: {a} vs {b}");
}

/// `--error-model-file`: a missing file, a file that is not a term table,
/// a term with an unknown weighting function, a non-numeric magnitude:
/// each a clear error and exit 1, no panic; with --error-model: refused.
#[test]
fn error_model_file_bad_inputs() {
    let stations = lateral("bad-file", |_| 0.0, None);
    let dir = common::scratch("survey-probe-cli", "bad-file");
    let good = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("data/probe_scc1300_terms.csv"),
    )
    .unwrap();
    let unknown = good.replacen(",PRB-GN,derived", ",PRB-NOSUCH,derived", 1);
    assert_ne!(unknown, good);
    let magnitude = good.replacen(",5.038459728906355,", ",lots,", 1);
    assert_ne!(magnitude, good);
    let header = good.lines().next().unwrap().to_string() + "\n";
    let cases: [(&str, Option<String>, &str); 5] = [
        ("missing.csv", None, "No such file"),
        (
            "not-a-table.csv",
            Some("md_m,inc_deg,azi_deg\n0,0,0\n".into()),
            "no column",
        ),
        ("unknown.csv", Some(unknown), "not implemented: PRB-NOSUCH"),
        ("magnitude.csv", Some(magnitude), "Magnitude"),
        ("empty.csv", Some(header), "no terms"),
    ];
    for (name, text, expect) in cases {
        let path = dir.join(name);
        if let Some(t) = &text {
            std::fs::write(&path, t).unwrap();
        }
        let run = host_sim(&[s(&stations), "--lat", "45", "--error-model-file", s(&path)]);
        assert_eq!(run.code, Some(1), "{name}: {}", run.stderr);
        assert!(!run.stderr.contains("panicked"), "{name}: {}", run.stderr);
        assert!(run.stderr.contains(expect), "{name}: {}", run.stderr);
        assert!(run.stderr.contains(name), "{name}: {}", run.stderr);
    }
    let table = better_gyro_table("bad-file-both", 100.0);
    let both = host_sim(&[
        s(&stations),
        "--lat",
        "45",
        "--error-model",
        "PROBE-SCC1300",
        "--error-model-file",
        s(&table),
    ]);
    assert_eq!(both.code, Some(1), "{}", both.stderr);
    assert!(
        both.stderr.contains("cannot be used with"),
        "{}",
        both.stderr
    );
}

/// The model is among the names `--error-model` lists (the message of an
/// unknown name), and its name is matched ignoring case.
#[test]
fn model_listing_includes_the_probe_model() {
    let stations = lateral("names", |_| 0.0, None);
    let run = host_sim(&[s(&stations), "--error-model", "NO SUCH MODEL"]);
    assert!(matches!(run.code, Some(1)), "{:?}", run.code);
    assert!(run.stderr.contains("unknown error model"), "{}", run.stderr);
    assert!(run.stderr.contains("PROBE-SCC1300"), "{}", run.stderr);
    let lower = host_sim(&[s(&stations), "--error-model", "probe-scc1300"]);
    assert_eq!(lower.code, Some(0), "{}", lower.stderr);
    assert!(lower.stdout.contains("error model PROBE-SCC1300"));
}
