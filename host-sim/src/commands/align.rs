//! `host-sim align`: coarse alignment of a recorded or simulated static file.
use anyhow::{bail, Context, Result};
use host_sim::alignment::coarse;
use host_sim::analysis::calibration_file::CalibrationFile;
use host_sim::analysis::csv_input::{capture_records, is_capture};
use host_sim::formats::samples_csv::{self, Record};
use host_sim::sim::{DeterministicErrors, SensorModel, SensorModelFile};
use mwd_core::alignment::AlignmentConfig;
use mwd_core::calibration::ProbeCalibration;
use mwd_core::conventions::DEG;
use mwd_core::sensor_noise::ImuNoise;
use mwd_core::timing::SAMPLE_INTERVAL_S;
use std::path::PathBuf;

use super::site::SiteArgs;

#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum CalibrationKind {
    /// The paper's Table 3 (what the default simulation's probe has).
    Paper,
    /// The deterministic errors of --sensor-model (a perfect calibration).
    Model,
    /// No correction (for ideal simulations or pre-corrected files).
    None,
}

#[derive(clap::Args, Debug)]
pub struct Args {
    /// Sample CSV (as written by `host-sim simulate`), or a probe capture
    /// (`.bin`, the probe's UART bytes: its raw-sample frames are read).
    pub file: PathBuf,
    /// The site (coarse alignment uses its latitude).
    #[command(flatten)]
    pub site: SiteArgs,
    /// Rough heading (degrees) to choose between ambiguous candidates, e.g.
    /// the parent well's survey.
    #[arg(long, allow_hyphen_values = true)]
    pub prior_heading: Option<f64>,
    /// Use only the first this many seconds (the paper aligns on 5 s).
    #[arg(long)]
    pub first: Option<f64>,
    /// Sensor calibration applied before aligning.
    #[arg(long, value_enum, default_value_t = CalibrationKind::Paper)]
    pub calibration: CalibrationKind,
    /// Calibration JSON (as `host-sim calibrate` writes); overrides
    /// --calibration.
    #[arg(long)]
    pub calibration_file: Option<PathBuf>,
    /// Sensor model JSON (as `simulate --print-sensor-model` writes): its
    /// error budget sets the uncertainties (default: the SCC1300's).
    #[arg(long)]
    pub sensor_model: Option<PathBuf>,
    /// Take the sensors as error-free when computing uncertainties.
    #[arg(long, default_value_t = false, conflicts_with = "sensor_model")]
    pub noise_free: bool,
}

pub fn run(args: Args) -> Result<()> {
    let records = read_records(&args)?;
    let model = match &args.sensor_model {
        Some(path) => Some(SensorModelFile::load(path, 0)?),
        None => None,
    };
    let cal = calibration(&args, model.as_ref())?;
    let noise = match (&model, args.noise_free) {
        (Some(m), _) => m.noise,
        (None, true) => ImuNoise::NONE,
        (None, false) => ImuNoise::scc1300(),
    };
    let records: Vec<_> = records
        .iter()
        .map(|r| coarse::calibrated(r, &cal))
        .collect();
    let config = AlignmentConfig {
        noise,
        ..AlignmentConfig::probe(args.site.position().lat)
    }
    .with_heading_prior(args.prior_heading.map(|h| h * DEG));
    let report = coarse::align_run(&records, &config)?;
    out!("{}", report.render());
    Ok(())
}

/// The file's samples, or its first `--first` seconds.
fn read_records(args: &Args) -> Result<Vec<Record>> {
    let mut records = if is_capture(&args.file) {
        capture_records(&args.file)?
    } else {
        let file = std::fs::File::open(&args.file)
            .with_context(|| format!("opening {}", args.file.display()))?;
        samples_csv::read(file).with_context(|| format!("reading {}", args.file.display()))?
    };
    if let Some(first) = args.first {
        let keep = (first / SAMPLE_INTERVAL_S).round() as usize;
        if keep == 0 {
            bail!("--first {first} keeps no sample");
        }
        records.truncate(keep);
    }
    Ok(records)
}

/// The correction applied before aligning: `--calibration-file`, else
/// `--calibration` (`model` needs the sensor model's errors).
fn calibration(args: &Args, model: Option<&SensorModel>) -> Result<ProbeCalibration> {
    if let Some(path) = &args.calibration_file {
        return Ok(CalibrationFile::load(path)?.to_probe());
    }
    Ok(match (args.calibration, model) {
        (CalibrationKind::Paper, _) => DeterministicErrors::paper_table3().calibration(),
        (CalibrationKind::None, _) => ProbeCalibration::default(),
        (CalibrationKind::Model, Some(m)) => m.deterministic.calibration(),
        (CalibrationKind::Model, None) => {
            bail!("--calibration model needs --sensor-model FILE")
        }
    })
}
