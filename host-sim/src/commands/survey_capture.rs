//! `host-sim survey CAPTURE.bin --depth DEPTH.csv`: the probe's station
//! surveys of a drilling capture, paired with MD from the surface depth
//! log, listed with their position uncertainty; `--trajectory OUT.csv`: the
//! continuous trajectory from the 20 Hz solutions. docs/drilling-survey.md.
//! The survey is `host_sim::survey::capture`'s; `survey` checks the
//! options and gives the inputs. The JSON, WITSML, figures and an offset
//! well's separation are written by the station-file survey's writers
//! (`host_sim::survey::outputs`).

use super::limits::number_in;
use anyhow::Result;
use host_sim::formats::files::OutputSet;
use host_sim::survey::capture::{trajectory_csv, CaptureSurvey, CaptureSurveyInputs};
use host_sim::survey::job::WellNames;
use host_sim::survey::listing::drilling::DEPTH_GAP_LIMIT_S;
use host_sim::survey::outputs::{stage_outputs, OutputPaths};
use host_sim::survey::well_survey::{OffsetInputs, SiteFor};
use std::path::PathBuf;
use std::process::ExitCode;

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
    /// With --depth: a station whose MD the depth log interpolates across
    /// a longer interval between its rows, s, is flagged "depth
    /// interpolated across a gap".
    #[arg(long, value_name = "S", default_value_t = DEPTH_GAP_LIMIT_S, value_parser = gap_s, requires = "depth")]
    pub depth_gap_limit: f64,
}

fn gap_s(text: &str) -> Result<f64, String> {
    number_in(text, "the depth-log gap limit", (0.0, 86_400.0), "s")
}

/// What a capture survey writes besides the listing.
pub struct CaptureOutputs<'a> {
    /// The CSV is the capture's own (toolface, time, each angle's sigma);
    /// the rest go through the station-file survey's writers.
    pub paths: OutputPaths<'a>,
    pub confidence: f64,
    /// Vertical-section azimuth, rad (`None`: the closure).
    pub vsec_azimuth: Option<f64>,
    pub offset: Option<OffsetInputs<'a>>,
    /// The well's names and uids (the WITSML trajectory's).
    pub well: &'a WellNames,
}

/// Surveys the capture, prints the listing and writes the outputs asked
/// for and `--trajectory`; incomplete (exit 2) when frames or stations
/// were lost, with their count on standard error.
pub fn run(
    args: &CaptureArgs,
    inputs: &CaptureSurveyInputs,
    outputs: &CaptureOutputs,
    site_for: SiteFor,
) -> Result<ExitCode> {
    let confidence = outputs.confidence;
    let survey = CaptureSurvey::run(inputs)?;
    let mut exported = survey.well_survey(confidence, outputs.vsec_azimuth)?;
    exported.well = outputs.well.clone();
    if let Some(offset) = &outputs.offset {
        exported.add_offset(offset, site_for)?;
    }
    out!("{}", survey.report(confidence));
    for line in exported.separation_summary() {
        outln!("{line}");
    }
    // Every output or none: staged, named together at the end.
    let mut set = OutputSet::default();
    if let Some(path) = outputs.paths.csv {
        set.stage(path, &survey.stations_csv(confidence))?;
    }
    let others = OutputPaths {
        csv: None,
        ..outputs.paths
    };
    let well = inputs
        .capture
        .file_stem()
        .map_or_else(|| "capture".into(), |n| n.to_string_lossy());
    let figures = stage_outputs(&mut set, &exported, &others, &well)?;
    let trajectory = match &args.trajectory {
        Some(path) => {
            let points = survey.trajectory(args.trajectory_step_m)?;
            set.stage(path, &trajectory_csv(&points, confidence))?;
            Some((path, points.len()))
        }
        None => None,
    };
    set.commit()?;
    for f in figures {
        outln!("wrote {}", f.display());
    }
    if let Some((path, points)) = trajectory {
        outln!("wrote {} ({points} points)", path.display());
    }
    Ok(super::status::complete_unless(survey.incomplete()))
}
