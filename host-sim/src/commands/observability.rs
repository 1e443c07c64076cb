//! `host-sim observability`: which errors a static probe's zero-velocity and
//! zero-position updates can determine, at one toolface or over toolface
//! indexing, with a per-state report from the SVD.
use anyhow::{ensure, Result};
use host_sim::alignment::observability::{analyse, Analysis, Measurements, STATE_NAMES};
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
    report(&args, &a);
    Ok(())
}

/// Ranks, each state's unobservable share and the unobservable directions.
fn report(args: &Args, a: &Analysis) {
    outln!(
        "{} states, {} toolface segment(s) {:?} deg, measurements: {}",
        a.states,
        args.toolfaces.len(),
        args.toolfaces,
        args.measurements
    );
    outln!("rank of each segment's obsv(F, H): {:?}", a.segment_ranks);
    outln!(
        "rank of the stripped observability matrix: {} of {} (stripping condition {})",
        a.stripped_rank,
        a.states,
        if a.stripping_condition {
            "holds: this is the total rank"
        } else {
            "does not hold: a lower bound"
        }
    );
    // Shares are of each state's unit vector (states scaled to 1 mrad,
    // 1 cm/s, 1 cm, 1 mg, 2 deg/h) lying in the unobservable subspace.
    outln!("\n{:<28} {:>13}", "state", "unobservable");
    for (i, name) in STATE_NAMES.iter().enumerate().take(a.states) {
        outln!(
            "{:<28} {:>12.0}%",
            name,
            100.0 * a.report.unobservable_share[i]
        );
    }
    for (k, v) in a.report.unobservable_directions.iter().enumerate() {
        let parts: Vec<String> = v
            .iter()
            .enumerate()
            .filter(|(_, c)| c.abs() > 0.1)
            .map(|(i, c)| format!("{c:+.2} {}", STATE_NAMES[i]))
            .collect();
        outln!("unobservable direction {}: {}", k + 1, parts.join(", "));
    }
}
