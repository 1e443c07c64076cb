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

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

use anyhow::Context;
use host_sim::analysis::calibration_file::CalibrationFile;
use host_sim::formats::capture::{CaptureSummary, ProbeCaptureFile};
use host_sim::formats::display;
use host_sim::replay::commands::{decode_uplink_log, CommandRow};
use host_sim::replay::live::{self, LiveOptions, LiveSinks};
use host_sim::replay::{
    self, ReplayRow, ReplaySummary, Replayer, StationRow, StationSummary, StepLoss,
};
use host_sim::survey::job::Job;
use mwd_core::calibration::ProbeCalibration;
use mwd_core::config::default_still_settings;
use mwd_core::earth::Position;
use mwd_core::probe::TieIn;
use mwd_core::protocol::uplink::{Command as UplinkCommand, StillSettings};

use super::site::SiteArgs;

/// Exit statuses of `replay` (also in its `--help`).
mod status {
    /// Every probe solution compared was identical, none left unchecked (or
    /// the run was post-processed with another calibration or site).
    pub const PARITY: u8 = 0;
    /// Replayed solutions differ from the probe's.
    pub const DIFFERENT: u8 = 3;
    /// Everything compared was identical, but some probe solutions could
    /// not be compared (frames lost, the capture starts mid-run, the probe
    /// dropped samples, a command the replay cannot repeat).
    pub const INCOMPLETE: u8 = 4;
}

#[derive(clap::Args, Debug)]
#[command(
    after_help = "Exit status: 0 every probe solution compared was identical (or the \
replay was post-processed with --calibration-file or a site option: differences are then \
expected and reported, not a failure); 1 error (unreadable file, not a probe capture, bad \
argument); 2 bad command line; 3 replayed solutions or station surveys differ from the probe's; 4 all compared \
solutions identical but some could not be compared (frames lost: the replay stops comparing \
from the first sample after the loss and starts again at the probe's next boot event; or a \
command the replay cannot repeat: its place lost with frames, a re-align with new settings, \
a lost reply that shows as the probe's navigation mode differing from the replay's). A \
command the replay's navigator refuses though the probe acknowledged it, or a navigation \
mode that differs with no frame lost, is a difference (3)."
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

/// A replayed capture: where it came from, the capture, the replayed
/// solutions and their summary.
/// What a replay reports: the rows themselves went to `--csv` as they
/// settled, so a capture of any length keeps only this.
struct Replayed {
    source: String,
    capture: CaptureSummary,
    /// How many rows the replay made, and the newest.
    rows: usize,
    last_row: Option<ReplayRow>,
    summary: ReplaySummary,
    step_losses: Vec<StepLoss>,
    /// The replies to uplink commands and what the replay did with each.
    commands: Vec<CommandRow>,
    /// Live: the CSV was written while streaming.
    /// Replayed station surveys and their comparison; `None` for a live
    /// session (its stations are listed from the probe's frames only).
    stations: Option<(Vec<StationRow>, StationSummary)>,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let job = args.job.as_deref().map(Job::load).transpose()?;
    let site = match (args.site_numbers.as_deref(), &job) {
        (Some(&[lat, lon, height]), _) => super::site::checked_position(lat, lon, height)?,
        (_, Some(job)) => job.site,
        _ => args.site.position(),
    };
    let job_calibration = job.as_ref().and_then(|j| j.calibration.as_ref());
    let calibration = match (&args.calibration_file, job_calibration) {
        (Some(path), _) => CalibrationFile::load(path)?.to_probe(),
        (None, Some((_, calibration))) => *calibration,
        (None, None) => ProbeCalibration::default(),
    };
    // A configured probe's navigator uses the job's still settings after
    // its next boot or re-align (docs/protocol.md): so does the replay.
    let job_still = job.as_ref().and_then(|j| j.still);
    let still = job_still.unwrap_or_else(default_still_settings);
    let tie_in = job.as_ref().and_then(|j| j.tie_in);
    let replayed = match (&args.port, &args.file) {
        (Some(port), _) => replay_live(&args, port, site, calibration, still, tie_in)?,
        (None, Some(file)) => {
            let sent = match &args.uplink {
                Some(log) => {
                    let bytes = std::fs::read(log)
                        .with_context(|| format!("reading the uplink log {}", log.display()))?;
                    decode_uplink_log(&bytes)
                }
                None => Vec::new(),
            };
            let probe = ReplayedProbe {
                site,
                calibration,
                still,
                tie_in,
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
        || job_calibration.is_some()
        || still != default_still_settings()
        || site != Position::paper_site()
        || job.as_ref().is_some_and(|j| j.tie_in.is_some());
    report(&replayed, args.csv.as_ref(), post_processed)
}

/// The probe the replay stands for: its site, calibration, still settings
/// and tie-in.
struct ReplayedProbe {
    site: Position,
    calibration: ProbeCalibration,
    still: StillSettings,
    tie_in: Option<TieIn>,
}

/// Replays a capture file as it is read, writing `--csv` as the rows
/// settle.
fn replay_file(
    file: &Path,
    probe: ReplayedProbe,
    sent: &[(u16, UplinkCommand)],
    csv: Option<&Path>,
) -> anyhow::Result<Replayed> {
    let mut capture = ProbeCaptureFile::open(file)?;
    let mut out = csv.map(create).transpose()?;
    let csv_error = |e: std::io::Error| {
        let path = csv.map(|p| p.display().to_string()).unwrap_or_default();
        anyhow::Error::new(e).context(format!("writing {path}"))
    };
    if let Some(w) = out.as_mut() {
        writeln!(w, "{}", replay::CSV_HEADER).map_err(csv_error)?;
    }
    let mut replayer = Replayer::with_settings(probe.site, probe.calibration, probe.still)
        .with_tie_in(probe.tie_in);
    for (seq, command) in sent {
        replayer.knows_sent_command(*seq, command);
    }
    let mut summary = CaptureSummary::default();
    let mut items = 0usize;
    while let Some(item) = capture.next_item()? {
        summary.note(item.received());
        replayer.push_received(item.received());
        items += 1;
        if items % replay::FILE_BATCH_ITEMS == 0 {
            let sink = out.as_mut().map(|w| w as &mut dyn Write);
            replayer.write_settled(sink, false).map_err(csv_error)?;
        }
    }
    summary.stats = *capture.stats();
    let (station_rows, station_summary) = replayer.stations();
    let stations = Some((station_rows.to_vec(), station_summary));
    let sink = out.as_mut().map(|w| w as &mut dyn Write);
    replayer.write_settled(sink, true).map_err(csv_error)?;
    // The header alone (no raw frame) was never flushed with rows.
    if let Some(w) = out.as_mut() {
        w.flush().map_err(csv_error)?;
    }
    let step_losses = replayer.step_losses().to_vec();
    let commands = replayer.commands().to_vec();
    let rows = replayer.rows_replayed();
    let last_row = replayer.last_row().copied();
    let (_, replay_summary) = replayer.finish();
    Ok(Replayed {
        source: file.display().to_string(),
        capture: summary,
        rows,
        last_row,
        summary: replay_summary,
        step_losses,
        commands,
        stations,
    })
}

fn seconds(name: &str, value: f64) -> anyhow::Result<Duration> {
    anyhow::ensure!(
        value.is_finite() && value > 0.0 && value < 1e9,
        "--{name} must be a positive number of seconds below 1e9, not {value}"
    );
    Ok(Duration::from_secs_f64(value))
}

/// Creates an output file for a live session.
fn create(path: &Path) -> anyhow::Result<BufWriter<File>> {
    let file = File::create(path).with_context(|| format!("creating {}", path.display()))?;
    Ok(BufWriter::new(file))
}

/// Replays the live stream of a serial port until it ends (or
/// `--duration`, `--silence`, SIGINT/SIGTERM), with a status line a few
/// times a second, writing `--save` and `--csv` as it goes.
fn replay_live(
    args: &Args,
    port: &str,
    site: Position,
    calibration: ProbeCalibration,
    still: StillSettings,
    tie_in: Option<TieIn>,
) -> anyhow::Result<Replayed> {
    let duration = args.duration.map(|s| seconds("duration", s)).transpose()?;
    let silence = seconds("silence", args.silence)?;
    let mut save = args.save.as_deref().map(create).transpose()?;
    let mut csv = args.csv.as_deref().map(create).transpose()?;
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
        calibration,
        still,
        tie_in,
        ..LiveOptions::default()
    };
    let sinks = LiveSinks {
        save: save.as_mut().map(|w| w as &mut dyn Write),
        csv: csv.as_mut().map(|w| w as &mut dyn Write),
        stop: Some(&stop),
    };
    let outcome = live::run(serial, site, options, sinks, |status| outln!("{status}"));
    outln!("end of stream    {}", outcome.end);
    if let Some(path) = &args.save {
        outln!(
            "saved            {} ({} bytes)",
            path.display(),
            outcome.capture.stats.bytes
        );
    }
    if let live::StreamEnd::OutputFailed(e) = &outcome.end {
        anyhow::bail!("writing the live session's output: {e}");
    }
    Ok(Replayed {
        source: port.to_string(),
        capture: outcome.capture,
        rows: outcome.rows,
        last_row: outcome.last_row,
        summary: outcome.summary,
        step_losses: outcome.step_losses,
        commands: outcome.commands,
        stations: None,
    })
}

/// The summary both modes end with, the CSV, and the exit status.
fn report(
    replayed: &Replayed,
    csv: Option<&PathBuf>,
    post_processed: bool,
) -> anyhow::Result<ExitCode> {
    let Replayed {
        source,
        capture: cap,
        rows,
        last_row,
        summary,
        step_losses,
        commands,
        stations,
    } = replayed;
    outln!("capture          {source}");
    outln!("{cap}");
    outln!("raw frames       {}", summary.raw_frames);
    outln!("degraded samples {}", summary.degraded);
    outln!("probe solutions  {}", summary.probe_solutions);
    outln!(
        "probe restarts   {} (the replay restarted with it)",
        summary.restarts
    );
    outln!(
        "replay parity    {} identical, {} different, {} not compared",
        summary.matched,
        summary.mismatched,
        summary.unchecked
    );
    for command in commands {
        outln!("uplink           {command}");
    }
    for loss in step_losses {
        outln!("out of step      {loss}");
    }
    let mut stations_differ = 0;
    let mut stations_unchecked = 0;
    match stations {
        Some((rows, s)) => {
            outln!(
                "station parity   {} replayed, {} from the probe: {} identical, {} different, \
                 {} not compared",
                s.replayed,
                s.probe,
                s.matched,
                s.mismatched,
                s.unchecked
            );
            for row in rows {
                let parity = match (row.in_step, row.matches_probe) {
                    (false, _) => "not compared",
                    (true, Some(true)) => "identical to the probe's",
                    (true, Some(false)) => "DIFFERENT from the probe's",
                    (true, None) => "no probe frame",
                };
                outln!(
                    "replayed {} [{parity}]",
                    display::station_text(&row.station)
                );
            }
            stations_differ = s.mismatched;
            stations_unchecked = s.unchecked;
        }
        None => {
            outln!("station parity   not replayed live (the probe's stations are listed above)")
        }
    }
    if let Some(last) = last_row {
        let s = &last.solution;
        let [r, p, h] = s.attitude.map(f64::from);
        outln!(
            "last attitude    roll {:.3} pitch {:.3} deg, azimuth {}",
            r.to_degrees(),
            p.to_degrees(),
            display::azimuth_text(h, f64::from(s.attitude_std[2]), 2)
        );
    }
    if let Some(out) = csv {
        outln!("csv              {} ({rows} rows)", out.display());
    }
    if post_processed {
        if summary.mismatched > 0 || stations_differ > 0 {
            outln!(
                "post-processed   with another calibration or site than the probe's defaults: \
                 differences from the probe's solutions are expected, not a parity failure"
            );
        }
        return Ok(ExitCode::from(status::PARITY));
    }
    let differences = step_losses
        .iter()
        .filter(|l| l.reason.is_a_difference())
        .count();
    if summary.mismatched > 0 || stations_differ > 0 || differences > 0 {
        eprintln!(
            "error: {} replayed solutions and {stations_differ} station surveys differ from the \
             probe's; {differences} commands or navigation modes differ (see \"out of step\")",
            summary.mismatched
        );
        return Ok(ExitCode::from(status::DIFFERENT));
    }
    if stations_unchecked > 0 {
        eprintln!("warning: {stations_unchecked} probe station surveys could not be compared");
        return Ok(ExitCode::from(status::INCOMPLETE));
    }
    if summary.unchecked > 0 || !step_losses.is_empty() {
        eprintln!(
            "warning: {} probe solutions could not be compared (see \"out of step\")",
            summary.unchecked
        );
        return Ok(ExitCode::from(status::INCOMPLETE));
    }
    Ok(ExitCode::from(status::PARITY))
}
