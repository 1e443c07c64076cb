use super::*;

fn site() -> Site {
    Site {
        gravity: 9.80665,
        b_total: 50_000.0,
        dip: 72_f64.to_radians(),
        declination: -4_f64.to_radians(),
        vertical_limit: 1e-4_f64.to_radians(),
        latitude: 60_f64.to_radians(),
        gyro_noise_reduction: 1.0,
    }
}

fn vertical(n: usize, step: f64) -> Vec<Station> {
    (0..n)
        .map(|i| Station {
            md: i as f64 * step,
            inc: 0.0,
            azi: 0.0,
            tvd: i as f64 * step,
            toolface: None,
        })
        .collect()
}

fn term(code: &str, wt: &str, sigma: f64, p: Propagation) -> ErrorTerm {
    ErrorTerm {
        code: code.into(),
        weighting: wt.into(),
        magnitude: sigma,
        unit: "-".into(),
        magnitude_si: sigma,
        propagation: p,
    }
}

/// On a vertical well the depth terms have closed forms: a random depth
/// reference error does not accumulate (sigma^2 at every station), a
/// systematic scale factor gives (sigma MD)^2, the stretch (sigma MD TVD)^2.
#[test]
fn depth_terms_on_a_vertical_well_have_closed_forms() {
    let st = vertical(41, 30.0);
    let terms = [
        term("DRFR", "DREF", 0.35, Propagation::Random),
        term("DSFS", "DSF", 5.6e-4, Propagation::Systematic),
        term("DSTG", "DST", 2.5e-7, Propagation::Global),
    ];
    let r = run(&terms, &st, &site());
    assert!(r.missing.is_empty());
    for (k, s) in st.iter().enumerate().skip(1) {
        let vv = |c: &str| r.per_source[c][k][2];
        assert!((vv("DRFR") - 0.35_f64.powi(2)).abs() < 1e-12, "k {k}");
        assert!((vv("DSFS") - (5.6e-4 * s.md).powi(2)).abs() < 1e-12);
        assert!((vv("DSTG") - (2.5e-7 * s.md * s.tvd).powi(2)).abs() < 1e-9);
        for c in ["DRFR", "DSFS", "DSTG"] {
            let cov = r.per_source[c][k];
            assert_eq!([cov[0], cov[1], cov[3], cov[4], cov[5]], [0.0; 5]);
        }
    }
    // the tie-on carries no error
    assert_eq!(r.total[0], [0.0; 6]);
}

/// A random inclination-type error grows as sqrt(stations), a systematic
/// one linearly: same source, same well, both modes.
#[test]
fn random_and_systematic_propagation_differ_as_expected() {
    let st: Vec<Station> = (0..101)
        .map(|i| Station {
            md: i as f64 * 30.0,
            inc: 60_f64.to_radians(),
            azi: 0.0,
            tvd: i as f64 * 15.0,
            toolface: None,
        })
        .collect();
    let sig = 1e-3;
    let r = run(
        &[
            term("R", "XYM1", sig, Propagation::Random),
            term("S", "XYM1", sig, Propagation::Systematic),
        ],
        &st,
        &site(),
    );
    let k = 100;
    // straight hold: every station's vector is the same, length 30 m (15 m
    // at the last, 45 m at station 1 which carries the tie-on), along
    // d t/dI = (cos I, 0, -sin I), scaled by |sin I|
    let w = 60_f64.to_radians().sin() * sig;
    let len_s = 3000.0; // 45 + 98 * 30 + 15
    let len_r2 = 45.0_f64.powi(2) + 98.0 * 900.0 + 225.0;
    let ci2 = 60_f64.to_radians().cos().powi(2);
    assert!((r.per_source["S"][k][0] - (w * len_s).powi(2) * ci2).abs() < 1e-9);
    assert!((r.per_source["R"][k][0] - w * w * len_r2 * ci2).abs() < 1e-9);
}

#[test]
fn unknown_weighting_is_reported_missing_not_zero() {
    let st = vertical(5, 30.0);
    let r = run(
        &[
            term("XCLL", "XCL", 0.167, Propagation::Random),
            term("DRFR", "DREF", 0.35, Propagation::Random),
        ],
        &st,
        &site(),
    );
    assert_eq!(r.missing, vec!["XCLL".to_string()]);
    assert!(!r.per_source.contains_key("XCLL"));
    // the total holds only what was computed
    assert!((r.total[4][2] - 0.1225).abs() < 1e-12);
}

fn write_tmp(name: &str, text: &str) -> std::path::PathBuf {
    let p = std::env::temp_dir().join(format!("iscwsa-{}-{name}", std::process::id()));
    std::fs::write(&p, text).expect("temp file");
    p
}

const HEADER: &str = "No,Code,Wt.Fn.,Magnitude,Units,Prop.,Convert Magnitudes Degrees to Radians\n";

#[test]
fn term_table_errors_are_clear() {
    let missing = load_term_table(Path::new("/nonexistent/terms.csv"));
    assert!(matches!(missing, Err(DataError(m)) if m.contains("/nonexistent/terms.csv")));

    let p = write_tmp(
        "bad-num.csv",
        &format!("{HEADER}1,DRFR,DREF,abc,m,R,0.35\n"),
    );
    let e = load_term_table(&p).expect_err("bad magnitude");
    assert!(e.0.contains("Magnitude") && e.0.contains("abc"), "{e}");

    let p = write_tmp(
        "bad-prop.csv",
        &format!("{HEADER}1,DRFR,DREF,0.35,m,X,0.35\n"),
    );
    let e = load_term_table(&p).expect_err("bad propagation");
    assert!(e.0.contains("propagation"), "{e}");

    let p = write_tmp("no-col.csv", "No,Code,Magnitude\n1,DRFR,0.35\n");
    let e = load_term_table(&p).expect_err("no Wt.Fn. column");
    assert!(e.0.contains("Wt.Fn."), "{e}");

    let p = write_tmp("empty.csv", HEADER);
    assert!(load_term_table(&p).is_err());

    let p = write_tmp(
        "ok.csv",
        &format!("{HEADER}1,DEC-U,AZ,0.16,deg,G,0.0027925268031909274\n"),
    );
    let t = load_term_table(&p).expect("valid table");
    assert_eq!(t[0].propagation, Propagation::Global);
    assert_eq!(t[0].unit, "deg");
    for n in ["bad-num", "bad-prop", "no-col", "empty", "ok"] {
        let _ = std::fs::remove_file(
            std::env::temp_dir().join(format!("iscwsa-{}-{n}.csv", std::process::id())),
        );
    }
}

/// A systematic gyro bias on the east axis (GXY-B2, azimuth error
/// b cos A / (Omega cos lat)) on a straight hold due north: the whole hold
/// is swung sideways, EE = (dA sin I L)^2 with L the hold's length.
#[test]
fn gyro_bias_swings_a_straight_hold() {
    let inc = 60_f64.to_radians();
    let st: Vec<Station> = (0..101)
        .map(|i| Station {
            md: i as f64 * 30.0,
            inc,
            azi: 0.0,
            tvd: i as f64 * 15.0,
            toolface: None,
        })
        .collect();
    let b = 0.15 * std::f64::consts::PI / 180.0 / 3600.0; // 0.15 deg/h
    let r = run(
        &[term("GXY-B2S", "GXY-B2", b, Propagation::Systematic)],
        &st,
        &site(),
    );
    let da = b / (EARTH_RATE * 60_f64.to_radians().cos());
    let expect = (da * inc.sin() * 3000.0).powi(2);
    let got = r.per_source["GXY-B2S"][100];
    assert!(
        (got[1] - expect).abs() < 1e-9 * expect,
        "{} vs {expect}",
        got[1]
    );
    assert!(got[0].abs() < 1e-12 && got[2].abs() < 1e-12);
}

#[test]
fn magnitudes_without_a_converted_column_follow_their_unit() {
    assert_eq!(to_model_units(0.35, "m"), Some(0.35));
    let dph = to_model_units(15.0, "deg/hr").expect("deg/hr");
    assert!((dph - 15_f64.to_radians() / 3600.0).abs() < 1e-18);
    assert!((to_model_units(0.2, "deg").expect("deg") - 0.2_f64.to_radians()).abs() < 1e-18);
    assert_eq!(to_model_units(1.0, "furlong"), None);
}

#[test]
fn bad_surveys_are_rejected_with_the_station_named() {
    assert!(check_stations(&[]).is_err());
    let mut st = vertical(5, 30.0);
    assert!(check_stations(&st).is_ok());
    st[3].md = st[2].md;
    let e = check_stations(&st).expect_err("repeated MD");
    assert!(e.0.contains("station 3"), "{e}");
    let mut st = vertical(5, 30.0);
    st[2].azi = f64::NAN;
    assert!(check_stations(&st)
        .expect_err("NaN")
        .0
        .contains("station 2"));
    let mut st = vertical(5, 30.0);
    st[4].inc = -0.1;
    assert!(check_stations(&st)
        .expect_err("negative inc")
        .0
        .contains("inclination"));
}
