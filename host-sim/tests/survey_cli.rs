//! `host-sim survey` through the binary: bad input refused with a sentence
//! and a non-zero exit (never a panic), and ISCWSA test well #1 against
//! the published numbers.

mod common;

use common::{refused, s, well1, Run, WELL1_SITE};
use std::path::{Path, PathBuf};

fn host_sim(args: &[&str]) -> Run {
    common::run(&[&["survey"], args].concat())
}

fn scratch(name: &str) -> PathBuf {
    common::scratch("survey-cli", name)
}

fn refused_file(name: &str, text: &str, extra: &[&str], needle: &str) {
    let path = scratch(name).join("stations.csv");
    std::fs::write(&path, text).unwrap();
    let mut args = vec![s(&path)];
    args.extend_from_slice(extra);
    refused(&host_sim(&args), needle);
}

#[test]
fn md_not_increasing() {
    refused_file(
        "md",
        "md_m,inc_deg,azi_deg\n0,0,0\n30,1,10\n30,2,10\n",
        &[],
        "MD must increase",
    );
}

#[test]
fn inclination_out_of_range() {
    refused_file(
        "inc",
        "md_m,inc_deg,azi_deg\n0,0,0\n30,181,10\n",
        &[],
        "outside 0..180",
    );
    refused_file(
        "inc-neg",
        "md_m,inc_deg,azi_deg\n0,0,0\n30,-1,10\n",
        &[],
        "outside 0..180",
    );
}

#[test]
fn nan_value() {
    refused_file(
        "nan",
        "md_m,inc_deg,azi_deg\n0,0,0\n30,NaN,10\n",
        &[],
        "not a finite number",
    );
}

#[test]
fn empty_file_and_header_only() {
    refused_file("empty", "", &[], "empty");
    refused_file("header", "md_m,inc_deg,azi_deg\n", &[], "no stations");
}

#[test]
fn missing_column() {
    refused_file("col", "md_m,inc_deg\n0,0\n30,1\n", &[], "no column azi_deg");
    refused_file(
        "no-md",
        "inc_deg,azi_deg\n0,0\n",
        &[],
        "no column md_m or md_ft",
    );
}

#[test]
fn feet_and_metres_mixed() {
    refused_file(
        "mixed",
        "md_ft,inc_deg,azi_deg,tvd_m\n0,0,0,0\n100,1,10,30\n",
        &[],
        "mixes feet and metres",
    );
    refused_file(
        "both-md",
        "md_m,md_ft,inc_deg,azi_deg\n0,0,0,0\n",
        &[],
        "mixes feet and metres",
    );
}

#[test]
fn unknown_model() {
    refused(
        &host_sim(&[s(&well1()), "--error-model", "NO SUCH MODEL"]),
        "unknown error model",
    );
}

#[test]
fn magnetic_model_needs_the_field() {
    refused(
        &host_sim(&[s(&well1()), "--error-model", "ISCWSA MWD Rev5"]),
        "--b-total-nt",
    );
}

#[test]
fn bad_flags() {
    refused(&host_sim(&[s(&well1()), "--confidence", "1"]), "confidence");
    refused(
        &host_sim(&[s(&well1()), "--azimuth-reference", "grid"]),
        "--convergence-deg",
    );
    refused(&host_sim(&[s(&well1()), "--tie-on-md", "5"]), "tie-on MD");
}

/// OWSG gyro models are stated up to 89 deg: well #1 reaches 90 deg, so
/// the stations beyond get no uncertainty, flagged in every output.
#[test]
fn gyro_model_outside_its_inclination_range_is_flagged() {
    let dir = scratch("gyro");
    let csv = dir.join("out.csv");
    let run = host_sim(&[
        s(&well1()),
        "--lat",
        "60",
        "--error-model",
        "GYRO-MWD",
        "--csv",
        s(&csv),
    ]);
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    assert!(run.stdout.contains("stated for inclinations up to 89 deg"));
    assert!(run.stdout.contains("outside the model's validity"));
    let text = std::fs::read_to_string(&csv).unwrap();
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let valid = header
        .iter()
        .position(|h| *h == "error_model_valid")
        .unwrap();
    let sigma = header.iter().position(|h| *h == "sigma_north_m").unwrap();
    let rows: Vec<Vec<&str>> = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    let flagged: Vec<&Vec<&str>> = rows.iter().filter(|r| r[valid] == "false").collect();
    assert!(!flagged.is_empty());
    assert!(flagged.iter().all(|r| r[sigma].is_empty()));
    let first_bad = rows.iter().position(|r| r[valid] == "false").unwrap();
    let inc: f64 = rows[first_bad][1].parse().unwrap();
    assert!(inc > 89.0);
    assert!(rows[..first_bad]
        .iter()
        .all(|r| r[1].parse::<f64>().unwrap() <= 89.0));
}

fn column(header: &[&str], row: &[&str], name: &str) -> f64 {
    let c = header
        .iter()
        .position(|h| *h == name)
        .unwrap_or_else(|| panic!("no column {name}"));
    row[c].parse().unwrap()
}

/// Well #1 with the Rev 5.10 table: positions against the workbook's
/// typed-in TVD (`well1_survey.csv`) and sigmas against the published
/// ISCWSA Rev 5.1 diagnostic TOTALs at the four tabulated depths (equal to
/// the WB5.10-#1 TOTALS sheet).
#[test]
fn iscwsa_well_1() {
    let dir = scratch("well1");
    let (csv, json, xml) = (dir.join("o.csv"), dir.join("o.json"), dir.join("o.xml"));
    let well = well1();
    let mut args = vec![s(&well), "--error-model", "ISCWSA MWD Rev5"];
    args.extend_from_slice(&WELL1_SITE);
    args.extend_from_slice(&["--csv", s(&csv), "--json", s(&json), "--witsml", s(&xml)]);
    let run = host_sim(&args);
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    for name in [
        "md_m",
        "inc_deg",
        "azi_deg",
        "tvd_m",
        "north_m",
        "east_m",
        "dls_deg_per_30m",
        "vsec_m",
        "sigma_north_m",
        "sigma_east_m",
        "sigma_vert_m",
        "ellipse_semi_major_m",
        "ellipse_semi_minor_m",
        "ellipse_azimuth_deg",
        "confidence",
    ] {
        assert!(header.contains(&name), "no {name}");
    }
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 268);
    let at = |md: f64| {
        rows.iter()
            .find(|r| r[0].parse::<f64>().unwrap() == md)
            .unwrap()
    };
    // (md, published TVD (2 decimals), NN, EE, VV of the WB5.10-#1 TOTALS)
    // ISCWSA Rev 5.1 diagnostics (HPT .dat), TOTAL rows of well #1
    // (tests/data/iscwsa/mwd_rev5_1_hpt_diagnostics_selected_rows.csv), m^2
    let published: [(f64, f64, f64, f64, f64); 4] = [
        (1200.0, 1200.0, 1.5352, 1.5352, 0.7037),
        (2100.0, 1944.29, 34.0575, 9.0728, 4.3935),
        (5100.0, 3444.29, 2073.1747, 215.9499, 134.5116),
        (8000.0, 3521.06, 8518.6721, 711.2004, 513.2943),
    ];
    for (md, tvd, nn, ee, vv) in published {
        let r = at(md);
        assert!((column(&header, r, "tvd_m") - tvd).abs() < 0.006);
        let sn = column(&header, r, "sigma_north_m");
        let se = column(&header, r, "sigma_east_m");
        let sv = column(&header, r, "sigma_vert_m");
        for (got, want) in [(sn, nn.sqrt()), (se, ee.sqrt()), (sv, vv.sqrt())] {
            assert!((got - want).abs() < 1e-3 * want, "MD {md}: {got} vs {want}");
        }
        let major = column(&header, r, "ellipse_semi_major_m");
        let minor = column(&header, r, "ellipse_semi_minor_m");
        let k = (-2.0 * (0.05f64).ln()).sqrt();
        // the 1-sigma semi-axes bracket the N and E sigmas
        assert!(major / k >= sn.max(se) - 1e-9 && minor / k <= sn.min(se) + 1e-9);
        let az = column(&header, r, "ellipse_azimuth_deg");
        assert!((0.0..180.0).contains(&az));
    }
    // 8000 m: horizontal at 75 deg azimuth, N/E from the closure
    let r = at(8000.0);
    let (n, e) = (column(&header, r, "north_m"), column(&header, r, "east_m"));
    assert!((e.atan2(n).to_degrees() - 75.0).abs() < 1e-6);
    // JSON and WITSML
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(doc["stations"].as_array().unwrap().len(), 268);
    let xml = std::fs::read_to_string(&xml).unwrap();
    assert!(xml.contains("xmlns=\"http://www.witsml.org/schemas/1series\""));
    assert!(xml.contains("version=\"1.4.1.1\""));
    assert_eq!(xml.matches("<trajectoryStation ").count(), 268);
    assert_eq!(xml.matches("</trajectoryStation>").count(), 268);
    for tag in [
        "md", "tvd", "incl", "azi", "dispNs", "dispEw", "vertSect", "dls",
    ] {
        assert_eq!(xml.matches(&format!("<{tag} uom=")).count(), 268, "{tag}");
    }
    assert!(well_formed(&xml));
}

/// A light well-formedness check: every open tag closed in order.
fn well_formed(xml: &str) -> bool {
    let mut stack: Vec<&str> = Vec::new();
    let mut rest = xml;
    while let Some(start) = rest.find('<') {
        let Some(len) = rest[start..].find('>') else {
            return false;
        };
        let tag = &rest[start + 1..start + len];
        rest = &rest[start + len + 1..];
        if tag.starts_with('?') {
            continue;
        }
        if let Some(name) = tag.strip_prefix('/') {
            if stack.pop() != Some(name.trim()) {
                return false;
            }
        } else if !tag.ends_with('/') {
            stack.push(tag.split_whitespace().next().unwrap_or(""));
        }
    }
    stack.is_empty()
}

#[test]
fn feet_input_is_converted() {
    let path = scratch("feet").join("stations.csv");
    std::fs::write(&path, "md_ft,inc_deg,azi_deg\n0,0,0\n1000,0,0\n").unwrap();
    let csv = path.with_extension("out.csv");
    let run = host_sim(&[s(&path), "--csv", s(&csv)]);
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    let text = std::fs::read_to_string(&csv).unwrap();
    let last: Vec<&str> = text.lines().last().unwrap().split(',').collect();
    assert!((last[0].parse::<f64>().unwrap() - 304.8).abs() < 1e-9);
    assert!((last[3].parse::<f64>().unwrap() - 304.8).abs() < 1e-9);
}

/// Each station's NEV covariance (m^2) from a `--json` output.
fn json_covariances(path: &Path) -> Vec<Vec<f64>> {
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    doc["stations"]
        .as_array()
        .unwrap()
        .iter()
        .map(|st| {
            st["nev_covariance_m2"]
                .as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_f64().unwrap())
                .collect()
        })
        .collect()
}

/// The parent well's uncertainty at the tie-on (`--tie-on-sigma`, or a
/// job's full covariance) adds whole to every station's covariance, and
/// the listing and the JSON say so; without it the listing says the
/// tie-on is taken as exact.
#[test]
fn the_tie_ons_uncertainty_adds_to_every_station() {
    let dir = scratch("tie-on-sigma");
    let well = well1();
    let survey = |name: &str, extra: &[&str]| {
        let json = dir.join(name);
        let mut args = vec![s(&well), "--error-model", "ISCWSA MWD Rev5"];
        args.extend_from_slice(&WELL1_SITE);
        args.extend_from_slice(&["--json", s(&json)]);
        args.extend_from_slice(extra);
        let run = host_sim(&args);
        assert_eq!(run.code, Some(0), "{}", run.stderr);
        (run.stdout, json_covariances(&json))
    };
    let (exact_text, exact) = survey("exact.json", &[]);
    assert!(exact_text.contains("tie-on taken as exact"), "{exact_text}");
    let (text, with) = survey("sigma.json", &["--tie-on-sigma", "3", "4", "2"]);
    assert!(
        text.contains("tie-on position 1-sigma N 3.00 m, E 4.00 m, TVD 2.00 m"),
        "{text}"
    );
    assert_eq!(exact.len(), with.len());
    for (a, b) in exact.iter().zip(&with) {
        let added: Vec<f64> = b.iter().zip(a).map(|(b, a)| b - a).collect();
        for (got, want) in added.iter().zip([9.0, 16.0, 4.0, 0.0, 0.0, 0.0]) {
            assert!((got - want).abs() < 1e-9, "{added:?}");
        }
    }
    // a job's full covariance, in feet: converted to m^2 (well 1 is in m)
    let job = dir.join("job.json");
    std::fs::write(
        &job,
        r#"{"format": "mwd-job", "version": 1,
            "site": {"latitude_deg": 60.0, "longitude_deg": 0.0, "height_m": 0.0},
            "survey": {"length_unit": "ft", "error_model": "ISCWSA MWD Rev5",
                       "tie_on": {"covariance": {"nn": 100.0, "ne": 20.0, "nv": 5.0,
                                                 "ee": 50.0, "ev": -3.0, "vv": 10.0}}}}"#,
    )
    .unwrap();
    let json = dir.join("job-out.json");
    let run = host_sim(&[
        s(&well),
        "--job",
        s(&job),
        "--b-total-nt",
        "50000",
        "--dip-deg",
        "72",
        "--declination-deg",
        "-4",
        "--json",
        s(&json),
    ]);
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    let ft2 = 0.3048f64.powi(2);
    for (a, b) in exact.iter().zip(&json_covariances(&json)) {
        for ((b, a), want) in b.iter().zip(a).zip([100.0, 50.0, 10.0, 20.0, 5.0, -3.0]) {
            assert!(
                (b - a - want * ft2).abs() < 1e-9,
                "{b} - {a} vs {want} ft^2"
            );
        }
    }
}

/// `--units ft`: every output in feet with its unit in the header (DLS
/// per 100 ft), and the feet CSV read back gives the same well; an MD
/// column without a unit takes `--units`, and without it is refused.
#[test]
fn feet_output_reads_back_as_the_same_well() {
    let dir = scratch("units-ft");
    let well = well1();
    let (metres_csv, feet_csv, feet_json, feet_xml) = (
        dir.join("m.csv"),
        dir.join("ft.csv"),
        dir.join("ft.json"),
        dir.join("ft.xml"),
    );
    let survey = |station_file: &Path, extra: &[&str]| {
        let mut args = vec![s(station_file), "--error-model", "ISCWSA MWD Rev5"];
        args.extend_from_slice(&WELL1_SITE);
        args.extend_from_slice(extra);
        host_sim(&args)
    };
    let metres = survey(&well, &["--csv", s(&metres_csv)]);
    assert_eq!(metres.code, Some(0), "{}", metres.stderr);
    let feet = survey(
        &well,
        &[
            "--units",
            "ft",
            "--csv",
            s(&feet_csv),
            "--json",
            s(&feet_json),
            "--witsml",
            s(&feet_xml),
        ],
    );
    assert_eq!(feet.code, Some(0), "{}", feet.stderr);
    assert!(feet.stdout.contains("lengths in ft"), "{}", feet.stdout);
    assert!(feet.stdout.contains("DLS in deg/100ft"), "{}", feet.stdout);
    assert!(feet.stdout.contains("MD ft"), "{}", feet.stdout);
    let table = |path: &Path| -> (Vec<String>, Vec<Vec<f64>>) {
        let text = std::fs::read_to_string(path).unwrap();
        let mut lines = text.lines();
        let header = lines.next().unwrap().split(',').map(String::from).collect();
        let rows = lines
            .map(|l| {
                l.split(',')
                    .map(|f| f.parse().unwrap_or(f64::NAN))
                    .collect()
            })
            .collect();
        (header, rows)
    };
    let (mh, m) = table(&metres_csv);
    let (fh, f) = table(&feet_csv);
    let col = |h: &[String], name: &str| h.iter().position(|c| c == name).unwrap();
    for (metre_name, foot_name, factor) in [
        ("md_m", "md_ft", 1.0 / 0.3048),
        ("tvd_m", "tvd_ft", 1.0 / 0.3048),
        ("north_m", "north_ft", 1.0 / 0.3048),
        ("sigma_east_m", "sigma_east_ft", 1.0 / 0.3048),
        (
            "ellipse_semi_major_m",
            "ellipse_semi_major_ft",
            1.0 / 0.3048,
        ),
        ("dls_deg_per_30m", "dls_deg_per_100ft", 30.48 / 30.0),
        ("inc_deg", "inc_deg", 1.0),
    ] {
        let (a, b) = (col(&mh, metre_name), col(&fh, foot_name));
        for (rm, rf) in m.iter().zip(&f) {
            let want = rm[a] * factor;
            assert!(
                (rf[b] - want).abs() <= 1e-9 * want.abs().max(1.0),
                "{foot_name}: {} vs {want}",
                rf[b]
            );
        }
    }
    let xml = std::fs::read_to_string(&feet_xml).unwrap();
    assert!(xml.contains("<md uom=\"ft\">") && xml.contains("uom=\"dega/100ft\""));
    assert!(xml.contains("<varianceNN uom=\"ft2\">") && !xml.contains("uom=\"m\""));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&feet_json).unwrap()).unwrap();
    assert_eq!(json["length_unit"], "ft");
    assert!(json["stations"][1]["md_ft"].as_f64().is_some());
    // the feet CSV as a station file, listed in metres: the same positions
    let back_csv = dir.join("back.csv");
    let back = survey(&feet_csv, &["--csv", s(&back_csv)]);
    assert_eq!(back.code, Some(0), "{}", back.stderr);
    let (bh, b) = table(&back_csv);
    for name in ["md_m", "tvd_m", "north_m", "east_m", "sigma_north_m"] {
        let (i, j) = (col(&mh, name), col(&bh, name));
        for (rm, rb) in m.iter().zip(&b) {
            assert!(
                (rm[i] - rb[j]).abs() <= 1e-9 * rm[i].abs().max(1.0),
                "{name}: {} vs {}",
                rm[i],
                rb[j]
            );
        }
    }
    // an MD column without a unit: refused, or taken in --units
    let unitless = dir.join("unitless.csv");
    std::fs::write(&unitless, "MD,Inc,Azi\n0,0,0\n1000,10,45\n2000,20,45\n").unwrap();
    refused(&survey(&unitless, &[]), "--units");
    let taken = survey(&unitless, &["--units", "ft"]);
    assert_eq!(taken.code, Some(0), "{}", taken.stderr);
    assert!(taken.stdout.contains("  2000.00"), "{}", taken.stdout);
}
