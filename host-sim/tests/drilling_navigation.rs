//! The probe's navigator through a simulated lateral (issue 13, part 2):
//! the drilling simulator's samples go through `mwd_core::probe::Navigator`
//! as raw frames, the navigator is tied in at the end of its levelling, and
//! its station surveys are compared with the simulator's truth.
use host_sim::formats::capture::{raw_sample_from_si, SiSample};
use host_sim::sim::plan::Plan;
use host_sim::sim::{DeterministicErrors, DrillState, Drilling, DrillingSimulator, SensorModel};
use mwd_core::calibration::{GyroCalibration, ProbeCalibration, TriadCalibration};
use mwd_core::conventions::{wrap_pi, DrillingAngles, DEG};
use mwd_core::error_model::GYRO_BIAS;
use mwd_core::probe::{Navigator, TieIn};
use mwd_core::protocol::frame::station_flags;
use mwd_core::protocol::StationSurvey;
use mwd_core::timing::SAMPLE_INTERVAL_S;
use std::path::Path;

/// The six-position calibration that exactly undoes the simulated part's
/// deterministic errors (the paper's Table 3), as a calibrated probe has.
fn table3_calibration() -> ProbeCalibration {
    let e = DeterministicErrors::paper_table3();
    let triad = TriadCalibration {
        bias: [e.accel_bias.x, e.accel_bias.y, e.accel_bias.z],
        ..TriadCalibration::IDENTITY
    };
    ProbeCalibration {
        accel: [triad; 2],
        gyro: [
            GyroCalibration {
                bias: e.gyro_bias.x,
                ..GyroCalibration::IDENTITY
            },
            GyroCalibration {
                bias: e.gyro_bias.z,
                ..GyroCalibration::IDENTITY
            },
        ],
    }
}

struct Run {
    /// (station, truth angles at its end sample).
    stations: Vec<(StationSurvey, DrillingAngles)>,
    max_speed: f64,
    max_tilt_std: f64,
    /// The filter's x and z rate-bias 1-sigma (rad/s) when tied in and
    /// after each station.
    bias_std: Vec<[f32; 2]>,
    /// Per connection turn: the heading error's change (rad) from the last
    /// still sample before the orienter turns to 3 s into the drilling
    /// after it, and the heading sigma then.
    turn_heading_changes: Vec<(f64, f64)>,
}

fn run(plan_json: &str, seed: u64) -> Run {
    let dir = std::env::temp_dir().join(format!("drillnav-{}-{seed}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("plan.json");
    std::fs::write(&path, plan_json).unwrap();
    let plan = Plan::load(Path::new(&path)).expect("valid plan");
    let site = plan.site;
    let drilling = Drilling::new(plan, seed);
    let sim = DrillingSimulator::new(&drilling, SensorModel::scc1300(seed), SAMPLE_INTERVAL_S);
    let mut navigator = Navigator::with_calibration(site, table3_calibration());
    let mut truths: Vec<DrillingAngles> = Vec::new();
    let mut out = Run {
        stations: Vec::new(),
        max_speed: 0.0,
        max_tilt_std: 0.0,
        bias_std: Vec::new(),
        turn_heading_changes: Vec::new(),
    };
    // (heading error at the last still sample, drilling samples since).
    let mut turn: Option<(f64, u32)> = None;
    let mut last_still_heading_error = None;
    let bias_std = |n: &Navigator| {
        let k = n.filter().filter();
        [k.std_dev(GYRO_BIAS), k.std_dev(GYRO_BIAS + 2)]
    };
    let mut tied = false;
    for (index, s) in sim.enumerate() {
        let accel = [s.sample.accel.x, s.sample.accel.y, s.sample.accel.z];
        let raw = raw_sample_from_si(&SiSample {
            index: index as u32,
            gyro_body_xz_rad_s: [s.sample.gyro.x, s.sample.gyro.z],
            accel_body_m_s2: [accel, accel],
            temperature_degc: 25.0,
        });
        let truth = DrillingAngles::from_euler(&s.truth.euler());
        truths.push(truth);
        let frame = navigator.step(&raw);
        if navigator.is_navigating() && !tied {
            let t = TieIn::new(
                DrillingAngles {
                    inclination: truth.inclination,
                    azimuth: truth.azimuth,
                    toolface: truth.toolface,
                },
                DrillingAngles {
                    inclination: 0.1 * DEG,
                    azimuth: 0.5 * DEG,
                    toolface: 0.3 * DEG,
                },
            )
            .unwrap();
            navigator.start_from_tie_in(&t);
            out.bias_std.push(bias_std(&navigator));
            tied = true;
        }
        if tied && s.truth.state == DrillState::Drilling {
            let v = frame.velocity_ned.map(f64::from);
            out.max_speed = out
                .max_speed
                .max((v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt());
            out.max_tilt_std = out
                .max_tilt_std
                .max(f64::from(frame.attitude_std[0].max(frame.attitude_std[1])));
        }
        if tied {
            let heading_error = wrap_pi(f64::from(frame.attitude[2]) - s.truth.euler().heading);
            match s.truth.state {
                DrillState::Still => last_still_heading_error = Some(heading_error),
                DrillState::Connection => {
                    if let Some(e) = last_still_heading_error.take() {
                        turn = Some((e, 0));
                    }
                }
                DrillState::Drilling => {
                    if let Some((e, k)) = turn.as_mut() {
                        *k += 1;
                        if *k == 60 {
                            let sigma = navigator.filter().euler_std().z;
                            out.turn_heading_changes
                                .push((wrap_pi(heading_error - *e), sigma));
                            turn = None;
                        }
                    }
                }
            }
        }
        if std::env::var("DIAG").is_ok() && tied && index % 600 == 0 {
            let e = s.truth.euler();
            eprintln!(
                "t {:7.0} {:?} md {:7.2} roll err {:7.2} pitch err {:6.2} head err {:7.2} sd {:6.2} tf {:6.1} flags {:#x}",
                s.truth.time,
                s.truth.state,
                s.truth.md,
                wrap_pi(f64::from(frame.attitude[0]) - e.roll) / DEG,
                (f64::from(frame.attitude[1]) - e.pitch) / DEG,
                wrap_pi(f64::from(frame.attitude[2]) - e.heading) / DEG,
                f64::from(frame.attitude_std[2]) / DEG,
                truth.toolface / DEG,
                frame.flags
            );
        }
        if let Some(st) = navigator.take_station() {
            let t = truths[st.end_sample as usize];
            if std::env::var("DIAG").is_ok() {
                let a = truths[st.start_sample as usize];
                let b = truths[st.end_sample as usize - 40];
                eprintln!(
                    "station {} truth tf start {:.3} end-40 {:.3} end {:.3} now {:.3}",
                    st.station,
                    a.toolface / DEG,
                    b.toolface / DEG,
                    t.toolface / DEG,
                    truth.toolface / DEG
                );
            }
            out.stations.push((st, t));
            out.bias_std.push(bias_std(&navigator));
            eprintln!(
                "station {}: filter heading sigma {:.2} deg (the frames' azimuth rule aside)",
                st.station,
                navigator.filter().euler_std().z / DEG
            );
        }
    }
    out
}

fn report(r: &Run) {
    for (st, t) in &r.stations {
        let e = [
            f64::from(st.angles[0]) - t.inclination,
            wrap_pi(f64::from(st.angles[1]) - t.azimuth),
            wrap_pi(f64::from(st.angles[2]) - t.toolface),
        ];
        eprintln!(
            "st {:3} flags {:#06x} inc err {:8.4} sd {:8.4} | azi err {:8.3} sd {:8.3} | tf err {:8.3} sd {:8.3}",
            st.station,
            st.flags,
            e[0] / DEG,
            f64::from(st.angles_std[0]) / DEG,
            e[1] / DEG,
            f64::from(st.angles_std[1]) / DEG,
            e[2] / DEG,
            f64::from(st.angles_std[2]) / DEG
        );
    }
    eprintln!(
        "max speed {} max tilt std {} deg",
        r.max_speed,
        r.max_tilt_std / DEG
    );
}

/// Fractions of the stations whose inclination and toolface errors are
/// within their 2-sigma (of those with finite sigmas), and how many had a
/// determined azimuth within its 2-sigma.
fn coverage(r: &Run) -> ([f64; 3], usize) {
    let mut inside = [0usize; 3];
    let mut determined = 0;
    for (st, t) in &r.stations {
        let e = [
            f64::from(st.angles[0]) - t.inclination,
            wrap_pi(f64::from(st.angles[1]) - t.azimuth),
            wrap_pi(f64::from(st.angles[2]) - t.toolface),
        ];
        for k in 0..3 {
            if e[k].abs() <= 2.0 * f64::from(st.angles_std[k]) {
                inside[k] += 1;
            }
        }
        if st.flags & station_flags::AZIMUTH_UNDETERMINED == 0 {
            determined += 1;
        }
    }
    let n = r.stations.len().max(1) as f64;
    (inside.map(|c| c as f64 / n), determined)
}

/// Drilling through the short QEMU plan (1.5 m stands at 90 m/h, moderate
/// vibration): the drilling mode keeps the velocity and the tilt sigma
/// bounded, and every connection gives a station. `DRILL_PLAN=NAME` runs
/// another of data/plans (e.g. lateral-100m.json, in release) and prints
/// the station errors against their sigmas.
#[test]
fn drilling_keeps_velocity_and_tilt_bounded_and_stations_come() {
    let name = std::env::var("DRILL_PLAN").unwrap_or_else(|_| "qemu-short.json".into());
    let plan = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("data/plans")
            .join(&name),
    )
    .unwrap();
    let r = run(&plan, 1);
    report(&r);
    let (fractions, determined) = coverage(&r);
    eprintln!(
        "{name}: {} stations; within 2 sigma: inclination {:.2}, azimuth {:.2}, toolface {:.2}; azimuth determined at {determined}",
        r.stations.len(),
        fractions[0],
        fractions[1],
        fractions[2]
    );
    let deg_h = |v: f32| f64::from(v) / DEG * 3600.0;
    for b in &r.bias_std {
        eprintln!(
            "rate-bias sigma x {:.3} z {:.3} deg/h",
            deg_h(b[0]),
            deg_h(b[1])
        );
    }
    // The rate gyrocompass runs at every block of 40 still cycles; with
    // this gyro noise a 5-minute station resolves the bias of the gyro
    // nearest the vertical to ~3 deg/h, the budget's own prior (derivation
    // section 4e): the sigmas stay finite and do not run away.
    assert!(
        r.bias_std
            .iter()
            .flatten()
            .all(|s| s.is_finite() && deg_h(*s) < 10.0),
        "{:?}",
        r.bias_std
    );
    // Unaided, the vibration's 0.74 g per sample would walk the velocity
    // by 0.36 m/s a sample (tens of m/s within a minute).
    assert!(r.max_speed < 2.0, "max speed {} m/s", r.max_speed);
    assert!(
        r.max_tilt_std < 3.0 * DEG,
        "tilt sigma {} deg",
        r.max_tilt_std / DEG
    );
    assert!(r.stations.len() >= 2, "{} stations", r.stations.len());
    // A connection's toolface turn leaves the heading where it was: the
    // still detector sees the turn a few samples late and the vibration
    // comes before the jitter window holds it, and both went, unmodelled,
    // through the non-holonomic updates into the heading (up to 8 deg per
    // connection against a 7 deg sigma before; derivation section 4h).
    assert!(!r.turn_heading_changes.is_empty());
    for (change, sigma) in &r.turn_heading_changes {
        eprintln!(
            "connection turn: heading error moved {:.3} deg (sigma {:.2} deg)",
            change / DEG,
            sigma / DEG
        );
        assert!(change.abs() < 0.5 * DEG, "{} deg", change / DEG);
    }
}
