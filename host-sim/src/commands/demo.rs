//! `host-sim demo`: the coarse alignment on built-in defaults. Simulates the paper's
//! 60 s static test (section 4) with the SCC1300 error model, coarse-aligns
//! on the first 5 s as the paper did and on the whole minute, then shows
//! what toolface indexing buys; each result next to the truth
//! (`host_sim::alignment::demo`).
use anyhow::Result;
use host_sim::alignment::demo::{case_text, config, indexed, setup_text, simulate};
use host_sim::paper::mgwd::COARSE_SAMPLES;

use super::simulate::TrajectoryArgs;

#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    pub trajectory: TrajectoryArgs,
    /// Seed of the sensor noise.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
}

pub fn run(args: Args) -> Result<()> {
    anyhow::ensure!(
        !matches!(args.trajectory.motion, super::simulate::MotionKind::Lateral),
        "--motion lateral is for `host-sim simulate --plan`; the demo runs at one place"
    );
    let traj = args.trajectory.trajectory();
    let config = config(&traj);
    out!("{}", setup_text(&traj));
    let minute = simulate(&traj, 60.0, args.seed);
    let first_5_s = &minute[..COARSE_SAMPLES];
    out!(
        "{}",
        case_text("Paper's coarse alignment: first 5 s", first_5_s, &config)?
    );
    out!("{}", case_text("Whole 60 s static test", &minute, &config)?);
    let indexed = indexed(&traj);
    out!(
        "{}",
        case_text(
            "Toolface indexing: 10 min at the start toolface, turn 180 deg, 10 min (gyro bias separated from earth rate)",
            &simulate(&indexed, indexed.scripted_duration(), args.seed),
            &config,
        )?
    );
    Ok(())
}
