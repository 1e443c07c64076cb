//! A heading reported determined must be covered by its
//! printed 2-sigma bound in at least 90 % of the trials of every attitude
//! class (inclination x azimuth), for a 60 s position, a 600 s position and
//! toolface indexing (2 x 300 s, 180 deg apart), or be reported
//! undetermined. The simulated SCC1300 (seeded), calibrated with the
//! paper's Table 3, and a prior 20 deg off the truth (as the issue's
//! reproduction gives `--prior-heading 155` for a tool heading 135).
//! A class fails when its misses show a coverage below 90 % (see
//! `below_ninety_percent`); every class's figures are printed.
use host_sim::alignment::coarse;
use host_sim::formats::samples_csv::Record;
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

/// Whether `misses` among `n` determined runs show the coverage to be
/// below 90 %: more than 10 % missed, and that many or more would happen
/// with 90 % coverage with a probability under 1 % (binomial tail). A
/// class with one determined run that misses is not evidence of a
/// coverage below 90 % (it happens in one class of ten at exactly 90 %),
/// and 40 or 200 seeds give classes of any size.
fn below_ninety_percent(n: usize, misses: usize) -> bool {
    if 10 * misses <= n {
        return false;
    }
    // P(X >= misses), X ~ Binomial(n, 0.1).
    let p: f64 = 0.1;
    let tail: f64 = (misses..=n)
        .map(|k| {
            let ln_choose = (1..=k)
                .map(|i| (((n - k + i) as f64) / i as f64).ln())
                .sum::<f64>();
            (ln_choose + k as f64 * p.ln() + (n - k) as f64 * (1.0 - p).ln()).exp()
        })
        .sum();
    tail < 0.01
}

/// Every class of `kinds` x `inclinations` x `azimuths` with `seeds`
/// trials each, the classes shared among the machine's cores (each class's
/// trials in seed order, so the figures do not depend on the threads);
/// each class's line printed, the failing ones returned.
fn sweep(inclinations: &[f64], azimuths: &[f64], kinds: &[Kind], seeds: u64) -> Vec<String> {
    let classes: Vec<(Kind, f64, f64)> = kinds
        .iter()
        .flat_map(|&k| {
            inclinations
                .iter()
                .flat_map(move |&i| azimuths.iter().map(move |&a| (k, i, a)))
        })
        .collect();
    // The study runner's pool: each thread takes the next class, the
    // outcomes in class order.
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    let results = host_sim::study::run_seeds(classes.len(), 0, threads, &|| {}, |c| {
        let (kind, inclination, azimuth) = classes[c as usize];
        Ok(class(inclination, azimuth, kind, seeds))
    });
    let mut failures = Vec::new();
    for (&(kind, inclination, azimuth), (_, t)) in classes.iter().zip(results) {
        let t = t.expect("every class ran");
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
        if below_ninety_percent(t.determined, t.determined - t.covered) {
            failures.push(line);
        }
    }
    failures
}

/// One class's trials, in seed order.
fn class(inclination: f64, azimuth: f64, kind: Kind, seeds: u64) -> Tally {
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
    t
}

/// Seeds per class: 200, or `ALIGNMENT_CLASS_SEEDS`.
fn seeds() -> u64 {
    std::env::var("ALIGNMENT_CLASS_SEEDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(200)
}

/// One class and kind, `ALIGNMENT_CLASS` = "kind inclination azimuth"
/// (kind 60, 600 or indexed), for a closer look with many seeds.
#[test]
#[ignore]
fn determined_headings_are_covered_in_one_class() {
    let spec = std::env::var("ALIGNMENT_CLASS").unwrap_or_else(|_| "600 60 135".into());
    let parts: Vec<&str> = spec.split_whitespace().collect();
    let kind = match parts.first().copied() {
        Some("60") => Kind::Static60,
        Some("indexed") => Kind::Indexed,
        _ => Kind::Static600,
    };
    let number =
        |i: usize, default: f64| parts.get(i).and_then(|p| p.parse().ok()).unwrap_or(default);
    let failures = sweep(&[number(1, 60.0)], &[number(2, 135.0)], &[kind], seeds());
    assert!(failures.is_empty(), "{failures:#?}");
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
        seeds(),
    );
    assert!(failures.is_empty(), "{failures:#?}");
}
