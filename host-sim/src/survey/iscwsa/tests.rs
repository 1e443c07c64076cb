use super::term_table::to_model_units;
use super::*;
use std::path::Path;

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

/// The straightforward propagation the optimised [`run_with`] is checked
/// against ("fast code checked against the slow one"): every source's
/// error vector built on its own, each station's trigonometry and the site
/// constants recomputed wherever they are used, the vectors stored, then
/// summed. This is the engine's propagation as it was before the
/// optimisation (SPE 67616 eqs. for the balanced-tangential derivatives,
/// as described in the module documentation), kept only as a test oracle;
/// it shares the engine's weighting table.
mod slow {
    use super::super::propagation::outer;
    use super::super::stations::{SiteTerms, StationTrig};
    use super::super::weighting::Weight;
    use super::super::{
        Cov6, ErrorTerm, ModelResult, Options, Propagation, Site, Station, TieOn, XclAzimuth,
        XCL_TORTUOSITY,
    };
    use std::collections::BTreeMap;

    /// The engine's own weighting table: the formulas are checked against
    /// the published ISCWSA covariances (`tests/iscwsa_error_model.rs`);
    /// what this oracle checks is the propagation around them, so it only
    /// recomputes the station's trigonometry and the site terms per call.
    fn weighting(name: &str, s: &Station, course: f64, site: &Site) -> Option<Weight> {
        super::super::weighting::weighting(
            name,
            s,
            &StationTrig::of(s, site),
            course,
            &SiteTerms::of(site),
        )
    }

    fn xcl_vector(
        name: &str,
        s: &Station,
        prev: &Station,
        sig: f64,
        site: &Site,
        xcl: XclAzimuth,
    ) -> Option<[f64; 3]> {
        let len = s.md - prev.md;
        let (si, ci) = s.inc.sin_cos();
        let (sa, ca) = s.azi.sin_cos();
        match name {
            "XCLH" => {
                let w = (s.inc - prev.inc).abs().max(XCL_TORTUOSITY * len);
                Some([
                    sig * len * w * ci * ca,
                    sig * len * w * ci * sa,
                    -sig * len * w * si,
                ])
            }
            "XCLA" => {
                let mut da = (s.azi - prev.azi).rem_euclid(std::f64::consts::TAU);
                if da > std::f64::consts::PI {
                    da = std::f64::consts::TAU - da;
                }
                if prev.inc < site.vertical_limit {
                    da = 0.0;
                }
                let change = match xcl {
                    XclAzimuth::Angle => da,
                    XclAzimuth::Sine => da.sin(),
                };
                let ws = (si * change).max(XCL_TORTUOSITY * len);
                Some([-sig * len * ws * sa, sig * len * ws * ca, 0.0])
            }
            _ => None,
        }
    }

    fn tangent(s: &Station) -> [f64; 3] {
        let (si, ci) = s.inc.sin_cos();
        let (sa, ca) = s.azi.sin_cos();
        [si * ca, si * sa, ci]
    }

    fn d_inc_azi(s: &Station, len: f64) -> ([f64; 3], [f64; 3]) {
        let (si, ci) = s.inc.sin_cos();
        let (sa, ca) = s.azi.sin_cos();
        let h = len / 2.0;
        (
            [h * ci * ca, h * ci * sa, -h * si],
            [-h * si * sa, h * si * ca, 0.0],
        )
    }

    #[allow(clippy::type_complexity)]
    fn error_vectors(
        term: &ErrorTerm,
        stations: &[Station],
        site: &Site,
        opts: Options,
    ) -> Option<Vec<([f64; 3], [f64; 3])>> {
        let n = stations.len();
        let mut out = vec![([0.0; 3], [0.0; 3]); n];
        let sig = term.magnitude_si;
        if term.weighting.starts_with("XCL") {
            for k in 1..n {
                let v = xcl_vector(
                    &term.weighting,
                    &stations[k],
                    &stations[k - 1],
                    sig,
                    site,
                    opts.xcl_azimuth,
                )?;
                out[k] = (v, v);
            }
            return Some(out);
        }
        for k in 1..n {
            let s = &stations[k];
            let wt = weighting(&term.weighting, s, s.md - stations[k - 1].md, site)?;
            let len_b = if k == 1 && opts.tie_on == TieOn::CarriedByFirstStation {
                2.0 * (s.md - stations[0].md)
            } else {
                s.md - stations[k - 1].md
            };
            let len_a = if k + 1 < n {
                stations[k + 1].md - s.md
            } else {
                0.0
            };
            let t = tangent(s);
            let tp = tangent(&stations[k - 1]);
            let tn = if k + 1 < n {
                tangent(&stations[k + 1])
            } else {
                t
            };
            let dd_b: [f64; 3] = std::array::from_fn(|j| 0.5 * (tp[j] + t[j]));
            let dd_a: [f64; 3] = std::array::from_fn(|j| -0.5 * (t[j] + tn[j]));
            let vec_for = |len_after: f64, dd_after: [f64; 3]| -> [f64; 3] {
                if let (Some(sv), true) = (wt.singular, s.inc < site.vertical_limit) {
                    let h = (len_b + len_after) / 2.0;
                    let dd: [f64; 3] = std::array::from_fn(|j| dd_b[j] + dd_after[j]);
                    return std::array::from_fn(|j| sig * (dd[j] * wt.w[0] + h * sv[j]));
                }
                let (di_b, da_b) = d_inc_azi(s, len_b);
                let (di_a, da_a) = d_inc_azi(s, len_after);
                std::array::from_fn(|j| {
                    sig * ((dd_b[j] + dd_after[j]) * wt.w[0]
                        + (di_b[j] + di_a[j]) * wt.w[1]
                        + (da_b[j] + da_a[j]) * wt.w[2])
                })
            };
            out[k] = (vec_for(len_a, dd_a), vec_for(0.0, [0.0; 3]));
        }
        Some(out)
    }

    pub fn run_with(
        terms: &[ErrorTerm],
        stations: &[Station],
        site: &Site,
        opts: Options,
    ) -> ModelResult {
        let n = stations.len();
        let mut per_source = BTreeMap::new();
        let mut missing = Vec::new();
        let mut total: Vec<Cov6> = vec![[0.0; 6]; n];
        for term in terms {
            let Some(ev) = error_vectors(term, stations, site, opts) else {
                missing.push(term.code.clone());
                continue;
            };
            let mut covs: Vec<Cov6> = vec![[0.0; 6]; n];
            for k in 1..n {
                covs[k] = match term.propagation {
                    // random: independent at every station, variances add
                    Propagation::Random => {
                        let mut c = outer(ev[k].1);
                        for e in &ev[1..k] {
                            let ci = outer(e.0);
                            for j in 0..6 {
                                c[j] += ci[j];
                            }
                        }
                        c
                    }
                    // systematic, per-well, global: the vectors add
                    _ => {
                        let mut v = ev[k].1;
                        for e in &ev[1..k] {
                            for (a, x) in v.iter_mut().zip(e.0) {
                                *a += x;
                            }
                        }
                        outer(v)
                    }
                };
            }
            for k in 0..n {
                for j in 0..6 {
                    total[k][j] += covs[k][j];
                }
            }
            per_source.insert(term.code.clone(), covs);
        }
        ModelResult {
            per_source,
            total,
            missing,
        }
    }
}

/// Worst difference between two results, normwise: at each station and
/// source, the largest element difference over the largest variance of
/// that covariance (its max norm). Element by element would not do: where
/// a systematic source's summed vector nearly cancels in one axis (e.g.
/// NN 7e-6 m^2 beside VV 40 m^2 on the random well), the summation order
/// alone moves that element by more than 1e-12 of itself.
fn worst_relative(fast: &ModelResult, slow: &ModelResult) -> f64 {
    assert_eq!(fast.missing, slow.missing);
    assert_eq!(
        fast.per_source.keys().collect::<Vec<_>>(),
        slow.per_source.keys().collect::<Vec<_>>()
    );
    let pairs = fast
        .per_source
        .values()
        .zip(slow.per_source.values())
        .chain(std::iter::once((&fast.total, &slow.total)));
    let mut worst: f64 = 0.0;
    for (a, b) in pairs {
        assert_eq!(a.len(), b.len());
        for (ca, cb) in a.iter().zip(b) {
            assert!(ca.iter().chain(cb).all(|x| x.is_finite()));
            let scale = cb[0].abs().max(cb[1].abs()).max(cb[2].abs());
            for (x, y) in ca.iter().zip(cb) {
                let d = (x - y).abs();
                if d > 0.0 {
                    worst = worst.max(d / scale);
                }
            }
        }
    }
    worst
}

fn data_dir() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("data")
}

/// The three ISCWSA test wells (`tests/data/iscwsa/`: survey files and the
/// sites of wells.json, typed here as the integration test reads them).
fn iscwsa_wells() -> Vec<(Vec<Station>, Site)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/data/iscwsa");
    // (file, feet, latitude, B nT, dip, declination): wells.json
    let wells = [
        ("well1_survey.csv", false, 60.0, 50_000.0, 72.0, -4.0),
        ("well2_survey.csv", true, 28.0, 48_000.0, 58.0, 2.0),
        ("well3_survey.csv", false, -40.0, 61_000.0, -70.0, 13.0),
    ];
    wells
        .iter()
        .map(|&(file, feet, lat, b, dip, dec)| {
            let unit = if feet { 0.3048 } else { 1.0 };
            let text = std::fs::read_to_string(dir.join(file)).expect("survey file");
            let stations: Vec<Station> = text
                .lines()
                .skip(1)
                .map(|l| {
                    let v: Vec<f64> = l
                        .split(',')
                        .map(|f| f.trim().parse().expect("number"))
                        .collect();
                    Station {
                        md: v[0] * unit,
                        inc: v[1].to_radians(),
                        azi: v[2].to_radians(),
                        tvd: v[3] * unit,
                        toolface: None,
                    }
                })
                .collect();
            check_stations(&stations).expect("valid survey");
            let site = Site {
                gravity: 9.80665,
                b_total: b,
                dip: f64::to_radians(dip),
                declination: f64::to_radians(dec),
                vertical_limit: 1e-4_f64.to_radians(),
                latitude: f64::to_radians(lat),
                gyro_noise_reduction: 1.0,
            };
            (stations, site)
        })
        .collect()
}

/// A random well (fixed seed, reproducible): vertical stretches (exactly
/// 0 deg, the singular branch), a vertical-but-not-zero station below the
/// limit, steps of 0.5-100 m, inclinations over 0..180 deg, azimuths
/// wrapping through 0/360, a random site.
fn random_well(seed: u64) -> (Vec<Station>, Site) {
    let mut x = seed;
    let mut rnd = move || {
        // SplitMix64
        x = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = x;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut st = Vec::new();
    let (mut md, mut tvd, mut inc, mut azi) = (100.0 * rnd(), 0.0, 0.0_f64, 0.0_f64);
    for k in 0..400 {
        st.push(Station {
            md,
            inc,
            azi,
            tvd,
            toolface: None,
        });
        let step = 0.5 + 99.5 * rnd();
        md += step;
        tvd += step * inc.cos();
        inc = match k {
            0..=9 | 150..=154 => 0.0,
            10 => 1e-7,
            _ => (inc + (rnd() - 0.45) * 0.2).clamp(0.0, std::f64::consts::PI),
        };
        azi = (azi + (rnd() - 0.5) * 0.6).rem_euclid(std::f64::consts::TAU);
    }
    let site = Site {
        gravity: 9.8 + 0.02 * rnd(),
        b_total: 30_000.0 + 30_000.0 * rnd(),
        dip: (rnd() - 0.5) * 160_f64.to_radians(),
        declination: (rnd() - 0.5) * 40_f64.to_radians(),
        vertical_limit: 1e-4_f64.to_radians(),
        latitude: (rnd() - 0.5) * 120_f64.to_radians(),
        gyro_noise_reduction: 1.0,
    };
    check_stations(&st).expect("valid random survey");
    (st, site)
}

/// The optimised propagation equals the straightforward one (`slow`) to
/// 1e-12 relative: every source and the total, at every station, on the
/// three ISCWSA wells and a random well, for every term table the tool
/// carries (MWD Rev 5, Rev 4, OWSG gyro; the gyro tables only where their
/// weightings are finite, below 89 deg) and every convention.
#[test]
fn fast_propagation_equals_the_straightforward_one() {
    let load = |f: &str| load_term_table(&data_dir().join(f)).expect("term table");
    let rev4 = load_term_table(
        &Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../tests/data/iscwsa/mwd_rev4_model_terms.csv"),
    )
    .expect("rev4 table");
    let mut mwd = load("mwd_rev5_model_terms.csv");
    // an unknown weighting must be reported the same way by both
    mwd.push(term("XCLL", "XCL", 0.167, Propagation::Random));
    mwd.push(term("NOPE", "NO-SUCH-FN", 1.0, Propagation::Systematic));
    let gyro = [
        load("owsg_gyro_mwd_terms.csv"),
        load("owsg_gyro_ns_terms.csv"),
    ];
    let mut wells = iscwsa_wells();
    wells.push(random_well(12));
    let mut worst: f64 = 0.0;
    let mut compared = 0;
    for (w, (stations, site)) in wells.iter().enumerate() {
        for opts in [Options::REV5_10, Options::REV5_DIAGNOSTIC, Options::REV4] {
            for terms in [&mwd, &rev4] {
                let fast = run_with(terms, stations, site, opts);
                let slow = slow::run_with(terms, stations, site, opts);
                let r = worst_relative(&fast, &slow);
                assert!(r <= 1e-12, "well {w} {opts:?}: {r:e}");
                worst = worst.max(r);
                compared += 1;
            }
        }
        let below_89 = stations
            .iter()
            .position(|s| s.inc > 89_f64.to_radians())
            .unwrap_or(stations.len());
        for terms in &gyro {
            let st = &stations[..below_89];
            let r = worst_relative(
                &run(terms, st, site),
                &slow::run_with(terms, st, site, Options::REV5_10),
            );
            assert!(r <= 1e-12, "well {w} gyro: {r:e}");
            worst = worst.max(r);
            compared += 1;
        }
    }
    assert_eq!(compared, 4 * 8);
    println!("fast vs straightforward propagation: worst relative difference {worst:e}");
}

/// The check above can fail: a changed magnitude in one source shows.
#[test]
fn fast_slow_comparison_detects_a_difference() {
    let (stations, site) = random_well(3);
    let terms = load_term_table(&data_dir().join("mwd_rev5_model_terms.csv")).expect("table");
    let mut other = terms.clone();
    other[5].magnitude_si *= 1.0 + 1e-9;
    let r = worst_relative(
        &run(&terms, &stations, &site),
        &slow::run_with(&other, &stations, &site, Options::REV5_10),
    );
    assert!(r > 1e-12, "{r:e}");
}
