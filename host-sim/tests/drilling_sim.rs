//! The drilling simulator (`host-sim simulate --motion lateral --plan`):
//! truth against minimum curvature, the connection schedule, the depth
//! log's errors, the capture's sample count, consistency with the strapdown
//! mechanization, and refused plans.
mod common;

use common::{run, s, scratch};
use host_sim::sim::plan::{Plan, Tortuosity, Vibration};
use host_sim::sim::{DrillState, Drilling, DrillingSimulator, SensorModel};
use mwd_core::conventions::{quat_from_dcm, DEG};
use mwd_core::mechanization::{ImuSample, NavState, Strapdown};
use mwd_core::timing::SAMPLE_INTERVAL_S;
use nalgebra::Vector3;
use std::path::{Path, PathBuf};

fn plan_path(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("data/plans")
        .join(name)
}

fn load(name: &str) -> host_sim::sim::BuiltPlan {
    Plan::load(&plan_path(name)).expect("the repository's plan is valid")
}

/// Minimum curvature written out here (SPE/ISCWSA: chord = L/2 RF (t1 +
/// t2), RF = tan(beta/2) / (beta/2)), independent of `mwd_core::survey`.
fn min_curvature(
    start: Vector3<f64>,
    stations: &[(f64, f64, f64)], // (md, inc, azi) in m, rad
) -> Vec<Vector3<f64>> {
    let t = |i: f64, a: f64| Vector3::new(i.sin() * a.cos(), i.sin() * a.sin(), i.cos());
    let mut out = vec![start];
    for w in stations.windows(2) {
        let (t1, t2) = (t(w[0].1, w[0].2), t(w[1].1, w[1].2));
        let beta = t1.dot(&t2).clamp(-1.0, 1.0).acos();
        let rf = if beta < 1e-9 {
            1.0
        } else {
            (beta / 2.0).tan() / (beta / 2.0)
        };
        let last = out[out.len() - 1];
        out.push(last + (t1 + t2) * (0.5 * (w[1].0 - w[0].0) * rf));
    }
    out
}

#[test]
fn truth_positions_match_minimum_curvature_at_the_plan_stations() {
    for name in ["lateral-100m.json", "lateral-1000m.json"] {
        // the plan drilled exactly (no tortuosity): the simulator's own
        // geometry against minimum curvature written out
        let mut plan = load(name);
        plan.drilling.tortuosity = Tortuosity::NONE;
        let stations: Vec<_> = plan
            .stations
            .iter()
            .map(|s| (s.md(), s.inclination(), s.azimuth()))
            .collect();
        let expected = min_curvature(plan.tie_on.nev(), &stations);
        let drilling = Drilling::new(plan.clone(), 1);
        for (k, (&(md, inc, azi), nev)) in stations.iter().zip(&expected).enumerate() {
            let t = drilling.time_at_md(md);
            let truth = drilling.truth(t);
            assert!(
                (truth.md - md).abs() < 1e-6,
                "{name} station {k}: MD {}",
                truth.md
            );
            // MD is reached to 1e-6 m: positions agree to that.
            assert!(
                (truth.point.nev - nev).norm() < 1e-5,
                "{name} station {k}: {:?} vs {nev:?}",
                truth.point.nev
            );
            assert!((truth.point.inclination - inc).abs() < 1e-8);
            assert!((truth.point.azimuth - azi).abs() < 1e-8);
            // The body attitude carries the same direction: pitch = inc -
            // 90 deg, heading = azimuth.
            let e = truth.euler();
            assert!((e.pitch - (inc - 90.0 * DEG)).abs() < 1e-8);
            assert!(mwd_core::conventions::wrap_pi(e.heading - azi).abs() < 1e-8);
        }
        // Between stations, the truth is the plan's interpolation along
        // the arc (mwd_core::survey::interpolate).
        let last = stations[stations.len() - 1].0;
        let mut md = stations[0].0 + 3.7;
        while md < last {
            let truth = drilling.truth(drilling.time_at_md(md));
            let survey = plan.interpolate(truth.md).expect("inside the plan");
            assert!(
                (truth.point.nev - survey.nev).norm() < 1e-9,
                "{name} at {md}"
            );
            md += 23.3;
        }
    }
}

#[test]
fn the_mechanization_fed_ideal_samples_reproduces_the_truth_attitude() {
    // Ideal samples: no sensor errors, no vibration, the tool-axis rate
    // taken from the truth (the probe derives it from its accelerometers).
    // Integrated with mwd_core::mechanization::Strapdown (paper eq. 3-8:
    // quaternion attitude with coning, velocity, position), 20 Hz, from
    // the true state at t = 0.
    let mut plan = load("lateral-100m.json");
    plan.drilling.vibration = Vibration::NONE;
    let drilling = Drilling::new(plan, 5);
    let start = drilling.truth(0.0);
    let mut nav = Strapdown::new(
        NavState::at_rest(quat_from_dcm(&start.c_bn), start.position),
        SAMPLE_INTERVAL_S,
    );
    let mut worst: f64 = 0.0;
    let mut n = 0;
    for d in DrillingSimulator::new(&drilling, SensorModel::ideal(), SAMPLE_INTERVAL_S) {
        nav.step(&ImuSample {
            rate: d.sample.true_rate,
            specific_force: d.sample.true_accel,
        });
        // Velocity and position held to the truth (as ZUPTs and the depth
        // log hold them on the probe): the free vertical channel diverges
        // with a time constant of sqrt(R / 2g) ~ 9.5 min, and in the 3.8 h
        // of a 100 m lateral any 1e-12 m/s error grows to km, whose
        // transport rate then turns the attitude. The attitude is free.
        let (v_err, p_err) = (
            nav.state().velocity - d.truth.velocity(),
            nav.state().position.ned_from(&d.truth.position),
        );
        nav.apply_correction(&Vector3::zeros(), &v_err, &p_err);
        let truth = quat_from_dcm(&d.truth.c_bn);
        let err = nav.state().attitude.angle_to(&truth);
        worst = worst.max(err);
        n += 1;
    }
    assert_eq!(n, drilling.sample_count(SAMPLE_INTERVAL_S));
    let end = drilling.truth(drilling.duration());
    assert!(end.md - drilling.plan().start_md() > 99.9);
    eprintln!(
        "{n} samples, largest attitude difference {:.2e} deg",
        worst / DEG
    );
    assert!(worst < 0.01 * DEG, "attitude off by {} deg", worst / DEG);
}

/// A short plan with short stands (quick to run).
fn short_plan(dir: &Path) -> PathBuf {
    let path = dir.join("short.json");
    std::fs::write(
        &path,
        r#"{
  "tie_on": { "md_m": 2000.0, "tvd_m": 1500.0, "north_m": 0.0, "east_m": 0.0,
              "inclination_deg": 90.0, "azimuth_deg": 45.0 },
  "sections": [
    { "type": "curve", "dls_deg_per_30m": 6.0, "inclination_deg": 91.0, "azimuth_deg": 47.0 },
    { "type": "hold", "end_md_m": 2030.0, "toolface_deg": 10.0 }
  ],
  "drilling": { "rop_m_per_h": 60.0, "stand_length_m": 10.0, "connection_still_s": 120.0,
                "initial_still_s": 60.0,
                "depth_errors": { "scale_ppm": 800.0, "stretch_per_m": 4e-7 } }
}"#,
    )
    .unwrap();
    path
}

fn parse_csv(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines
        .next()
        .unwrap()
        .split(',')
        .map(str::to_owned)
        .collect();
    let rows = lines
        .map(|l| l.split(',').map(str::to_owned).collect())
        .collect();
    (header, rows)
}

#[test]
fn cli_writes_truth_depth_log_and_a_capture_of_every_sample() {
    let dir = scratch("drillsim", "cli");
    let plan = short_plan(&dir);
    let (bin, truth, depth) = (dir.join("run.bin"), dir.join("t.csv"), dir.join("d.csv"));
    let r = run(&[
        "simulate",
        "--motion",
        "lateral",
        "--plan",
        s(&plan),
        "-o",
        s(&bin),
        "--truth",
        s(&truth),
        "--truth-every",
        "1",
        "--depth-log",
        s(&depth),
        "--seed",
        "9",
    ]);
    assert_eq!(r.code, Some(0), "{}", r.stderr);

    // Truth: one row per sample plus t = 0.
    let (header, rows) = parse_csv(&truth);
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    let (c_t, c_md, c_tvd, c_state) = (col("time_s"), col("md_m"), col("tvd_m"), col("state"));
    let num = |row: &Vec<String>, c: usize| row[c].parse::<f64>().unwrap();
    // Expected length: 60 s + 3 x (10 m at 60 m/h + 10 s of ramps + 120 s
    // still) + 2 turns of 30 deg at 10 deg/s.
    let duration = 60.0 + 3.0 * (600.0 + 10.0 + 120.0) + 2.0 * 3.0;
    let samples = (duration / SAMPLE_INTERVAL_S).round() as usize;
    assert_eq!(rows.len(), samples + 1);

    // Connections: runs of "still" after drilling, each 120 s long, at
    // every 10 m of MD.
    let mut runs: Vec<(String, f64, f64, f64)> = Vec::new(); // state, start, end, md
    for row in &rows {
        let (state, t, md) = (row[c_state].clone(), num(row, c_t), num(row, c_md));
        match runs.last_mut() {
            Some(last) if last.0 == state => last.2 = t,
            _ => runs.push((state, t, t, md)),
        }
    }
    let stills: Vec<_> = runs.iter().filter(|r| r.0 == "still").skip(1).collect();
    assert_eq!(stills.len(), 3, "{runs:?}");
    for (i, still) in stills.iter().enumerate() {
        // The run's rows cover (start - 0.05 s, end]: 120 s in all.
        let length = still.2 - still.1 + SAMPLE_INTERVAL_S;
        assert!(
            (length - 120.0).abs() <= SAMPLE_INTERVAL_S + 1e-6,
            "still {i}: {length} s"
        );
        assert!((still.3 - (2000.0 + 10.0 * (i + 1) as f64)).abs() < 1e-6);
    }
    assert_eq!(runs.iter().filter(|r| r.0 == "connection").count(), 2);
    // Each connection turns the toolface by the plan's 30 deg (default),
    // MD unchanged.
    let c_tf = col("toolface_deg");
    let mut turns = 0;
    for w in rows.windows(2) {
        if w[0][c_state] == "still" && w[1][c_state] == "connection" {
            let before = num(&w[0], c_tf);
            let end = rows
                .iter()
                .skip_while(|r| num(r, c_t) <= num(&w[1], c_t))
                .find(|r| r[c_state] != "connection")
                .expect("drilling after the connection");
            let turned = (num(end, c_tf) - before + 540.0).rem_euclid(360.0) - 180.0;
            assert!((turned.abs() - 30.0).abs() < 0.01, "turned {turned} deg");
            assert_eq!(num(end, c_md), num(&w[0], c_md));
            turns += 1;
        }
    }
    assert_eq!(turns, 2);

    // Depth log: monotone, and md_log - md = scale md + stretch md TVD.
    let (_, log) = parse_csv(&depth);
    let mut last = f64::NEG_INFINITY;
    let mut worst: f64 = 0.0;
    for (k, row) in log.iter().enumerate() {
        let (t, md_log) = (num(row, 0), num(row, 1));
        assert!(md_log >= last, "depth log goes back at {t} s");
        last = md_log;
        // The truth row at the same time (one per 50 ms).
        let truth_row = &rows[k * 20];
        assert!((num(truth_row, c_t) - t).abs() < 1e-9);
        let (md, tvd) = (num(truth_row, c_md), num(truth_row, c_tvd));
        let expected = md * 800e-6 + 4e-7 * md * tvd;
        worst = worst.max((md_log - md - expected).abs());
    }
    // Printed to 0.1 mm (log) and 1 um (truth).
    assert!(worst < 1e-4, "depth error off by {worst} m");
    // The errors are there: 1.6 m + 1.2 m at 2000 m.
    assert!(last - 2030.0 > 2.5, "{last}");

    // The capture decodes to one raw frame per sample.
    let r = run(&["decode", s(&bin)]);
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    let frames = r
        .stdout
        .lines()
        .find(|l| l.starts_with("frames"))
        .expect("a frames line");
    assert!(
        frames.contains(&format!("raw sample {samples},")),
        "{frames}"
    );
}

#[test]
fn the_same_seed_gives_the_same_capture_and_another_seed_another() {
    let dir = scratch("drillsim", "seed");
    let plan = short_plan(&dir);
    let out = |seed: &str, name: &str| {
        let path = dir.join(name);
        let r = run(&[
            "simulate",
            "--motion",
            "lateral",
            "--plan",
            s(&plan),
            "-o",
            s(&path),
            "--seed",
            seed,
        ]);
        assert_eq!(r.code, Some(0), "{}", r.stderr);
        std::fs::read(path).unwrap()
    };
    let (a, b, c) = (out("4", "a.bin"), out("4", "b.bin"), out("5", "c.bin"));
    assert!(a == b, "same seed, different bytes");
    assert!(a != c, "different seeds, same bytes");
}

/// The capture's navigation and station frames are the probe's own
/// (`Navigator` at the configured site, the plan's): `replay` of the
/// capture, which knows only that site, gets every one bit for bit (exit 0).
/// It did not when the simulator's navigator ran at the probe's position
/// down hole: every solution differed.
#[test]
fn a_drilling_capture_replays_bit_for_bit() {
    let dir = scratch("drillsim", "replay");
    let plan = short_plan(&dir);
    let bin = dir.join("run.bin");
    let r = run(&[
        "simulate",
        "--motion",
        "lateral",
        "--plan",
        s(&plan),
        "-o",
        s(&bin),
        "--seed",
        "3",
    ]);
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    let r = run(&["replay", s(&bin)]);
    assert_eq!(r.code, Some(0), "replay: {}\n{}", r.stdout, r.stderr);
    let parity = r
        .stdout
        .lines()
        .find(|l| l.starts_with("replay parity"))
        .unwrap_or_else(|| panic!("no parity line: {}", r.stdout));
    assert!(parity.contains(" 0 different, 0 not compared"), "{parity}");
    let stations = r
        .stdout
        .lines()
        .find(|l| l.starts_with("station parity"))
        .unwrap_or_else(|| panic!("no station line: {}", r.stdout));
    assert!(
        stations.contains("0 different, 0 not compared"),
        "{stations}"
    );
    assert!(
        !stations.starts_with("station parity   0 replayed"),
        "{stations}"
    );
}

#[test]
fn vibration_reaches_the_samples_as_stated_and_harsh_levels_clip() {
    // Moderate: 2 g RMS lateral over 5-500 Hz through a first-order 50 Hz
    // low-pass: sqrt(0.1385) x 2 g = 0.744 g per sample on body x.
    let mut plan = load("lateral-100m.json");
    plan.drilling.vibration = Vibration::MODERATE;
    let expected = 2.0 * 9.80665 * Vibration::MODERATE.passed_power_fraction().sqrt();
    assert!((expected / 9.80665 - 0.744).abs() < 0.001, "{expected}");
    let drilling = Drilling::new(plan.clone(), 2);
    let (mut still, mut moving) = (Vec::new(), Vec::new());
    let mut x = Vec::new();
    for d in
        DrillingSimulator::new(&drilling, SensorModel::scc1300(2), SAMPLE_INTERVAL_S).take(200_000)
    {
        let dev = (d.sample.accel.norm() - 9.80665).abs();
        match d.truth.state {
            DrillState::Still => still.push(dev),
            DrillState::Drilling => {
                moving.push(dev);
                x.push(d.sample.accel.x - d.sample.true_accel.x);
            }
            DrillState::Connection => {}
        }
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let m = mean(&x);
    let sd = (x.iter().map(|v| (v - m).powi(2)).sum::<f64>() / x.len() as f64).sqrt();
    // Shocks (30 g, 6 an hour) add a little; the rest is sampling error.
    assert!((sd / expected - 1.0).abs() < 0.05, "{sd} vs {expected}");
    // A still-period detector can tell rest from drilling: the norm of
    // the specific force is 1 g to noise at rest, spread while drilling.
    assert!(mean(&still) < 0.1, "still: {}", mean(&still));
    assert!(mean(&moving) > 2.0, "drilling: {}", mean(&moving));

    // Harsh (the paper's 15 g RMS): 5.6 g per sample on each axis; most
    // drilling samples have an axis beyond the 6 g range.
    plan.drilling.vibration = Vibration::HARSH;
    let drilling = Drilling::new(plan, 2);
    let (mut over, mut drilled, mut over_still) = (0, 0, 0);
    for d in
        DrillingSimulator::new(&drilling, SensorModel::scc1300(2), SAMPLE_INTERVAL_S).take(200_000)
    {
        match d.truth.state {
            DrillState::Drilling => {
                drilled += 1;
                over += usize::from(d.accel_over_range);
            }
            _ => over_still += usize::from(d.accel_over_range),
        }
    }
    let fraction = over as f64 / drilled as f64;
    assert!(fraction > 0.4 && fraction < 0.9, "{fraction}");
    assert_eq!(over_still, 0);
}

#[test]
fn bad_plans_and_arguments_are_refused_with_a_reason() {
    let dir = scratch("drillsim", "bad");
    let good = std::fs::read_to_string(plan_path("lateral-100m.json")).unwrap();
    let cases = [
        (
            "md",
            good.replace("\"end_md_m\": 3020.0", "\"end_md_m\": 2990.0"),
            "end_md_m",
        ),
        (
            "dls",
            good.replacen("\"dls_deg_per_30m\": 6.0", "\"dls_deg_per_30m\": 60.0", 1),
            "dls_deg_per_30m",
        ),
        (
            "zero-dls",
            good.replacen("\"dls_deg_per_30m\": 6.0", "\"dls_deg_per_30m\": 0.0", 1),
            "dls_deg_per_30m",
        ),
        (
            "inf",
            good.replace("\"rop_m_per_h\": 30.0", "\"rop_m_per_h\": 1e999"),
            "not a well plan",
        ),
        (
            "unknown",
            good.replace("\"rop_m_per_h\"", "\"rop\""),
            "unknown field",
        ),
        (
            "ramp",
            good.replace("\"lateral_rms_g\": 2.0", "\"lateral_rms_g\": -2.0"),
            "lateral_rms_g",
        ),
        ("empty", String::new(), "not a well plan"),
    ];
    for (name, text, needle) in cases {
        let path = dir.join(format!("{name}.json"));
        std::fs::write(&path, text).unwrap();
        let r = run(&[
            "simulate",
            "--motion",
            "lateral",
            "--plan",
            s(&path),
            "-o",
            s(&dir.join("x.bin")),
        ]);
        assert_eq!(r.code, Some(1), "{name}: {}", r.stderr);
        assert!(r.stderr.contains(needle), "{name}: {}", r.stderr);
        assert!(!r.stderr.contains("panicked"), "{name}: {}", r.stderr);
    }
    let r = run(&[
        "simulate",
        "--motion",
        "lateral",
        "-o",
        s(&dir.join("x.bin")),
    ]);
    assert_eq!(r.code, Some(1));
    assert!(r.stderr.contains("--plan"), "{}", r.stderr);
    let r = run(&[
        "simulate",
        "--plan",
        s(&plan_path("lateral-100m.json")),
        "-o",
        s(&dir.join("x.csv")),
    ]);
    assert_eq!(r.code, Some(1));
    assert!(r.stderr.contains("--motion lateral"), "{}", r.stderr);
}
