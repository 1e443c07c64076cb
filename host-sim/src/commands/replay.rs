//! `host-sim replay FILE [--csv OUT]` or `host-sim replay --port PATH
//! [--baud 115200] [--duration S] [--csv OUT]`: runs the probe's navigation
//! on the raw frames of a capture (for example QEMU's `-serial file:`
//! output) or of a live stream from a serial port (a real probe, or QEMU's
//! `-serial pty`), and checks the replayed solutions against the probe's
//! own navigation frames. Live mode shows a running status line and, when
//! the stream ends, prints the same summary as a file replay. The probe's
//! replies to uplink commands in the capture are carried out at the
//! probe's sample (`host_sim::replay::commands`); `--uplink LOG` gives what
//! the replies do not carry (toolface indexing's parameters).

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

use anyhow::Context;
use host_sim::analysis::calibration_file::CalibrationFile;
use host_sim::formats::files::create_buffered;
use host_sim::replay::commands::decode_uplink_log;
use host_sim::replay::file_replay::{replay_file, ReplayedProbe};
use host_sim::replay::live::{self, LiveOptions, LiveSinks};
use host_sim::replay::report::{Replayed, Verdict};
use host_sim::survey::job::Job;
use mwd_core::calibration::ProbeCalibration;
use mwd_core::config::default_still_settings;
use mwd_core::earth::Position;

use super::site::SiteArgs;
use super::status;

#[derive(clap::Args, Debug)]
#[command(
    after_help = "Exit status: 0 every probe solution and station compared was identical, \
nothing left unchecked (or the replay was post-processed with --calibration-file, a site \
option or a job's tie-in: differences are then expected and reported, not a failure); 1 error \
(bad argument, unreadable file, not a probe capture, an output that could not be written); 2 \
written but incomplete: all compared identical, but frames were lost (each one counted as not \
compared, post-processed or not) or some solutions or stations could not be compared (the \
replay stops comparing from the first sample after a loss and starts again at the probe's next \
boot event; or a command the replay cannot repeat: its place lost with frames, a re-align with \
new settings, a lost reply that shows as the probe's navigation mode differing from the \
replay's); 3 replayed solutions or station surveys differ from the probe's. A command the \
replay's navigator refuses though the probe acknowledged it, or a navigation mode that differs \
with no frame lost, is a difference (3)."
)]
pub struct Args {
    /// Capture of the probe's UART bytes (`.bin`).
    #[arg(required_unless_present = "port", conflicts_with = "port")]
    pub file: Option<PathBuf>,
    /// Read a live stream from this serial port instead (e.g. /dev/ttyUSB0,
    /// or the /dev/pts/N QEMU prints for `-serial pty`). Ends at end of
    /// stream, --duration, --silence, or Ctrl-C / SIGTERM, each with the
    /// summary.
    #[arg(long, value_name = "PATH")]
    pub port: Option<String>,
    /// Baud rate of the serial port (the probe sends at 115200).
    #[arg(long, default_value_t = 115_200, requires = "port")]
    pub baud: u32,
    /// Stop a live replay after this many seconds (default: until the
    /// stream ends).
    #[arg(long, value_name = "SECONDS", requires = "port")]
    pub duration: Option<f64>,
    /// End a live replay when no byte came for this many seconds (counted
    /// from the first byte).
    #[arg(
        long,
        value_name = "SECONDS",
        default_value_t = 10.0,
        requires = "port"
    )]
    pub silence: f64,
    /// Live: record the port's raw bytes here as they arrive (a capture
    /// `decode` and `replay` read).
    #[arg(long, value_name = "FILE", requires = "port")]
    pub save: Option<PathBuf>,
    /// Write the replayed navigation solutions as CSV here (live: each row
    /// as soon as its comparison is settled).
    #[arg(long, value_name = "OUT")]
    pub csv: Option<PathBuf>,
    /// The probe's site (the QEMU probe's is the MGWD paper's).
    #[command(flatten)]
    pub site: SiteArgs,
    /// The probe's site as three numbers, the same as --lat --lon --height.
    #[arg(long = "site", num_args = 3, value_names = ["LAT", "LON", "HEIGHT"],
          allow_negative_numbers = true, conflicts_with_all = ["lat", "lon", "height"])]
    pub site_numbers: Option<Vec<f64>>,
    /// A sensor calibration (`host-sim calibrate`'s JSON) the replay
    /// applies as the probe does. Default: none (the QEMU probe runs
    /// uncalibrated).
    #[arg(long, value_name = "PATH")]
    pub calibration_file: Option<PathBuf>,
    /// A job file (host-sim/src/job.rs): its site, calibration, still
    /// settings and tie-in, as `probe configure` sent them; --site and
    /// --calibration-file override it (its site: with --site, not
    /// --lat/--lon/--height). The tie-in is taken where the probe takes
    /// it, after its first navigating cycle.
    #[arg(long, value_name = "JOB.json", conflicts_with_all = ["lat", "lon", "height"])]
    pub job: Option<PathBuf>,
    /// The bytes the host sent the probe during the capture (its uplink
    /// commands): what the probe's replies do not carry, toolface
    /// indexing's parameters, so that its dwell stations are compared too.
    #[arg(long, value_name = "LOG", conflicts_with = "port")]
    pub uplink: Option<PathBuf>,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let job = args.job.as_deref().map(Job::load).transpose()?;
    let probe = replayed_probe(&args, job.as_ref())?;
    let replayed = match (&args.port, &args.file) {
        (Some(port), _) => replay_live(&args, port, probe)?,
        (None, Some(file)) => {
            let sent = match &args.uplink {
                Some(log) => {
                    let bytes = std::fs::read(log)
                        .with_context(|| format!("reading the uplink log {}", log.display()))?;
                    decode_uplink_log(&bytes)
                }
                None => Vec::new(),
            };
            replay_file(file, probe, &sent, args.csv.as_deref())?
        }
        (None, None) => anyhow::bail!("give a capture file or --port"),
    };
    // Another calibration or site than the QEMU probe's (none, the
    // paper's site; the site defaults are the paper's to the bit) is
    // post-processing, not a parity check.
    // A job's tie-in, as its calibration: this capture's probe may not
    // have had it.
    // Still settings other than the defaults: as another calibration.
    let post_processed = args.calibration_file.is_some()
        || job.as_ref().is_some_and(|j| j.calibration.is_some())
        || probe.still != default_still_settings()
        || probe.site != Position::paper_site()
        || job.as_ref().is_some_and(|j| j.tie_in.is_some());
    let report = replayed.report(args.csv.as_deref(), post_processed);
    out!("{}", report.text);
    let (prefix, status) = match report.verdict {
        Verdict::Parity => ("", status::COMPLETE),
        Verdict::Different => ("error: ", status::DIFFERENT),
        Verdict::Incomplete => ("warning: ", status::INCOMPLETE),
    };
    if let Some(note) = report.note {
        eprintln!("{prefix}{note}");
    }
    Ok(ExitCode::from(status))
}

/// The probe the replay stands for: `--site` or the job's site (else
/// `--lat`, `--lon`, `--height`), `--calibration-file` or the job's
/// calibration; the job's still settings and tie-in.
fn replayed_probe(args: &Args, job: Option<&Job>) -> anyhow::Result<ReplayedProbe> {
    let site = match (args.site_numbers.as_deref(), job) {
        (Some(&[lat, lon, height]), _) => super::site::checked_position(lat, lon, height)?,
        (_, Some(job)) => job.site,
        _ => args.site.position(),
    };
    let job_calibration = job.and_then(|j| j.calibration.as_ref());
    let calibration = match (&args.calibration_file, job_calibration) {
        (Some(path), _) => CalibrationFile::load(path)?.to_probe(),
        (None, Some((_, calibration))) => *calibration,
        (None, None) => ProbeCalibration::default(),
    };
    // A configured probe's navigator uses the job's still settings after
    // its next boot or re-align (docs/protocol.md): so does the replay.
    let still = job
        .and_then(|j| j.still)
        .unwrap_or_else(default_still_settings);
    Ok(ReplayedProbe {
        site,
        calibration,
        still,
        tie_in: job.and_then(|j| j.tie_in),
    })
}

fn seconds(name: &str, value: f64) -> anyhow::Result<Duration> {
    anyhow::ensure!(
        value.is_finite() && value > 0.0 && value < 1e9,
        "--{name} must be a positive number of seconds below 1e9, not {value}"
    );
    Ok(Duration::from_secs_f64(value))
}

/// Replays the live stream of a serial port until it ends (or
/// `--duration`, `--silence`, SIGINT/SIGTERM), with a status line a few
/// times a second, writing `--save` and `--csv` as it goes.
fn replay_live(args: &Args, port: &str, probe: ReplayedProbe) -> anyhow::Result<Replayed> {
    let duration = args.duration.map(|s| seconds("duration", s)).transpose()?;
    let silence = seconds("silence", args.silence)?;
    let mut save = args.save.as_deref().map(create_buffered).transpose()?;
    let mut csv = args.csv.as_deref().map(create_buffered).transpose()?;
    // Ctrl-C or SIGTERM ends the session like the end of the stream.
    let stop = Arc::new(AtomicBool::new(false));
    let handler_stop = Arc::clone(&stop);
    ctrlc::set_handler(move || handler_stop.store(true, Ordering::Relaxed))
        .context("installing the SIGINT/SIGTERM handler")?;
    // A short timeout keeps the limits and the stop flag responsive.
    let serial = serialport::new(port, args.baud)
        .timeout(Duration::from_millis(100))
        .open()
        .with_context(|| format!("opening serial port {port}"))?;
    // Tools driving this (tests, scripts) wait for this line before
    // letting the probe run.
    outln!("listening on {port} at {} baud", args.baud);
    let options = LiveOptions {
        duration,
        silence: Some(silence),
        calibration: probe.calibration,
        still: probe.still,
        tie_in: probe.tie_in,
        ..LiveOptions::default()
    };
    let sinks = LiveSinks {
        save: save.as_mut().map(|w| w as &mut dyn Write),
        csv: csv.as_mut().map(|w| w as &mut dyn Write),
        stop: Some(&stop),
    };
    let mut outcome = live::run(serial, probe.site, options, sinks, |status| {
        outln!("{status}")
    });
    outln!("end of stream    {}", outcome.end);
    if let live::StreamEnd::OutputFailed(e) = &outcome.end {
        anyhow::bail!("writing the live session's output: {e}");
    }
    // Named only now (`OutputFile`): a session that failed leaves none.
    for file in [save, csv].into_iter().flatten() {
        file.finish()?;
    }
    if let Some(path) = &args.save {
        let bytes = outcome.replayed.capture.stats.bytes;
        outln!("saved            {} ({bytes} bytes)", path.display());
    }
    outcome.replayed.source = port.to_string();
    Ok(outcome.replayed)
}
