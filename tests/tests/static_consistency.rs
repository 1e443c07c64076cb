//! Consistency of every sigma the probe prints over long static runs:
//! seeded Monte Carlo runs of a still probe with the simulator's SCC1300
//! (`host_sim::sim::SensorModel::scc1300`: the MGWD paper's deterministic
//! errors, Table 3, then each seed's turn-on residual bias, bias
//! instability, AR(4) and white noise, quantised to the parts' LSB),
//! through the probe's own navigator, sampled every 10 s.
//!
//! For each printed state (roll, pitch, azimuth, three velocities, three
//! positions) it counts the sampled epochs whose sigma is a number on a
//! solution not flagged invalid, and how many of them hold the error within
//! 2 sigma. Two probes see the same sensors:
//! - calibrated with the parts' deterministic errors (as a six-position
//!   calibration gives them): what its error budget describes; every state
//!   must hold its error within 2 sigma in at least 93 % of those epochs;
//! - without a calibration: its budget leaves the parts' turn-on errors out,
//!   so every frame must carry the "uncalibrated" bit (its figures are
//!   printed to show why).
//!
//! In both, a NaN sigma always comes with the "solution invalid" bit.
//!
//! The test command runs 20 seeds of 2 h (past the first station the still
//! probe navigates free under the moving tool's constraints; about 40 s in
//! release), and gives the figures per 2 h from the start too. The
//! day-long figures (every state within 2 sigma in at least 99 % of the
//! epochs of 20 seeds of 24 h: docs/filter-derivation.md section 5c;
//! `STATIC_CONSISTENCY_SEEDS` sets the number of seeds):
//! `STATIC_CONSISTENCY_HOURS=24 cargo test --release -p system-tests --test
//! static_consistency -- --ignored --nocapture`.

use host_sim::formats::capture::raw_sample_from_body;
use host_sim::sim::{SensorModel, SensorSimulator, Trajectory};
use mwd_core::calibration::ProbeCalibration;
use mwd_core::conventions::{wrap_pi, DrillingAngles, Euler};
use mwd_core::earth::{LocalEarth, Position};
use mwd_core::probe::tie_in::TieIn;
use mwd_core::probe::Navigator;
use mwd_core::protocol::frame::{nav_flags, nav_mode};
use mwd_core::protocol::NavSolution;
use mwd_core::timing::SAMPLE_RATE_HZ;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;

const SEEDS: u64 = 20;
/// Every 10 s of frames.
const CHECK_EVERY: u64 = 200;
/// The bound: at least this share of sampled epochs within 2 sigma.
const MIN_WITHIN_2_SIGMA: f64 = 0.93;
const STATES: [&str; 9] = [
    "roll", "pitch", "azimuth", "vN", "vE", "vD", "pN", "pE", "pD",
];

/// The paper's static attitude (the `simulate` defaults).
fn start() -> Euler {
    Euler::new(
        (-0.8061f64).to_radians(),
        0.5371f64.to_radians(),
        (-150.9636f64).to_radians(),
    )
}

/// Per state: epochs with a printed number (on a valid solution), those
/// within 2 sigma, epochs flagged invalid, epochs with the sigma +inf
/// (undetermined); and the largest |error| / sigma.
#[derive(Default, Clone, Copy)]
struct Tally {
    printed: u64,
    within_2: u64,
    flagged_invalid: u64,
    undetermined: u64,
    worst: f64,
}

/// Width (h) of the time spans the figures are also given by.
const SPAN_HOURS: f64 = 2.0;

struct Run {
    tallies: [Tally; 9],
    /// Per span of [`SPAN_HOURS`] from the start, per state: (printed,
    /// within 2 sigma).
    spans: Vec<[(u64, u64); 9]>,
    frames: u64,
    flagged_uncalibrated: u64,
}

/// (error, sigma) of each state against a still probe at `site`.
fn errors_and_sigmas(
    nav: &NavSolution,
    truth: &Euler,
    site: &Position,
    earth: &LocalEarth,
) -> [(f64, f32); 9] {
    let attitude = [truth.roll, truth.pitch, truth.heading];
    let position = [
        (nav.latitude - site.lat) * (earth.meridian + site.height),
        (nav.longitude - site.lon) * (earth.transverse + site.height) * earth.cos_lat,
        -(f64::from(nav.height) - site.height),
    ];
    core::array::from_fn(|i| match i {
        0..=2 => (
            wrap_pi(f64::from(nav.attitude[i]) - attitude[i]),
            nav.attitude_std[i],
        ),
        3..=5 => (f64::from(nav.velocity_ned[i - 3]), nav.velocity_std[i - 3]),
        _ => (position[i - 6], nav.position_std_ned[i - 6]),
    })
}

fn run(seed: u64, hours: f64, calibrated: bool) -> Run {
    let model = SensorModel::scc1300(seed);
    let calibration = if calibrated {
        model.deterministic.calibration()
    } else {
        ProbeCalibration::default()
    };
    let trajectory = Trajectory::paper_static(start());
    let site = trajectory.position;
    let earth = LocalEarth::at(&site);
    let mut navigator = Navigator::with_calibration(site, calibration);
    let samples = (hours * 3600.0 * SAMPLE_RATE_HZ).round() as u64;
    let sim = SensorSimulator::new(trajectory, model, 1.0 / SAMPLE_RATE_HZ);
    let mut out = Run {
        tallies: [Tally::default(); 9],
        spans: vec![[(0, 0); 9]; span_count(hours)],
        frames: 0,
        flagged_uncalibrated: 0,
    };
    for (n, s) in (0..samples).zip(sim) {
        let nav = navigator.step(&raw_sample_from_body(n as u32, &s.gyro, &s.accel));
        out.frames += 1;
        if nav.flags & nav_flags::UNCALIBRATED != 0 {
            out.flagged_uncalibrated += 1;
        }
        let invalid = nav.flags & nav_flags::SOLUTION_INVALID != 0;
        let sigmas = [nav.attitude_std, nav.velocity_std, nav.position_std_ned];
        assert!(
            invalid || sigmas.iter().flatten().all(|s| !s.is_nan()),
            "seed {seed}, sample {n}: a NaN sigma without the invalid bit: {nav:?}"
        );
        if n % CHECK_EVERY != 0 || nav.mode == nav_mode::COARSE_ALIGNMENT {
            continue;
        }
        let span = ((n as f64 / SAMPLE_RATE_HZ / 3600.0) / SPAN_HOURS) as usize;
        for ((tally, in_span), (error, sigma)) in out
            .tallies
            .iter_mut()
            .zip(out.spans[span].iter_mut())
            .zip(errors_and_sigmas(&nav, &s.truth, &site, &earth))
        {
            if invalid {
                tally.flagged_invalid += 1;
            } else if sigma == f32::INFINITY {
                tally.undetermined += 1;
            } else {
                assert!(sigma.is_finite() && sigma > 0.0, "seed {seed}: {nav:?}");
                let ratio = error.abs() / f64::from(sigma);
                tally.printed += 1;
                tally.within_2 += u64::from(ratio <= 2.0);
                in_span.0 += 1;
                in_span.1 += u64::from(ratio <= 2.0);
                tally.worst = tally.worst.max(ratio);
            }
        }
    }
    out
}

/// Runs every seed on the machine's cores and adds their tallies.
fn study(hours: f64, calibrated: bool) -> Run {
    let next = AtomicU64::new(1);
    let total = Mutex::new(Run {
        tallies: [Tally::default(); 9],
        spans: vec![[(0, 0); 9]; span_count(hours)],
        frames: 0,
        flagged_uncalibrated: 0,
    });
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    std::thread::scope(|scope| {
        for _ in 0..threads {
            scope.spawn(|| loop {
                let seed = next.fetch_add(1, Ordering::Relaxed);
                if seed > seeds() {
                    break;
                }
                let r = run(seed, hours, calibrated);
                let mut t = total.lock().unwrap_or_else(|e| e.into_inner());
                t.frames += r.frames;
                t.flagged_uncalibrated += r.flagged_uncalibrated;
                for (a, b) in t.tallies.iter_mut().zip(r.tallies) {
                    a.printed += b.printed;
                    a.within_2 += b.within_2;
                    a.flagged_invalid += b.flagged_invalid;
                    a.undetermined += b.undetermined;
                    a.worst = a.worst.max(b.worst);
                }
                for (a, b) in t.spans.iter_mut().zip(&r.spans) {
                    for (x, y) in a.iter_mut().zip(b) {
                        x.0 += y.0;
                        x.1 += y.1;
                    }
                }
            });
        }
    });
    total.into_inner().unwrap_or_else(|e| e.into_inner())
}

fn print(title: &str, hours: f64, r: &Run) {
    eprintln!(
        "{title}: {} seeds x {hours} h, sampled every {} s",
        seeds(),
        CHECK_EVERY as f64 / SAMPLE_RATE_HZ
    );
    eprintln!("state    printed  within 2 sigma  worst |e|/sigma  flagged invalid  undetermined");
    for (name, t) in STATES.iter().zip(&r.tallies) {
        let share = if t.printed > 0 {
            format!("{:>13.1} %", 100.0 * t.within_2 as f64 / t.printed as f64)
        } else {
            format!("{:>15}", "-")
        };
        eprintln!(
            "{name:<8} {:>7} {share} {:>16.2} {:>16} {:>13}",
            t.printed, t.worst, t.flagged_invalid, t.undetermined
        );
    }
}

/// The share within 2 sigma per span of [`SPAN_HOURS`] ("-": none printed).
fn print_spans(r: &Run) {
    eprintln!("within 2 sigma by time from the start:");
    eprintln!("hours  {}", STATES.map(|s| format!("{s:>8}")).join(""));
    for (k, span) in r.spans.iter().enumerate() {
        let from = k as f64 * SPAN_HOURS;
        let shares = span.map(|(printed, within)| {
            if printed == 0 {
                format!("{:>8}", "-")
            } else {
                format!("{:>7.1}%", 100.0 * within as f64 / printed as f64)
            }
        });
        eprintln!("{:>2}-{:<4}{}", from, from + SPAN_HOURS, shares.join(""));
    }
}

fn span_count(hours: f64) -> usize {
    ((hours / SPAN_HOURS).ceil() as usize).max(1)
}

/// Seeds 1..=N (`STATIC_CONSISTENCY_SEEDS`, default [`SEEDS`]).
fn seeds() -> u64 {
    std::env::var("STATIC_CONSISTENCY_SEEDS")
        .ok()
        .and_then(|n| n.parse::<u64>().ok())
        .filter(|n| *n > 0)
        .unwrap_or(SEEDS)
}

fn hours() -> f64 {
    std::env::var("STATIC_CONSISTENCY_HOURS")
        .ok()
        .and_then(|h| h.parse::<f64>().ok())
        .filter(|h| h.is_finite() && *h > 0.0)
        .unwrap_or(2.0)
}

#[test]
#[ignore = "20 seeded static runs: run in release, scripts/test-all.sh"]
fn a_calibrated_probe_holds_every_printed_state_within_2_sigma() {
    let hours = hours();
    let r = study(hours, true);
    print("calibrated probe", hours, &r);
    print_spans(&r);
    assert_eq!(r.flagged_uncalibrated, 0);
    for (name, t) in STATES.iter().zip(&r.tallies) {
        if *name == "azimuth" && t.printed == 0 {
            // One still minute of SCC1300 cannot gyrocompass: the azimuth
            // is undetermined, never a number (the frames' rule).
            assert!(t.undetermined > 0, "{name}");
            continue;
        }
        assert!(t.printed > 0, "{name}: no epoch with a printed sigma");
        let share = t.within_2 as f64 / t.printed as f64;
        assert!(
            share >= MIN_WITHIN_2_SIGMA,
            "{name}: {:.1} % within 2 sigma",
            100.0 * share
        );
    }
}

#[test]
#[ignore = "20 seeded static runs: run in release, scripts/test-all.sh"]
fn an_uncalibrated_probe_flags_every_frame() {
    let hours = hours();
    let r = study(hours, false);
    print(
        "uncalibrated probe (every frame flagged uncalibrated)",
        hours,
        &r,
    );
    assert_eq!(r.flagged_uncalibrated, r.frames);
}

/// The day-long pitch's old failure, isolated: the vertical (z) gyro's
/// white noise alone (every other error of the simulated sensors off),
/// tied in at the true attitude, 20 h still. Past the longest station the
/// moving tool's constraints hold the still tool; an error model that
/// followed the estimate's heading noise there walked the pitch by about
/// -15 mdeg/h (-291 mdeg at 20 h against a 114 mdeg sigma), where the
/// first-estimates linearisation keeps it at a few mdeg
/// (docs/filter-derivation.md section 5c). Each hour from the fourth on,
/// the pitch error must stay within 1 sigma.
#[test]
#[ignore = "a 20 h run: run in release, scripts/test-all.sh"]
fn the_vertical_gyros_noise_alone_does_not_walk_the_pitch() {
    let mut model = SensorModel::ideal();
    model.noise.gyro[2].white_density = SensorModel::scc1300(1).noise.gyro[2].white_density;
    model.seed = 1;
    let calibration = model.deterministic.calibration();
    let trajectory = Trajectory::paper_static(start());
    let site = trajectory.position;
    let mut navigator = Navigator::with_calibration(site, calibration);
    let hour = (3600.0 * SAMPLE_RATE_HZ) as u64;
    let sim = SensorSimulator::new(trajectory, model, 1.0 / SAMPLE_RATE_HZ);
    let mut tied_in = false;
    for (n, s) in (0..20 * hour + 1).zip(sim) {
        let nav = navigator.step(&raw_sample_from_body(n as u32, &s.gyro, &s.accel));
        if !tied_in && nav.mode == nav_mode::NAVIGATING {
            let given = DrillingAngles::from_euler(&s.truth);
            let sigma = DrillingAngles {
                inclination: 1e-3,
                azimuth: 1e-2,
                toolface: 1e-3,
            };
            navigator.start_from_tie_in(&TieIn::new(given, sigma).expect("a valid tie-in"));
            tied_in = true;
        }
        if n >= 4 * hour && n % hour == 0 {
            let error = wrap_pi(f64::from(nav.attitude[1]) - s.truth.pitch);
            let sigma = f64::from(nav.attitude_std[1]);
            assert!(
                error.abs() <= sigma,
                "hour {}: pitch error {:.4} deg, sigma {:.4} deg",
                n / hour,
                error.to_degrees(),
                sigma.to_degrees()
            );
        }
    }
    assert!(tied_in, "the navigator never navigated");
}
