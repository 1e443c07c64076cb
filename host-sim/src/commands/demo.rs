//! `host-sim demo`: the coarse alignment on built-in defaults. Simulates the paper's
//! 60 s static test (section 4) with the SCC1300 error model, coarse-aligns
//! on the first 5 s as the paper did and on the whole minute, then shows
//! what toolface indexing buys; each result next to the truth.
use anyhow::Result;
use host_sim::alignment::coarse;
use host_sim::formats::samples_csv::Record;
use host_sim::paper::mgwd::COARSE_SAMPLES;
use host_sim::sim::{DeterministicErrors, Motion, SensorModel, SensorSimulator, Trajectory};
use mwd_core::alignment::AlignmentConfig;
use mwd_core::conventions::DEG;
use mwd_core::timing::SAMPLE_INTERVAL_S;

use super::simulate::TrajectoryArgs;

#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    pub trajectory: TrajectoryArgs,
    /// Seed of the sensor noise.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
}

/// Calibrates `records` with the paper's Table 3, coarse-aligns their
/// static segments and prints the report under `title`.
fn run_case(title: &str, records: &[Record], config: &AlignmentConfig) -> Result<()> {
    let cal = DeterministicErrors::paper_table3().calibration();
    let records: Vec<_> = records
        .iter()
        .map(|r| coarse::calibrated(r, &cal))
        .collect();
    let report = coarse::align_run(&records, config)?;
    outln!("== {title}");
    out!("{}", report.render());
    outln!();
    Ok(())
}

pub fn run(args: Args) -> Result<()> {
    anyhow::ensure!(
        !matches!(args.trajectory.motion, super::simulate::MotionKind::Lateral),
        "--motion lateral is for `host-sim simulate --plan`; the demo runs at one place"
    );
    let traj = args.trajectory.trajectory();
    // The paper's heading is known to be south-westerly from the parent
    // well: a prior within 90 deg resolves the north/south ambiguity.
    let config = AlignmentConfig::probe(traj.position.lat)
        .with_heading_prior(Some(traj.start.heading + 30.0 * DEG));
    print_setup(&traj);
    let minute = simulate(&traj, 60.0, args.seed);
    run_case(
        "Paper's coarse alignment: first 5 s",
        &minute[..COARSE_SAMPLES],
        &config,
    )?;
    run_case("Whole 60 s static test", &minute, &config)?;
    let indexed = Trajectory {
        motion: Motion::ToolfaceSteps {
            step: std::f64::consts::PI,
            turn_rate: 30.0 * DEG,
            dwell: 600.0,
            steps: 1,
        },
        ..traj
    };
    run_case(
        "Toolface indexing: 10 min at the start toolface, turn 180 deg, 10 min (gyro bias separated from earth rate)",
        &simulate(&indexed, indexed.scripted_duration(), args.seed),
        &config,
    )
}

/// Where the simulated probe is and how it sits.
fn print_setup(traj: &Trajectory) {
    outln!(
        "Simulated SCC1300 probe at rest, {:.5} N {:.6} E {:.0} m; truth roll {:.4} pitch {:.4} azimuth {:.4} deg (the paper's coarse result).",
        traj.position.lat / DEG,
        traj.position.lon / DEG,
        traj.position.height,
        traj.start.roll / DEG,
        traj.start.pitch / DEG,
        host_sim::formats::display::deg_0_360(traj.start.heading)
    );
    outln!("Prior heading for the north/south ambiguity: truth + 30 deg.\n");
}

/// `seconds` of the SCC1300 model on `trajectory`.
fn simulate(trajectory: &Trajectory, seconds: f64, seed: u64) -> Vec<Record> {
    let n = (seconds / SAMPLE_INTERVAL_S).round() as usize;
    let model = SensorModel::scc1300(seed);
    SensorSimulator::new(trajectory.clone(), model, SAMPLE_INTERVAL_S)
        .take(n)
        .map(|s| Record::from(&s))
        .collect()
}
