//! Issue 11 item 15: a heading reported determined must be covered by its
//! printed 2-sigma bound in at least 90 % of the trials of every attitude
//! class (inclination x azimuth), for a 60 s position, a 600 s position and
//! toolface indexing (2 x 300 s, 180 deg apart), or be reported
//! undetermined. The simulated SCC1300 (seeded), calibrated with the
//! paper's Table 3, and a prior 20 deg off the truth (as the issue's
//! reproduction gives `--prior-heading 155` for a tool heading 135).
use host_sim::coarse;
use host_sim::samples_csv::Record;
use host_sim::sim::{DeterministicErrors, Motion, SensorModel, SensorSimulator, Trajectory};
use mwd_core::alignment::AlignmentConfig;
use mwd_core::conventions::{wrap_pi, DrillingAngles, DEG};
use mwd_core::earth::Position;
use mwd_core::timing::SAMPLE_INTERVAL_S;

#[derive(Clone, Copy, Debug, PartialEq)]
enum Kind {
    Static60,
    Static600,
    Indexed,
}

#[derive(Clone, Copy, Debug, Default)]
struct Tally {
    trials: usize,
    determined: usize,
    covered: usize,
    /// Largest |error| / bound among the determined trials.
    worst_ratio: f64,
}

fn trajectory(inclination: f64, azimuth: f64, toolface: f64, kind: Kind) -> (Trajectory, f64) {
    let start = DrillingAngles {
        inclination: inclination * DEG,
        azimuth: azimuth * DEG,
        toolface: toolface * DEG,
    }
    .to_euler();
    let motion = match kind {
        Kind::Indexed => Motion::ToolfaceSteps {
            step: std::f64::consts::PI,
            turn_rate: 30.0 * DEG,
            dwell: 300.0,
            steps: 1,
        },
        _ => Motion::Static,
    };
    let t = Trajectory {
        position: Position::paper_site(),
        start,
        motion,
    };
    let seconds = match kind {
        Kind::Static60 => 60.0,
        Kind::Static600 => 600.0,
        Kind::Indexed => t.scripted_duration(),
    };
    (t, seconds)
}

/// One seeded trial: (determined, covered, |error| / bound).
fn trial(inclination: f64, azimuth: f64, kind: Kind, seed: u64) -> (bool, bool, f64) {
    // Toolface and the prior's side from the seed, reproducibly.
    let toolface = (seed * 137 % 360) as f64;
    let prior_side = if seed % 2 == 0 { 1.0 } else { -1.0 };
    let (traj, seconds) = trajectory(inclination, azimuth, toolface, kind);
    let cal = DeterministicErrors::paper_table3().calibration();
    let n = (seconds / SAMPLE_INTERVAL_S).round() as usize;
    let records: Vec<Record> =
        SensorSimulator::new(traj.clone(), SensorModel::scc1300(seed), SAMPLE_INTERVAL_S)
            .take(n)
            .map(|s| coarse::calibrated(&Record::from(&s), &cal))
            .collect();
    let prior = (azimuth + prior_side * 20.0) * DEG;
    let config = AlignmentConfig::probe(traj.position.lat).with_heading_prior(Some(prior));
    let spans = coarse::find_segments(&records);
    let report = coarse::align(&records, &spans, &config).expect("alignment runs");
    let truth = report.truth.last().copied().flatten().expect("truth");
    let h = report.heading;
    let error = wrap_pi(h.heading.value - truth.heading).abs();
    (h.determined, error <= h.bound(), error / h.bound())
}

fn sweep(inclinations: &[f64], azimuths: &[f64], kinds: &[Kind], seeds: u64) -> Vec<String> {
    let mut failures = Vec::new();
    for &kind in kinds {
        for &inclination in inclinations {
            for &azimuth in azimuths {
                let mut t = Tally::default();
                for seed in 0..seeds {
                    let (determined, covered, ratio) = trial(inclination, azimuth, kind, seed);
                    t.trials += 1;
                    if determined {
                        t.determined += 1;
                        t.covered += usize::from(covered);
                        t.worst_ratio = t.worst_ratio.max(ratio);
                    }
                }
                let line = format!(
                    "{kind:?} incl {inclination} az {azimuth}: determined {} of {}, \
                     {} covered ({:.0} %), worst error/bound {:.2}",
                    t.determined,
                    t.trials,
                    t.covered,
                    100.0 * t.covered as f64 / t.determined.max(1) as f64,
                    t.worst_ratio
                );
                println!("{line}");
                if 10 * t.covered < 9 * t.determined {
                    failures.push(line);
                }
            }
        }
    }
    failures
}

/// The class (inclination 60, azimuth 135, roll 90: 9 of 34
/// determined 600 s runs outside their bound) and its neighbours.
#[test]
fn determined_headings_are_covered_in_the_reported_class() {
    let failures = sweep(&[60.0], &[135.0], &[Kind::Static600], 40);
    assert!(failures.is_empty(), "{failures:#?}");
}

/// Every class: inclination 5 to 90 deg, azimuth every 45 deg, the three
/// kinds of run. Too long for the debug test build (about 2 x 10^7
/// simulated samples); `scripts/test-all.sh` runs it in release.
#[test]
#[ignore]
fn determined_headings_are_covered_in_every_class() {
    let azimuths: Vec<f64> = (0..8).map(|k| 45.0 * k as f64).collect();
    let failures = sweep(
        &[5.0, 30.0, 60.0, 90.0],
        &azimuths,
        &[Kind::Static60, Kind::Static600, Kind::Indexed],
        40,
    );
    assert!(failures.is_empty(), "{failures:#?}");
}
