//! `host-sim survey CAPTURE.bin --depth DEPTH.csv` and `host-sim study
//! drilling-coverage`: station surveys paired with the depth log and
//! positioned (synthetic stations with known answers; a simulated short
//! lateral against its truth file), bad depth logs refused, and the
//! coverage study's harness.
mod common;

use common::{plan, run, s, scratch, simulate_tied_in};
use host_sim::formats::depth_log::DepthLog;
use host_sim::survey::iscwsa::Site;
use host_sim::survey::listing::drilling::{
    survey, survey_terms, SurveySetup, DEPTH_GAP_FLAG, DEPTH_GAP_LIMIT_S,
};
use host_sim::survey::listing::drilling_text::{listing, stations_csv};
use host_sim::survey::listing::TieOnInput;
use mwd_core::protocol::frame::station_flags;
use mwd_core::protocol::StationSurvey;

fn site() -> Site {
    Site {
        gravity: 9.806_65,
        b_total: 0.0,
        dip: 0.0,
        declination: 0.0,
        vertical_limit: 1e-4f64.to_radians(),
        latitude: 45f64.to_radians(),
        gyro_noise_reduction: 1.0,
    }
}

/// A horizontal station heading east at time `t` s with azimuth sigma
/// `s_azi` deg.
fn station(number: u16, t: f64, s_azi: f64) -> StationSurvey {
    StationSurvey {
        time_us: (t * 1e6) as u64,
        station: number,
        flags: station_flags::MAGNETIC_FREE,
        start_sample: 0,
        end_sample: (t * 20.0) as u32,
        angles: [90f32.to_radians(), 90f32.to_radians(), 0.0],
        angles_std: [
            0.05f32.to_radians(),
            (s_azi as f32).to_radians(),
            0.05f32.to_radians(),
        ],
        correlations: [0.0; 3],
        still_quality: 1.0,
    }
}

fn log() -> DepthLog {
    // still at 1000 m to 100 s, then 10 m per stand, still at each
    let points = [
        (0.0, 1000.0),
        (100.0, 1000.0),
        (150.0, 1010.0),
        (200.0, 1010.0),
        (250.0, 1020.0),
        (300.0, 1020.0),
        (350.0, 1030.0),
        (400.0, 1030.0),
    ];
    DepthLog::new(points).unwrap()
}

const TIE: TieOnInput = TieOnInput {
    md: None,
    tvd: 2000.0,
    north: 0.0,
    east: 0.0,
    covariance: None,
};

/// The across-hole variance of an azimuth random walk (each station's
/// error carried on): sum_jk h_j h_k min(s_j^2, s_k^2), `h` the length
/// each station's error acts over, `s2` the azimuth variances.
fn random_walk_variance(h: &[f64], s2: &[f64]) -> f64 {
    let mut v = 0.0;
    for (hj, sj) in h.iter().zip(s2) {
        for (hk, sk) in h.iter().zip(s2) {
            v += hj * hk * sj.min(*sk);
        }
    }
    v
}

/// One 10 m leg's long-course-length term (XCLA or XCLH) at the
/// tortuosity floor: 0.167 L (1 deg / 100 ft) L.
const XCL_10M_LEG: f64 = 0.167 * 10.0 * (1.0f64.to_radians() / 30.48) * 10.0;

/// The probe's survey tied on at `TIE`, the bit `sensor_to_bit` m ahead.
fn setup(sensor_to_bit: Option<f64>) -> SurveySetup {
    SurveySetup {
        tie: TIE,
        terms: survey_terms().unwrap(),
        site: site(),
        sensor_to_bit_m: None,
        first_station: 1,
        uncalibrated: false,
        depth_gap_limit_s: DEPTH_GAP_LIMIT_S,
    }
    .with_sensor_to_bit(sensor_to_bit)
}

/// A station frame received twice is taken once; a lost one is listed as
/// lost where it was, the others keep their MD; a tie-on given with the
/// first station lost is refused, not moved to the next station.
#[test]
fn repeated_and_lost_stations() {
    let stations: Vec<StationSurvey> = (0..4)
        .map(|k| station(k as u16 + 1, 100.0 * (k + 1) as f64, 0.1))
        .collect();
    let whole = survey(&stations, &[], &[], &log(), &setup(None)).unwrap();
    // station 2 received twice, one after the other
    let mut repeated = [stations.clone(), vec![stations[1]]].concat();
    repeated.sort_by_key(|s| s.station);
    let again = survey(&repeated, &[], &[], &log(), &setup(None)).unwrap();
    assert_eq!(again.rows.len(), 4);
    assert!(again.skipped.is_empty() && again.lost.is_empty());
    for (a, b) in again.rows.iter().zip(&whole.rows) {
        assert_eq!(a.row.md_m, b.row.md_m);
        assert_eq!(a.row.cov, b.row.cov);
    }
    let without_2: Vec<_> = stations
        .iter()
        .filter(|s| s.station != 2)
        .copied()
        .collect();
    let gap = survey(&without_2, &[], &[], &log(), &setup(None)).unwrap();
    assert_eq!(gap.lost, vec![(2, 2)]);
    let mds = |s: &host_sim::survey::listing::drilling::DrillingSurvey| -> Vec<f64> {
        s.rows.iter().map(|r| r.row.md_m).collect()
    };
    assert_eq!(mds(&gap), [1000.0, 1020.0, 1030.0]);
    let text = listing(&gap, 0.95);
    let lost_at = text.find("station 2 lost (frame not received)").unwrap();
    let three_at = text.find("\n  3 ").unwrap();
    assert!(lost_at < three_at, "{text}");
    // the first station lost: a tie-on MD cannot be placed
    let tied = SurveySetup {
        tie: TieOnInput {
            md: Some(3000.0),
            ..TIE
        },
        ..setup(None)
    };
    let e = survey(&stations[1..], &[], &[], &log(), &tied).unwrap_err();
    assert!(
        e.to_string()
            .starts_with("station 1 lost (frame not received) before station 2"),
        "{e}"
    );
    assert_eq!(
        mds(&survey(&stations, &[], &[], &log(), &tied).unwrap())[0],
        3000.0
    );
}

#[test]
fn synthetic_stations_are_positioned_with_the_random_walk_depth_and_method_uncertainty() {
    let sig = [0.1, 0.2, 0.3, 0.4];
    let stations: Vec<StationSurvey> = (0..4)
        .map(|k| station(k as u16 + 1, 100.0 * (k + 1) as f64, sig[k]))
        .collect();
    let out = survey(&stations, &[], &[], &log(), &setup(None)).unwrap();
    assert_eq!(out.rows.len(), 4);
    for (k, r) in out.rows.iter().enumerate() {
        assert!((r.row.md_m - (1000.0 + 10.0 * k as f64)).abs() < 1e-9);
        // the frame's angles are f32: 90 deg is pi/2 to 4e-8 rad
        assert!((r.row.east_m - 10.0 * k as f64).abs() < 1e-6);
        assert!(r.row.north_m.abs() < 1e-5 && (r.row.tvd_m - 2000.0).abs() < 1e-5);
        assert!(r.position_determined);
    }
    // north (across the hole): the azimuth random walk, by hand,
    // h = half the legs around each station
    let h = [5.0, 10.0, 10.0, 5.0];
    let s2 = sig.map(|s: f64| s.to_radians().powi(2));
    let mut var_n = random_walk_variance(&h, &s2);
    // the method's long-course-length terms (XCLA across the hole, XCLH
    // vertical, random per leg): the legs do not turn, so each weighs the
    // tortuosity floor, 0.167 L (1 deg / 100 ft) L, on the three 10 m legs
    let var_xcl = 3.0 * XCL_10M_LEG * XCL_10M_LEG;
    var_n += var_xcl;
    let c = out.rows[3].row.cov.unwrap();
    // (the frame's sigmas are f32: 1e-7 relative)
    assert!((c[0] - var_n).abs() < 1e-6 * var_n, "{} vs {var_n}", c[0]);
    // east (along the hole): depth scale and stretch on the 30 m drilled,
    // MD counted from the tie-on (DSFS 560 ppm, DSTG 2.5e-7 /m), and the
    // angles' second order, systematic: each station's half legs shortened
    // by sqrt(3)/2 (s_I^2 + s_A^2)
    let inc2 = 0.05f64.to_radians().powi(2);
    let shortening: f64 = (0..4)
        .map(|k| h[k] * 0.5 * 3f64.sqrt() * (inc2 + s2[k]))
        .sum();
    let var_e =
        (560e-6 * 30.0f64).powi(2) + (2.5e-7 * 30.0 * 2000.0f64).powi(2) + shortening.powi(2);
    assert!((c[1] - var_e).abs() < 1e-6 * var_e, "{} vs {var_e}", c[1]);
    // vertical: the inclination, random per station
    let var_v = 0.05f64.to_radians().powi(2) * h.iter().map(|x| x * x).sum::<f64>() + var_xcl;
    assert!((c[2] - var_v).abs() < 1e-6 * var_v);
}

#[test]
fn the_bit_is_projected_straight_ahead_with_the_last_stations_errors_over_the_lever() {
    let sig = [0.1, 0.2, 0.3, 0.4];
    let stations: Vec<StationSurvey> = (0..4)
        .map(|k| station(k as u16 + 1, 100.0 * (k + 1) as f64, sig[k]))
        .collect();
    let plain = survey(&stations, &[], &[], &log(), &setup(None)).unwrap();
    assert!(plain.bit.is_none());
    let out = survey(&stations, &[], &[], &log(), &setup(Some(10.0))).unwrap();
    let bit = out.bit.expect("a projection with a sensor-to-bit distance");
    // (the log ends at the last station: the projection is the 10 m)
    assert_eq!(bit.sensor_to_bit_m, 10.0);
    assert_eq!(bit.projected_m, 10.0);
    assert!((bit.row.md_m - 1040.0).abs() < 1e-9);
    assert!((bit.row.east_m - 40.0).abs() < 1e-5 && bit.row.north_m.abs() < 1e-5);
    // the stations themselves are untouched by the projection
    for (a, b) in out.rows.iter().zip(&plain.rows) {
        assert_eq!(a.row, b.row);
    }
    // north (across the hole): the azimuth random walk as at the stations,
    // with the last station's error acting over its half leg and the 10 m
    // to the bit; the method's terms on four 10 m legs
    let h = [5.0, 10.0, 10.0, 15.0];
    let s2 = sig.map(|s: f64| s.to_radians().powi(2));
    let var_n = random_walk_variance(&h, &s2) + 4.0 * XCL_10M_LEG * XCL_10M_LEG;
    let c = bit.row.cov.expect("the bit's position is determined");
    assert!((c[0] - var_n).abs() < 1e-6 * var_n, "{} vs {var_n}", c[0]);
    assert!(c[0] > plain.rows[3].row.cov.unwrap()[0]);
    // an undetermined last station leaves the bit undetermined too
    let mut lost = stations.clone();
    lost[3].flags |= station_flags::AZIMUTH_UNDETERMINED;
    lost[3].angles_std[1] = f32::INFINITY;
    let out = survey(&lost, &[], &[], &log(), &setup(Some(10.0))).unwrap();
    assert!(out.bit.is_some_and(|b| b.row.cov.is_none()));
}

#[test]
fn an_undetermined_azimuth_ends_the_positions_and_is_printed_so() {
    let mut stations: Vec<StationSurvey> = (0..4)
        .map(|k| station(k as u16 + 1, 100.0 * (k + 1) as f64, 0.2))
        .collect();
    stations[2].flags |= station_flags::AZIMUTH_UNDETERMINED;
    stations[2].angles_std[1] = f32::INFINITY;
    let out = survey(&stations, &[], &[], &log(), &setup(None)).unwrap();
    let determined: Vec<bool> = out.rows.iter().map(|r| r.position_determined).collect();
    assert_eq!(determined, [true, true, false, false]);
    assert!(out.rows[3].azimuth_determined && out.rows[3].row.cov.is_none());
    let text = listing(&out, 0.95);
    let lines: Vec<&str> = text.lines().filter(|l| l.contains("  1030.00")).collect();
    assert_eq!(lines.len(), 1, "{text}");
    assert!(lines[0].contains("position undetermined"), "{text}");
    assert!(text.contains("undetermined from station 3"), "{text}");
    assert!(!text.contains("lost its heading"), "{text}");
    // a heading lost since the tie-in (not merely never found) says so
    stations[2].flags |= station_flags::HEADING_LOST;
    let out = survey(&stations, &[], &[], &log(), &setup(None)).unwrap();
    let text = listing(&out, 0.95);
    assert!(
        text.contains(
            "lost its heading at station 3 (MD 1020.00 m): its azimuth sigma passed 10 deg"
        ),
        "{text}"
    );
    // an invalid station is skipped, with its reason
    stations[1].flags |= station_flags::SOLUTION_INVALID;
    let out = survey(&stations, &[], &[], &log(), &setup(None)).unwrap();
    assert_eq!(out.rows.len(), 3);
    assert!(out.skipped[0].reason.contains("invalid"));
}

#[test]
fn a_station_whose_md_spans_a_hole_in_the_depth_log_is_flagged() {
    // Rows every 10 s, but none from 120 s to 320 s (a 200 s hole).
    let mut points: Vec<(f64, f64)> = (0..=12).map(|k| (10.0 * k as f64, 1000.0)).collect();
    points.extend((32..=40).map(|k| (10.0 * k as f64, 1000.0 + (k as f64 - 31.0))));
    let depth = DepthLog::new(points).unwrap();
    // Station 1 at a row, station 2 inside the hole, station 3 after it.
    let stations = [
        station(1, 100.0, 0.5),
        station(2, 250.0, 0.5),
        station(3, 395.0, 0.5),
    ];
    let run = |limit: f64| {
        let setup = SurveySetup {
            depth_gap_limit_s: limit,
            ..setup(None)
        };
        survey(&stations, &[None; 3], &[None; 3], &depth, &setup).unwrap()
    };
    let flagged = run(DEPTH_GAP_LIMIT_S);
    let gaps: Vec<Option<f64>> = flagged.rows.iter().map(|r| r.depth_gap_s).collect();
    assert_eq!(gaps, [None, Some(200.0), None]);
    let text = listing(&flagged, 0.95);
    assert!(
        text.contains(&format!("{DEPTH_GAP_FLAG}: station 2 (200 s)"))
            && text.contains("longer than 30 s"),
        "{text}"
    );
    let csv = stations_csv(&flagged, 0.95);
    let rows = table(&csv);
    let flags: Vec<&str> = rows.iter().map(|r| r["flag"].as_str()).collect();
    assert_eq!(flags, ["", DEPTH_GAP_FLAG, ""], "{csv}");
    // A longer limit takes the hole as a pause: no flag, no column.
    let allowed = run(300.0);
    assert!(allowed.rows.iter().all(|r| r.depth_gap_s.is_none()));
    assert!(!stations_csv(&allowed, 0.95).contains("flag"));
    assert!(!listing(&allowed, 0.95).contains(DEPTH_GAP_FLAG));
}

#[test]
fn a_station_outside_the_log_or_a_log_that_is_not_one_is_refused() {
    let late = [station(1, 100.0, 0.1), station(2, 500.0, 0.1)];
    let err = survey(&late, &[], &[], &log(), &setup(None)).unwrap_err();
    assert!(
        format!("{err:#}").contains("outside the depth log"),
        "{err:#}"
    );
    for bad in [
        "",
        "md_m,inc_deg,azi_deg\n0,1,2\n",
        "time_s,md_m\n5,1\n4,2\n",
    ] {
        assert!(DepthLog::read(bad.as_bytes()).is_err(), "{bad:?}");
    }
}

/// CSV text as rows of named cells.
fn table(text: &str) -> Vec<std::collections::HashMap<String, String>> {
    let mut lines = text.lines();
    let head: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
    lines
        .map(|l| {
            head.iter()
                .cloned()
                .zip(l.split(',').map(String::from))
                .collect()
        })
        .collect()
}

fn num(row: &std::collections::HashMap<String, String>, key: &str) -> Option<f64> {
    row.get(key).and_then(|v| v.parse().ok())
}

#[test]
fn a_simulated_short_lateral_is_surveyed_against_its_truth() {
    let dir = scratch("drilling-survey", "short");
    let (bin, truth, depth) = (
        dir.join("run.bin"),
        dir.join("truth.csv"),
        dir.join("depth.csv"),
    );
    let sim = run(&[
        "simulate",
        "--motion",
        "lateral",
        "--plan",
        s(&plan("qemu-short.json")),
        "--seed",
        "5",
        "-o",
        s(&bin),
        "--truth",
        s(&truth),
        "--truth-every",
        "1",
        "--depth-log",
        s(&depth),
    ]);
    assert_eq!(sim.code, Some(0), "{}", sim.stderr);
    let (csv, traj) = (dir.join("stations.csv"), dir.join("trajectory.csv"));
    let out = run(&[
        "survey",
        s(&bin),
        "--depth",
        s(&depth),
        "--tie-on-md",
        "3000",
        "--tie-on-tvd",
        "2450",
        "--tie-on-north",
        "420",
        "--tie-on-east",
        "310",
        "--csv",
        s(&csv),
        "--trajectory",
        s(&traj),
    ]);
    assert_eq!(out.code, Some(0), "{}", out.stderr);
    // the capture replays bit for bit: the survey chains the links the
    // probe's filter held
    assert!(
        out.stdout
            .contains("station links: from the capture's replay"),
        "{}",
        out.stdout
    );
    // replayed at another site than the probe's, no station is the
    // probe's: no links, and the survey says so
    let elsewhere = run(&[
        "survey",
        s(&bin),
        "--depth",
        s(&depth),
        "--site",
        "30",
        "126.687898",
        "124",
        "--tie-on-md",
        "3000",
    ]);
    assert_eq!(elsewhere.code, Some(0), "{}", elsewhere.stderr);
    assert!(
        elsewhere
            .stdout
            .contains("station links: none (0 of the capture's"),
        "{}",
        elsewhere.stdout
    );
    let truth = table(&std::fs::read_to_string(&truth).unwrap());
    let stations = table(&std::fs::read_to_string(&csv).unwrap());
    assert!(!stations.is_empty(), "{}", out.stdout);
    let truth_at = |t: f64| {
        truth
            .iter()
            .min_by(|a, b| {
                let d = |r: &std::collections::HashMap<String, String>| {
                    (num(r, "time_s").unwrap() - t).abs()
                };
                d(a).total_cmp(&d(b))
            })
            .unwrap()
    };
    for st in &stations {
        let t = num(st, "time_s").unwrap();
        let tr = truth_at(t);
        // MD: the log referenced to the tie-on; its scale and stretch over
        // the 3 m drilled are millimetres
        let md = num(st, "md_m").unwrap();
        assert!(
            (md - num(tr, "md_m").unwrap()).abs() < 0.02,
            "{st:?} vs {tr:?}"
        );
        assert!(num(st, "sigma_inc_deg").unwrap() > 0.0);
        match num(st, "azi_deg") {
            // positioned: within 5 sigma of the truth on each axis
            Some(_) if num(st, "north_m").is_some() => {
                for (k, sk) in [("north_m", "sigma_north_m"), ("east_m", "sigma_east_m")] {
                    let (v, sig) = (num(st, k).unwrap(), num(st, sk).unwrap());
                    assert!(
                        (v - num(tr, k).unwrap()).abs() <= 5.0 * sig + 1e-6,
                        "{k}: {st:?}"
                    );
                }
            }
            // no azimuth, no position: empty cells, never a number
            _ => assert!(num(st, "north_m").is_none() && num(st, "sigma_north_m").is_none()),
        }
    }
    let points = table(&std::fs::read_to_string(&traj).unwrap());
    let mds: Vec<f64> = points.iter().map(|p| num(p, "md_m").unwrap()).collect();
    assert!(mds.len() >= 3, "{mds:?}");
    assert!(
        mds.windows(2).all(|w| (w[1] - w[0] - 1.0).abs() < 1e-9),
        "{mds:?}"
    );
    // a depth log that does not cover the capture: a clear error
    let short = dir.join("short-log.csv");
    std::fs::write(&short, "time_s,md_m\n0,3000\n10,3000\n").unwrap();
    let bad = run(&["survey", s(&bin), "--depth", s(&short)]);
    assert_eq!(bad.code, Some(1), "{}", bad.stderr);
    assert!(
        bad.stderr.contains("outside the depth log"),
        "{}",
        bad.stderr
    );
    // a station file is not a depth log
    let stations_file = dir.join("stations-in.csv");
    std::fs::write(&stations_file, "md_m,inc_deg,azi_deg\n3000,90,120\n").unwrap();
    let bad = run(&["survey", s(&bin), "--depth", s(&stations_file)]);
    assert_eq!(bad.code, Some(1), "{}", bad.stderr);
    assert!(bad.stderr.contains("not a depth log"), "{}", bad.stderr);
    assert!(!bad.stderr.contains("panicked"));
}

/// A probe configured with a job's tie-in: its capture replays bit for bit
/// with the same job (`replay --job` exits 0), and the survey with it
/// chains the stations through the replay's links; without the job the
/// replay has no tie-in, differs, and the survey says it has no links.
#[test]
fn a_tied_in_capture_is_surveyed_with_the_links_of_its_replay() {
    let dir = scratch("drilling-survey", "tied-in");
    let (bin, depth, job) = simulate_tied_in(&dir);
    let replay = run(&["replay", s(&bin), "--job", s(&job)]);
    assert_eq!(replay.code, Some(0), "{}{}", replay.stdout, replay.stderr);
    assert!(replay.stdout.contains(" 0 different"), "{}", replay.stdout);
    let survey = |with_job: bool| {
        let mut a = vec!["survey", s(&bin), "--depth", s(&depth)];
        if with_job {
            a.extend(["--job", s(&job)]);
        } else {
            a.extend(["--tie-on-md", "3000"]);
        }
        let out = run(&a);
        assert_eq!(out.code, Some(0), "{}", out.stderr);
        out.stdout
    };
    let linked = survey(true);
    assert!(
        linked.contains("station links: from the capture's replay"),
        "{linked}"
    );
    // the azimuth is the tie-in's, carried: determined at every station
    assert!(!linked.contains("undetermined"), "{linked}");
    let unlinked = survey(false);
    assert!(unlinked.contains("station links: none ("), "{unlinked}");
    // a job without a tie-in is refused by --tie-in-job, clearly
    let no_tie_in = dir.join("no-tie-in.json");
    std::fs::write(
        &no_tie_in,
        r#"{ "format": "mwd-job", "version": 1,
  "site": { "latitude_deg": 45.77755, "longitude_deg": 126.687898, "height_m": 124.0 } }"#,
    )
    .unwrap();
    let bad = run(&[
        "simulate",
        "--motion",
        "lateral",
        "--plan",
        s(&plan("qemu-short.json")),
        "-o",
        s(&dir.join("bad.bin")),
        "--tie-in-job",
        s(&no_tie_in),
    ]);
    assert_eq!(bad.code, Some(1), "{}", bad.stderr);
    assert!(bad.stderr.contains("has no tie_in"), "{}", bad.stderr);
}

#[test]
fn the_coverage_study_finds_its_built_in_plan_from_any_directory() {
    let dir = scratch("drilling-survey", "elsewhere");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_host-sim"))
        .current_dir(&dir)
        .args([
            "study",
            "drilling-coverage",
            "--runs",
            "1",
            "--threads",
            "1",
        ])
        .output()
        .expect("host-sim runs");
    let (stdout, stderr) = (
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr),
    );
    assert_eq!(out.status.code(), Some(0), "{stdout}\n{stderr}");
    assert!(
        stdout.contains("drilling coverage: the built-in 100 m lateral (1 runs"),
        "{stdout}"
    );
}

/// The coverage study's fractions of stations within 2 sigma (JSON keys).
const WITHIN_2_SIGMA: [&str; 3] = [
    "azimuth_within_2_sigma",
    "inclination_within_2_sigma",
    "toolface_within_2_sigma",
];

/// A study fraction's cases inside and its cases.
fn inside_and_total(f: &serde_json::Value) -> (u64, u64) {
    (f["inside"].as_u64().unwrap(), f["total"].as_u64().unwrap())
}

#[test]
fn the_coverage_study_harness_runs_a_short_plan() {
    let dir = scratch("drilling-survey", "study");
    let json = dir.join("study.json");
    let out = run(&[
        "study",
        "drilling-coverage",
        "--plan",
        s(&plan("qemu-short.json")),
        "--runs",
        "12",
        "--json",
        s(&json),
    ]);
    assert_eq!(out.code, Some(0), "{}", out.stderr);
    assert!(
        out.stdout.contains("azimuth within 2 sigma"),
        "{}",
        out.stdout
    );
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(v["runs"], 12);
    assert_eq!(v["failed_runs"].as_array().unwrap().len(), 0, "{v}");
    // every run surveys the window and the stand's end at least
    assert!(v["stations"].as_u64().unwrap() >= 24, "{v}");
    for key in WITHIN_2_SIGMA {
        let f = &v[key];
        let (inside, total) = inside_and_total(f);
        assert!(total > 0 && inside <= total, "{key}: {f}");
        let p = f["fraction"].as_f64().unwrap();
        assert!((p - inside as f64 / total as f64).abs() < 1e-12);
    }
    let td = v["td_inside_95_ellipse"]["total"].as_u64().unwrap();
    let unchecked: u64 = v["td_unchecked"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x[1].as_u64().unwrap())
        .sum();
    assert_eq!(td + unchecked, 12, "{v}");
}

/// `study drilling-coverage --uncalibrated`: the probe runs without the
/// calibration of its parts' deterministic errors, which its station
/// sigmas do not cover. Each station is within 2 sigma or flagged
/// "uncalibrated", and the flag is not set on calibrated runs.
#[test]
fn the_uncalibrated_coverage_study_flags_the_stations_its_sigmas_do_not_cover() {
    let dir = scratch("drilling-survey", "uncalibrated-study");
    let short = plan("qemu-short.json");
    let study = |uncalibrated: bool| {
        let json = dir.join(format!("study-{uncalibrated}.json"));
        let mut args = vec![
            "study",
            "drilling-coverage",
            "--plan",
            s(&short),
            "--runs",
            "3",
            "--json",
            s(&json),
        ];
        if uncalibrated {
            args.push("--uncalibrated");
        }
        let out = run(&args);
        assert_eq!(out.code, Some(0), "{}", out.stderr);
        let v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
        (out.stdout, v)
    };
    let (text, v) = study(true);
    assert!(text.contains("UNCALIBRATED: "), "{text}");
    let stations = v["stations"].as_u64().unwrap();
    assert!(stations >= 6, "{v}");
    assert_eq!(v["uncalibrated_stations"].as_u64(), Some(stations), "{v}");
    for c in v["by_station"].as_array().unwrap() {
        // within 2 sigma in every run, or flagged in every run
        let flagged = c["uncalibrated"].as_u64().unwrap_or(0);
        for key in WITHIN_2_SIGMA {
            let (inside, total) = inside_and_total(&c[key]);
            assert!(inside == total || flagged >= total, "{key}: {c}");
        }
        assert!(
            text.contains(&format!("flagged uncalibrated in {flagged}")),
            "{text}"
        );
    }
    let (text, v) = study(false);
    assert!(
        !text.contains("UNCALIBRATED") && !text.contains("flagged"),
        "{text}"
    );
    assert!(v.get("uncalibrated_stations").is_none(), "{v}");
}
