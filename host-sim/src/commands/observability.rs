//! `host-sim observability`: which errors a static probe's zero-velocity and
//! zero-position updates can determine, at one toolface or over toolface
//! indexing, with a per-state report from the SVD
//! (`host_sim::alignment::observability_report`).
use anyhow::{ensure, Result};
use host_sim::alignment::observability::{analyse, Measurements};
use host_sim::alignment::observability_report::report;
use host_sim::paper::mgwd::PUBLISHED;
use mwd_core::conventions::{Euler, DEG};

use super::site::SiteArgs;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// Roll (toolface) of the first segment, degrees.
    #[arg(long, default_value_t = PUBLISHED.coarse_deg[0], allow_hyphen_values = true)]
    pub roll: f64,
    /// Pitch, degrees.
    #[arg(long, default_value_t = PUBLISHED.coarse_deg[1], allow_hyphen_values = true)]
    pub pitch: f64,
    /// Heading, degrees.
    #[arg(long, default_value_t = PUBLISHED.coarse_deg[2], allow_hyphen_values = true)]
    pub heading: f64,
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
    let start = Euler::new(args.roll * DEG, args.pitch * DEG, args.heading * DEG);
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
