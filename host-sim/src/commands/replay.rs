//! `host-sim replay FILE [--csv OUT]` or `host-sim replay --port PATH
//! [--baud 115200] [--duration S] [--csv OUT]`: runs the probe's navigation
//! on the raw frames of a capture (for example QEMU's `-serial file:`
//! output) or of a live stream from a serial port (a real probe, or QEMU's
//! `-serial pty`), and checks the replayed solutions against the probe's
//! own navigation frames. Live mode shows a running status line and, when
//! the stream ends, prints the same summary as a file replay.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::time::Duration;

use anyhow::Context;
use host_sim::analysis::calibration_file::CalibrationFile;
use host_sim::capture::Capture;
use host_sim::live::{self, LiveOptions};
use host_sim::replay::{self, ReplayRow, ReplaySummary};
use mwd_core::calibration::ProbeCalibration;
use mwd_core::earth::Position;
use mwd_core::probe::Navigator;

use super::site::SiteArgs;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// Capture of the probe's UART bytes (`.bin`).
    #[arg(required_unless_present = "port", conflicts_with = "port")]
    pub file: Option<PathBuf>,
    /// Read a live stream from this serial port instead (e.g. /dev/ttyUSB0,
    /// or the /dev/pts/N QEMU prints for `-serial pty`).
    #[arg(long, value_name = "PATH")]
    pub port: Option<String>,
    /// Baud rate of the serial port (the probe sends at 115200).
    #[arg(long, default_value_t = 115_200, requires = "port")]
    pub baud: u32,
    /// Stop a live replay after this many seconds (default: until the
    /// stream ends).
    #[arg(long, value_name = "SECONDS", requires = "port")]
    pub duration: Option<f64>,
    /// Write the replayed navigation solutions as CSV here.
    #[arg(long, value_name = "OUT")]
    pub csv: Option<PathBuf>,
    /// The probe's site (the QEMU probe's is the MGWD paper's).
    #[command(flatten)]
    pub site: SiteArgs,
    /// The probe's site as three numbers, the same as --lat --lon --height.
    #[arg(long = "site", num_args = 3, value_names = ["LAT", "LON", "HEIGHT"],
          allow_negative_numbers = true, conflicts_with_all = ["lat", "lon", "height"])]
    pub site_numbers: Option<Vec<f64>>,
    /// The probe's sensor calibration (`host-sim calibrate`'s JSON): the
    /// replay applies it as the probe does. Default: none (the QEMU probe
    /// runs uncalibrated).
    #[arg(long, value_name = "PATH")]
    pub calibration_file: Option<PathBuf>,
}

/// A replayed capture: where it came from, the capture, the replayed
/// solutions and their summary.
struct Replayed {
    source: String,
    capture: Capture,
    rows: Vec<ReplayRow>,
    summary: ReplaySummary,
}

pub fn run(args: Args) -> anyhow::Result<()> {
    let site = match args.site_numbers.as_deref() {
        Some(&[lat, lon, height]) => super::site::checked_position(lat, lon, height)?,
        _ => args.site.position(),
    };
    let calibration = match &args.calibration_file {
        Some(path) => CalibrationFile::load(path)?.to_probe(),
        None => ProbeCalibration::default(),
    };
    let replayed = match (&args.port, &args.file) {
        (Some(port), _) => replay_live(&args, port, site, calibration)?,
        (None, Some(file)) => replay_file(file, site, calibration)?,
        (None, None) => anyhow::bail!("give a capture file or --port"),
    };
    report(&replayed, args.csv.as_ref())
}

/// Replays a capture file.
fn replay_file(
    file: &Path,
    site: Position,
    calibration: ProbeCalibration,
) -> anyhow::Result<Replayed> {
    let capture = host_sim::capture::read_capture(file)
        .with_context(|| format!("reading {}", file.display()))?;
    let navigator = Navigator::with_calibration(site, calibration);
    let (rows, summary) = replay::replay_with(&capture.frames, navigator);
    Ok(Replayed {
        source: file.display().to_string(),
        capture,
        rows,
        summary,
    })
}

/// Replays the live stream of a serial port until it ends (or
/// `--duration`), with a status line a few times a second.
fn replay_live(
    args: &Args,
    port: &str,
    site: Position,
    calibration: ProbeCalibration,
) -> anyhow::Result<Replayed> {
    let duration = match args.duration {
        Some(s) if s.is_finite() && s > 0.0 => Some(Duration::from_secs_f64(s)),
        Some(s) => anyhow::bail!("--duration must be a positive number of seconds, not {s}"),
        None => None,
    };
    // A short timeout keeps the time limit responsive on a quiet line.
    let serial = serialport::new(port, args.baud)
        .timeout(Duration::from_millis(100))
        .open()
        .with_context(|| format!("opening serial port {port}"))?;
    // Tools driving this (tests, scripts) wait for this line before
    // letting the probe run.
    println!("listening on {port} at {} baud", args.baud);
    std::io::stdout().flush()?;
    let options = LiveOptions {
        duration,
        calibration,
        ..LiveOptions::default()
    };
    let outcome = live::run(serial, site, options, |status| println!("{status}"));
    println!("end of stream    {}", outcome.end);
    Ok(Replayed {
        source: port.to_string(),
        capture: outcome.capture,
        rows: outcome.rows,
        summary: outcome.summary,
    })
}

/// The summary both modes end with, and the CSV.
fn report(replayed: &Replayed, csv: Option<&PathBuf>) -> anyhow::Result<()> {
    let Replayed {
        source,
        capture: cap,
        rows,
        summary,
    } = replayed;
    println!("capture          {source}");
    println!("{cap}");
    println!("raw frames       {}", summary.raw_frames);
    println!("degraded samples {}", summary.degraded);
    println!("probe solutions  {}", summary.probe_solutions);
    println!(
        "replay parity    {} identical, {} different",
        summary.matched, summary.mismatched
    );
    if let Some(last) = rows.last() {
        let [r, p, h] = last.solution.attitude.map(|a| f64::from(a).to_degrees());
        let h_std = f64::from(last.solution.attitude_std[2]).to_degrees();
        println!(
            "last attitude    roll {r:.3} pitch {p:.3} heading {h:.2} (+/- {h_std:.2} deg 1-sigma)"
        );
    }
    if let Some(out) = csv {
        let file = File::create(out).with_context(|| format!("creating {}", out.display()))?;
        replay::write_csv(rows, BufWriter::new(file))
            .with_context(|| format!("writing {}", out.display()))?;
        println!("csv              {} ({} rows)", out.display(), rows.len());
    }
    if summary.mismatched > 0 {
        anyhow::bail!(
            "{} replayed solutions differ from the probe's",
            summary.mismatched
        );
    }
    Ok(())
}
