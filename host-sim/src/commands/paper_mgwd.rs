//! `host-sim paper mgwd`: the MGWD paper's fine-alignment experiment
//! (section 4, Figures 13-15) reproduced, ours beside the paper's figures.
//! The experiment is `host_sim::paper::mgwd`'s and its report
//! `host_sim::paper::mgwd_report`'s; this module reads the options and
//! prints.

use anyhow::Result;
use host_sim::paper::mgwd::{consistency, ranks, static_test};
use host_sim::paper::mgwd_report::{
    consistency_text, filter_model, ranks_text, static_test_text, write_figures, WHY,
};
use mwd_core::error_model::Coupling;
use std::path::PathBuf;

#[derive(clap::Args, Debug)]
pub struct MgwdArgs {
    /// Seed of the run shown and plotted.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Seeded runs behind the 3-sigma consistency check.
    #[arg(long, default_value_t = 100)]
    pub runs: usize,
    /// Write the SVG plots of Figures 13-15 into this directory (none
    /// unless asked).
    #[arg(long, value_name = "DIR")]
    pub plots: Option<PathBuf>,
    /// AR(4) noise models fitted at 20 Hz by `host-sim arfit` (its
    /// `.ar.json`): they replace the paper's Tables 4-5 in every filter
    /// setting and in the consistency runs. Sensors map by name onto the
    /// filter's axes: accel_x/y/z, gyro_x/y/z (optionally `_<unit>`).
    #[arg(long, value_name = "FILE")]
    pub ar_models: Option<PathBuf>,
    /// With --ar-models: keep the paper's Table 5 model for the
    /// accelerometer-derived tool-axis rate (gyro y). The probe has no
    /// tool-axis gyro, so a fit of its files has no such sensor.
    #[arg(long, requires = "ar_models")]
    pub paper_derived_rate: bool,
}

pub fn run(args: MgwdArgs) -> Result<()> {
    let (model, loaded) = filter_model(args.ar_models.as_deref(), args.paper_derived_rate)?;
    let test = static_test(args.seed, &model)?;
    out!(
        "{}",
        static_test_text(args.seed, &test, &model, loaded.as_ref())
    );
    out!(
        "{}",
        ranks_text(&[
            ranks(Coupling::BlockDiagonalAsPublished),
            ranks(Coupling::SensorErrorsDriveNavigation),
        ])
    );
    let lines = consistency(args.runs, &model)?;
    out!("{}", consistency_text(args.runs, &lines, loaded.is_some()));
    outln!("{WHY}");
    if let Some(dir) = &args.plots {
        write_figures(dir, &test.runs)?;
        outln!(
            "Plots of Figures 13-15 for each setting in {}",
            dir.display()
        );
    }
    Ok(())
}
