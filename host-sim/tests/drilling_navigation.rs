//! The probe's navigator through a simulated lateral (issue 13, part 2):
//! the drilling simulator's samples go through `mwd_core::probe::Navigator`
//! as raw frames, the navigator is tied in at the end of its levelling, and
//! its station surveys are compared with the simulator's truth.
use host_sim::capture::{raw_sample_from_si, SiSample};
use host_sim::sim::plan::Plan;
use host_sim::sim::{DeterministicErrors, DrillState, Drilling, DrillingSimulator, SensorModel};
use mwd_core::calibration::{GyroCalibration, ProbeCalibration, TriadCalibration};
use mwd_core::conventions::{wrap_pi, DrillingAngles, DEG};
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
            tied = true;
        }
        if tied && s.truth.state == DrillState::Drilling {
            let v = frame.velocity_ned.map(f64::from);
            out.max_speed = out.max_speed.max((v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt());
            out.max_tilt_std = out
                .max_tilt_std
                .max(f64::from(frame.attitude_std[0].max(frame.attitude_std[1])));
        }
        if let Some(st) = navigator.take_station() {
            let t = truths[st.end_sample as usize];
            out.stations.push((st, t));
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
    eprintln!("max speed {} max tilt std {} deg", r.max_speed, r.max_tilt_std / DEG);
}

#[test]
fn experiment() {
    let plan = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("data/plans/lateral-100m.json"),
    )
    .unwrap();
    let r = run(&plan, 1);
    report(&r);
    let _ = station_flags::AZIMUTH_UNDETERMINED;
}
