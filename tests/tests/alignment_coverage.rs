//! Coarse alignment against the simulated SCC1300: the printed
//! 2-sigma bounds must cover the actual errors in at least 90 % of 200
//! seeded trials, and must not be vacuous where the data determine the
//! answer.
use host_sim::alignment::coarse;
use host_sim::formats::samples_csv::Record;
use host_sim::sim::{DeterministicErrors, Motion, SensorModel, SensorSimulator, Trajectory};
use mwd_core::alignment::{AlignmentConfig, COVERAGE_FACTOR, MAX_DETERMINED_SIGMA};
use mwd_core::conventions::{wrap_pi, Euler, DEG};
use mwd_core::earth::Position;
use mwd_core::timing::SAMPLE_INTERVAL_S;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const TRIALS: u64 = 200;

struct Trial {
    roll_covered: bool,
    pitch_covered: bool,
    heading_covered: bool,
    heading_determined: bool,
    heading_bound: f64,
    /// The heading's 1-sigma as computed, before `bound()` turns an
    /// undetermined one into pi (rad).
    heading_sigma: f64,
    heading_error: f64,
    /// Printed 2-sigma half-widths of roll and pitch (rad).
    roll_bound: f64,
    pitch_bound: f64,
    ill_conditioned: bool,
}

fn run_trial(trajectory: Trajectory, seconds: f64, seed: u64, prior: Option<f64>) -> Trial {
    let n = (seconds / SAMPLE_INTERVAL_S).round() as usize;
    let cal = DeterministicErrors::paper_table3().calibration();
    let records: Vec<Record> = SensorSimulator::new(
        trajectory.clone(),
        SensorModel::scc1300(seed),
        SAMPLE_INTERVAL_S,
    )
    .take(n)
    .map(|s| coarse::calibrated(&Record::from(&s), &cal))
    .collect();
    let config = AlignmentConfig::probe(trajectory.position.lat).with_heading_prior(prior);
    let spans = coarse::find_segments(&records);
    let report = coarse::align(&records, &spans, &config).expect("alignment runs");
    let lev = report.levels[0];
    let truth = report.truth[0].expect("simulated files carry truth");
    let h = report.heading;
    let heading_error = wrap_pi(h.heading.value - truth.heading).abs();
    Trial {
        roll_covered: wrap_pi(lev.roll.value - truth.roll).abs()
            <= COVERAGE_FACTOR * lev.roll.sigma,
        pitch_covered: (lev.pitch.value - truth.pitch).abs() <= COVERAGE_FACTOR * lev.pitch.sigma,
        heading_covered: heading_error <= h.bound(),
        heading_determined: h.determined,
        heading_bound: h.bound(),
        heading_sigma: h.heading.sigma,
        heading_error,
        roll_bound: COVERAGE_FACTOR * lev.roll.sigma,
        pitch_bound: COVERAGE_FACTOR * lev.pitch.sigma,
        ill_conditioned: h.ill_conditioned,
    }
}

fn fraction(trials: &[Trial], f: impl Fn(&Trial) -> bool) -> f64 {
    trials.iter().filter(|t| f(t)).count() as f64 / trials.len() as f64
}

/// The paper's 60 s static test at 200 random attitudes. Roll and pitch are
/// always determined; heading is not in one minute, and the bound must say
/// so. The physics: the white noise of a 60 s gyro mean (ARW 0.86
/// deg/sqrt(h): 6.7 deg/h) alone is 0.64 of the horizontal earth rate
/// (10.5 deg/h here), and the two gyros together see at most the whole
/// horizontal earth rate change with heading, so the heading's 1-sigma is
/// at least 0.64 rad (36 deg) before the 2.1 deg/h residual bias: above
/// the 20 deg beyond which a heading is reported undetermined (bound pi,
/// which covers any error). So:
/// * among the trials where heading is determined, the printed bound must
///   cover the error in 90 % of them; at 60 s there must be none, and every
///   trial must report undetermined, bound pi, sigma above the limit;
/// * the linearised sigma the estimator computed (before the bound became
///   pi) must still be honest: 2 sigma covers 90 % of the errors;
/// * the tilt bounds must be finite, not over-confident (the 1 mg residual
///   accelerometer bias alone is 0.057 deg of tilt: 2 sigma >= 0.1 deg) and
///   not vacuous (2 sigma < 0.5 deg), and cover 90 % of the errors.
#[test]
fn sixty_second_static_bounds_cover_the_errors() {
    let mut rng = ChaCha8Rng::seed_from_u64(2026);
    let trials: Vec<Trial> = (0..TRIALS)
        .map(|seed| {
            let truth = Euler::new(
                rng.random_range(-180.0..180.0) * DEG,
                rng.random_range(-30.0..30.0) * DEG,
                rng.random_range(-180.0..180.0) * DEG,
            );
            let prior = truth.heading + rng.random_range(-45.0..45.0) * DEG;
            run_trial(Trajectory::paper_static(truth), 60.0, seed, Some(prior))
        })
        .collect();
    let roll = fraction(&trials, |t| t.roll_covered);
    let pitch = fraction(&trials, |t| t.pitch_covered);
    let heading = fraction(&trials, |t| t.heading_covered);
    let determined: Vec<&Trial> = trials.iter().filter(|t| t.heading_determined).collect();
    let determined_covered = determined.iter().filter(|t| t.heading_covered).count();
    let linearised = fraction(&trials, |t| {
        t.heading_error <= COVERAGE_FACTOR * t.heading_sigma
    });
    let min_sigma = trials
        .iter()
        .map(|t| t.heading_sigma)
        .fold(f64::INFINITY, f64::min);
    let tilt_bounds = trials.iter().flat_map(|t| [t.roll_bound, t.pitch_bound]);
    let (min_tilt, max_tilt) = tilt_bounds.fold((f64::INFINITY, 0.0f64), |(lo, hi), b| {
        (lo.min(b), hi.max(b))
    });
    println!(
        "60 s static: roll {roll:.3} pitch {pitch:.3} heading {heading:.3} covered; \
         heading determined in {} of {TRIALS} ({determined_covered} of them covered); \
         linearised 2-sigma heading coverage {linearised:.3}, smallest sigma {:.1} deg; \
         tilt 2-sigma bounds {:.3}..{:.3} deg",
        determined.len(),
        min_sigma / DEG,
        min_tilt / DEG,
        max_tilt / DEG,
    );
    assert!(roll >= 0.9, "roll coverage {roll}");
    assert!(pitch >= 0.9, "pitch coverage {pitch}");
    assert!(heading >= 0.9, "heading coverage {heading}");
    // Coverage where the bound means something.
    assert!(
        determined_covered as f64 >= 0.9 * determined.len() as f64,
        "determined headings: only {determined_covered} of {} covered",
        determined.len()
    );
    // The expected physics at 60 s: no trial is determined, each says so.
    assert!(
        determined.is_empty(),
        "{} of {TRIALS} headings reported determined at 60 s",
        determined.len()
    );
    for t in &trials {
        assert!(!t.heading_determined && t.heading_bound == std::f64::consts::PI);
        assert!(
            t.heading_sigma > MAX_DETERMINED_SIGMA,
            "sigma {} deg reported undetermined",
            t.heading_sigma / DEG
        );
    }
    assert!(
        linearised >= 0.9,
        "linearised heading sigma covers only {linearised}"
    );
    // Not vacuous and not over-confident: the tilt bounds are a fraction of
    // a degree, no smaller than the residual accelerometer bias allows
    // (min/max skip NaN, so finiteness is checked on every trial).
    assert!(trials
        .iter()
        .all(|t| t.roll_bound.is_finite() && t.pitch_bound.is_finite()));
    assert!(
        min_tilt.is_finite() && min_tilt >= 0.1 * DEG,
        "tilt bound {} deg",
        min_tilt / DEG
    );
    assert!(
        max_tilt.is_finite() && max_tilt < 0.5 * DEG,
        "tilt bound {} deg",
        max_tilt / DEG
    );
}

/// Toolface indexing (2 x 5 min at toolfaces 180 deg apart) at headings
/// within 45 deg of north or south: heading is determined in most trials,
/// its bound is a few tens of degrees at most, and it covers the error.
#[test]
fn toolface_indexed_heading_bounds_cover_the_errors() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let trials: Vec<Trial> = (0..TRIALS)
        .map(|seed| {
            let north_or_south = if rng.random_bool(0.5) { 0.0 } else { 180.0 };
            let heading = (north_or_south + rng.random_range(-45.0..45.0)) * DEG;
            let truth = Euler::new(
                rng.random_range(-180.0..180.0) * DEG,
                rng.random_range(-20.0..20.0) * DEG,
                heading,
            );
            let trajectory = Trajectory {
                position: Position::paper_site(),
                start: truth,
                motion: Motion::ToolfaceSteps {
                    step: std::f64::consts::PI,
                    turn_rate: 30.0 * DEG,
                    dwell: 300.0,
                    steps: 1,
                },
            };
            let seconds = trajectory.scripted_duration();
            let prior = heading + rng.random_range(-45.0..45.0) * DEG;
            run_trial(trajectory, seconds, 1000 + seed, Some(prior))
        })
        .collect();
    let heading = fraction(&trials, |t| t.heading_covered);
    let determined = fraction(&trials, |t| t.heading_determined);
    let mut bounds: Vec<f64> = trials
        .iter()
        .filter(|t| t.heading_determined)
        .map(|t| t.heading_bound / DEG)
        .collect();
    bounds.sort_by(f64::total_cmp);
    let median = bounds
        .get(bounds.len() / 2)
        .copied()
        .unwrap_or(f64::INFINITY);
    println!("indexed: heading covered {heading:.3}, determined {determined:.3}, median bound {median:.1} deg");
    assert!(heading >= 0.9, "heading coverage {heading}");
    // Headings up to 45 deg from north or south at inclinations 70-110 deg:
    // the sigma covers the expected sigma of every heading the data allow
    // at 3 sigma, which reach towards east/west (the
    // bounds of runs that looked sharp by luck missed the truth), so about
    // a fifth stay determined (18 %; 70 % before, not all of them
    // honestly: see tests/tests/alignment_classes.rs).
    assert!(
        determined >= 0.15,
        "heading determined in only {determined}"
    );
    assert!(median < 40.0, "median bound {median} deg");
    assert!(trials
        .iter()
        .all(|t| !t.ill_conditioned || !t.heading_determined || t.heading_bound > 0.0));
}

/// Heading east or west is reported as ill-conditioned with real noise too.
#[test]
fn east_west_headings_are_flagged_ill_conditioned() {
    for (seed, heading) in [(1u64, 90.0), (2, -88.0), (3, 95.0)] {
        let truth = Euler::new(0.4, -0.1, heading * DEG);
        let t = run_trial(
            Trajectory::paper_static(truth),
            60.0,
            seed,
            Some(heading * DEG),
        );
        assert!(t.ill_conditioned, "heading {heading} not flagged");
    }
}

/// The flag comes from the geometry, not from the prior: the test above
/// sets the prior to the truth, and a prior near east or west raises the
/// flag by itself. Here the same headings (within 5 deg of east or west)
/// with no prior, and with a prior pointing north (far from the truth),
/// after 60 s at rest and after toolface indexing (2 x 5 min), 80 trials:
/// at least 90 % must be flagged ill-conditioned (the noise-free geometry
/// flags them all, see the unit tests in mwd-core), and where a heading is
/// reported determined its printed bound must cover the error in at least
/// 90 % of those trials, as everywhere else.
#[test]
fn east_west_flag_comes_from_the_geometry_not_the_prior() {
    let indexed = |truth: Euler| Trajectory {
        position: Position::paper_site(),
        start: truth,
        motion: Motion::ToolfaceSteps {
            step: std::f64::consts::PI,
            turn_rate: 30.0 * DEG,
            dwell: 300.0,
            steps: 1,
        },
    };
    let mut unflagged = Vec::new();
    let mut overconfident = Vec::new();
    let mut determined = 0;
    let mut total = 0;
    for (name, prior) in [("no prior", None), ("prior north", Some(0.0))] {
        for seed in 0..20u64 {
            let heading = [90.0, -88.0, 95.0, -95.0][seed as usize % 4];
            let truth = Euler::new(0.4, -0.1, heading * DEG);
            for (kind, trajectory) in [
                ("60 s", Trajectory::paper_static(truth)),
                ("indexed", indexed(truth)),
            ] {
                let seconds = match kind {
                    "60 s" => 60.0,
                    _ => trajectory.scripted_duration(),
                };
                let t = run_trial(trajectory, seconds, 100 + seed, prior);
                total += 1;
                let case = format!(
                    "{kind}, {name}, heading {heading}, seed {seed}: error {:.1} deg, \
                     bound {:.1} deg, determined {}",
                    t.heading_error / DEG,
                    t.heading_bound / DEG,
                    t.heading_determined
                );
                if !t.ill_conditioned {
                    unflagged.push(case.clone());
                }
                determined += usize::from(t.heading_determined);
                if t.heading_determined && !t.heading_covered {
                    overconfident.push(case);
                }
            }
        }
    }
    println!(
        "east/west: {} of {total} trials not flagged ill-conditioned; \
         heading determined in {determined}, {} of them with the error outside the bound",
        unflagged.len(),
        overconfident.len()
    );
    assert!(
        10 * overconfident.len() <= determined,
        "{} of {determined} determined east/west headings have the error \
         outside the bound: {overconfident:#?}",
        overconfident.len()
    );
    assert!(
        10 * unflagged.len() <= total,
        "{} of {total} east/west headings not flagged ill-conditioned without \
         a prior near the truth: {unflagged:#?}",
        unflagged.len()
    );
}
