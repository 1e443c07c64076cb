//! `host-sim observability`: which errors a static probe's zero-velocity and
//! zero-position updates can determine, at one toolface or over toolface
//! indexing, with a per-state report from the SVD
//! (`host_sim::alignment::observability_report`).
use anyhow::{ensure, Result};
use host_sim::alignment::observability::{analyse, Measurements};
use host_sim::alignment::observability_report::report;
use mwd_core::conventions::DEG;

use super::site::{AttitudeArgs, SiteArgs};

#[derive(clap::Args, Debug)]
#[command(
    mut_arg("roll", |a| a.help("Roll (toolface) of the first segment, degrees")),
    mut_arg("pitch", |a| a.help("Pitch, degrees")),
    mut_arg("heading", |a| a.help("Heading, degrees"))
)]
pub struct Args {
    #[command(flatten)]
    pub attitude: AttitudeArgs,
    #[command(flatten)]
    pub site: SiteArgs,
    /// Toolface offsets of the segments, degrees (e.g. 0,180 for indexing).
    #[arg(long, value_delimiter = ',', default_values_t = [0.0], allow_hyphen_values = true)]
    pub toolfaces: Vec<f64>,
    /// Leave out the six constant sensor-bias states (9 navigation errors only).
    #[arg(long)]
    pub no_biases: bool,
    /// Measurements: zupt, zpu or both.
    #[arg(long, default_value = "both")]
    pub measurements: String,
}

pub fn run(args: Args) -> Result<()> {
    let Some(measurements) = Measurements::from_name(&args.measurements) else {
        anyhow::bail!(
            "--measurements takes zupt, zpu or both, not `{}`",
            args.measurements
        );
    };
    ensure!(
        !args.toolfaces.is_empty() && args.toolfaces.len() <= 16,
        "1 to 16 toolface segments"
    );
    let start = args.attitude.euler();
    let offsets: Vec<f64> = args.toolfaces.iter().map(|t| t * DEG).collect();
    let a = analyse(
        &start,
        args.site.position(),
        &offsets,
        !args.no_biases,
        measurements,
    );
    out!("{}", report(&args.toolfaces, &args.measurements, &a));
    Ok(())
}
