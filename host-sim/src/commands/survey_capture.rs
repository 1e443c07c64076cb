//! `host-sim survey CAPTURE.bin --depth DEPTH.csv`: the probe's station
//! surveys of a drilling capture, paired with MD from the surface depth
//! log, listed with their position uncertainty; `--trajectory OUT.csv`: the
//! continuous trajectory from the 20 Hz solutions. docs/drilling-survey.md.
//! The survey is `host_sim::survey::capture`'s; `survey` checks the
//! options and gives the inputs.

use super::limits::number_in;
use anyhow::Result;
use host_sim::formats::files::write_text;
use host_sim::survey::capture::{trajectory_csv, CaptureSurvey, CaptureSurveyInputs};
use std::path::{Path, PathBuf};

fn step_m(text: &str) -> Result<f64, String> {
    let v = number_in(text, "the trajectory step", (0.0, 1000.0), "m")?;
    if v == 0.0 {
        return Err("the trajectory step must be above 0 m".into());
    }
    Ok(v)
}

/// Options of a capture survey.
#[derive(clap::Args, Debug)]
pub struct CaptureArgs {
    /// The surface depth log (CSV: time_s, md_m): the input is then a probe
    /// capture (.bin), and its station surveys are listed.
    #[arg(long, value_name = "DEPTH.csv")]
    pub depth: Option<PathBuf>,
    /// With --depth: write the continuous trajectory (20 Hz attitude and
    /// the depth log by minimum curvature) here (CSV).
    #[arg(long, value_name = "OUT.csv", requires = "depth")]
    pub trajectory: Option<PathBuf>,
    /// MD step of the trajectory, m.
    #[arg(long, default_value_t = 1.0, value_parser = step_m, requires = "trajectory")]
    pub trajectory_step_m: f64,
}

/// Surveys the capture, prints the listing and writes `csv` (one row per
/// station) and `--trajectory`.
pub fn run(
    args: &CaptureArgs,
    inputs: &CaptureSurveyInputs,
    csv: Option<&Path>,
    confidence: f64,
) -> Result<()> {
    let survey = CaptureSurvey::run(inputs)?;
    out!("{}", survey.report(confidence));
    if let Some(path) = csv {
        write_text(path, &survey.stations_csv(confidence))?;
    }
    if let Some(path) = &args.trajectory {
        let points = survey.trajectory(args.trajectory_step_m)?;
        write_text(path, &trajectory_csv(&points, confidence))?;
        outln!("wrote {} ({} points)", path.display(), points.len());
    }
    Ok(())
}
