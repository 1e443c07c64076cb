//! `host-sim paper rins`: the redundant-RINS paper's 120 h semi-physical
//! simulation (section 4.1, Figures 3-6) reproduced, ours beside the
//! paper's figures. The experiment is `host_sim::paper::rins`'s, its
//! report `host_sim::paper::rins_report`'s; this module reads the options
//! and prints.

use super::output::print_out;
use anyhow::Result;
use host_sim::paper::rins::{self, Scenario};
use host_sim::paper::rins_report::{report, strapdown_check};
use std::path::PathBuf;

#[derive(clap::Args, Debug)]
pub struct RinsArgs {
    /// Seed of the noise and the initial errors.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Length of the run (h).
    #[arg(long, default_value_t = Scenario::paper().hours)]
    pub hours: f64,
    /// When the master fails (h).
    #[arg(long, default_value_t = Scenario::paper().failure_hour)]
    pub failure_hour: f64,
    /// Filter step (s); the systems are simulated in 1 s substeps.
    #[arg(long, default_value_t = Scenario::paper().filter_step)]
    pub filter_step: f64,
    /// Vehicle speed (m/s), due east at the scenario's latitude.
    #[arg(long, default_value_t = Scenario::paper().speed)]
    pub speed: f64,
    /// Gyro angle random walk of both systems (deg/sqrt(h)); the paper's
    /// bound 0.001 by default.
    #[arg(long, default_value_t = 0.001)]
    pub gyro_arw: f64,
    /// Write the SVG and PNG plots of Figures 3-6 into this directory.
    #[arg(long, value_name = "DIR")]
    pub plot: Option<PathBuf>,
    /// Print the summary and the history as JSON instead of the report.
    #[arg(long)]
    pub json: bool,
    /// Instead of the paper's run: each system's error-state propagation
    /// against a full strapdown run of the same sensor errors over `--hours`
    /// (4 h if not given), docs/redundant-rins.md.
    #[arg(long)]
    pub strapdown_check: bool,
    /// Strapdown sample rate of `--strapdown-check` (Hz).
    #[arg(long, default_value_t = 100.0)]
    pub strapdown_rate: f64,
}

pub fn run(args: RinsArgs) -> Result<()> {
    if !(args.gyro_arw.is_finite() && args.gyro_arw >= 0.0) {
        anyhow::bail!(
            "--gyro-arw must be a non-negative number (deg/sqrt(h)), got {}",
            args.gyro_arw
        );
    }
    let mut scenario = Scenario {
        seed: args.seed,
        hours: args.hours,
        failure_hour: args.failure_hour,
        filter_step: args.filter_step,
        speed: args.speed,
        ..Scenario::paper()
    };
    if args.strapdown_check {
        // the paper's 120 h default is far longer than the check needs
        let hours_given = args.hours != Scenario::paper().hours;
        let hours = if hours_given { args.hours } else { 4.0 };
        let check = strapdown_check(&scenario, hours, args.strapdown_rate)?;
        return if args.json {
            print_out(&(serde_json::to_string_pretty(&check.json())? + "\n"))
        } else {
            print_out(&check.text(&scenario))
        };
    }
    let arw = args.gyro_arw * mwd_core::conventions::DEG / 60.0;
    scenario.backup.gyro_arw = arw;
    scenario.master.gyro_arw = arw;
    let started = std::time::Instant::now();
    let results = rins::run(&scenario)?;
    let wall = started.elapsed().as_secs_f64();
    if let Some(dir) = &args.plot {
        host_sim::formats::figure::prepare_dir(dir)?;
        let files = rins::plot::write_figures(dir, &results, scenario.failure_hour)?;
        if !args.json {
            outln!("Figures 3-6: {} files in {}", files.len(), dir.display());
        }
    }
    if args.json {
        print_out(&(serde_json::to_string_pretty(&results)? + "\n"))
    } else {
        print_out(&report(&scenario, &results, wall))
    }
}
