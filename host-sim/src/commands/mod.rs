//! The CLI: one module per subcommand, each with its clap `Args` and a `run`.
use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// `println!` for command output that a closed pipe (`| head -1`) does not
/// turn into a panic: see [`print_out`].
macro_rules! outln {
    () => { $crate::commands::print_line(format_args!("")) };
    ($($arg:tt)*) => { $crate::commands::print_line(format_args!($($arg)*)) };
}

/// `print!` through [`print_out`], as [`outln!`].
macro_rules! out {
    ($($arg:tt)*) => { $crate::commands::print_text(format_args!($($arg)*)) };
}

mod align;
mod allan;
mod arfit;
mod calibrate;
#[cfg(feature = "dashboard")]
mod dashboard;
mod decode;
mod demo;
mod limits;
mod observability;
mod paper;
mod paper_mgwd;
mod paper_rins;
mod probe;
mod replay;
mod simulate;
mod site;
mod study;
mod study_lateral;
mod survey;
mod survey_capture;

#[derive(Parser, Debug)]
#[command(name = "host-sim", version, about = "Host tool of the gyro MWD probe")]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Simulate the paper's 60 s static test (and 2 x 10 min of toolface
    /// indexing) and print the coarse alignment next to the truth.
    Demo(demo::Args),
    /// Simulate a trajectory and the probe's sensors; write the samples.
    Simulate(simulate::Args),
    /// Decode a capture of the probe's UART frames: summary and CSV export.
    Decode(decode::Args),
    /// Replay a capture's raw frames through the probe's navigation (CSV out).
    Replay(replay::Args),
    /// Coarse alignment of a recorded or simulated static file.
    Align(align::Args),
    /// Overlapping Allan deviation of a static record, with noise coefficients.
    Allan(allan::Args),
    /// Autocorrelation and AR(p) fits (Yule-Walker, Burg, covariance method).
    Arfit(arfit::Args),
    /// Six-position calibration of accelerometer triads and gyro biases (LS and TLS).
    Calibrate(calibrate::Args),
    /// What ZUPT and zero-position updates can determine at rest, per state
    /// (one toolface or toolface indexing).
    Observability(observability::Args),
    /// Survey stations (CSV): positions by minimum curvature, ISCWSA
    /// uncertainty and error ellipses; listing, CSV, JSON, WITSML exports.
    Survey(survey::Args),
    /// Monte Carlo studies over simulated runs.
    #[command(subcommand)]
    Study(study::StudyCommand),
    /// Commands to a live probe over its serial port: configure (a job
    /// file), status, align, station, index, reboot.
    Probe(probe::Args),
    /// The probe's live display as a local web page (a serial port, or a
    /// capture replayed at a chosen pace).
    #[cfg(feature = "dashboard")]
    Dashboard(dashboard::Args),
    /// Reproductions of the papers' experiments.
    #[command(subcommand)]
    Paper(paper::PaperCommand),
}

/// Prints to stdout; a closed pipe (`| head`) ends the output quietly: the
/// command goes on (files it writes are still written, its exit status
/// still tells), only what nobody reads is dropped.
fn print_out(text: &str) -> anyhow::Result<()> {
    use std::io::Write;
    let mut stdout = std::io::stdout().lock();
    match stdout
        .write_all(text.as_bytes())
        .and_then(|()| stdout.flush())
    {
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        other => Ok(other?),
    }
}

/// What [`outln!`] calls: one line through [`print_out`]. Another write
/// error than a closed pipe (a full disk behind a redirection) is said on
/// stderr rather than panicking as `println!` would.
pub fn print_line(args: std::fmt::Arguments<'_>) {
    print_text(format_args!("{args}\n"));
}

/// What [`out!`] calls.
pub fn print_text(args: std::fmt::Arguments<'_>) {
    if let Err(e) = print_out(&args.to_string()) {
        eprintln!("error: writing to standard output: {e:#}");
    }
}

/// Writes `value` as pretty JSON (with a final newline) to `path`, the
/// path named in the error: the studies' `--json` outputs.
fn write_json(path: &std::path::Path, value: &impl serde::Serialize) -> anyhow::Result<()> {
    use anyhow::Context;
    let text = serde_json::to_string_pretty(value)? + "\n";
    std::fs::write(path, text).with_context(|| format!("writing {}", path.display()))
}

/// A flag the first Ctrl-C (or SIGTERM) sets: a study then finishes the
/// runs under way and writes what it has. A second one quits at once. The
/// note goes above `bar` when it is drawn (one bar for the whole study),
/// else to standard error.
fn stop_on_ctrl_c(
    bar: Option<&indicatif::ProgressBar>,
) -> anyhow::Result<std::sync::Arc<std::sync::atomic::AtomicBool>> {
    use anyhow::Context;
    use std::sync::atomic::{AtomicBool, Ordering};
    use std::sync::Arc;
    let stop = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&stop);
    let bar = bar.filter(|b| !b.is_hidden()).cloned();
    ctrlc::set_handler(move || {
        if flag.swap(true, Ordering::Relaxed) {
            std::process::exit(130);
        }
        let note = "interrupted: finishing the runs under way, then writing the results so \
                    far (Ctrl-C again to quit at once, writing nothing)";
        // A bar that is not drawn (no terminal) prints nothing either.
        match &bar {
            Some(bar) => bar.println(note),
            None => eprintln!("{note}"),
        }
    })
    .context("installing the SIGINT/SIGTERM handler")?;
    Ok(stop)
}

/// Runs a command; its exit status (only `replay` has others than 0: see
/// its `--help`).
pub fn run(cli: Cli) -> anyhow::Result<ExitCode> {
    let done = |result: anyhow::Result<()>| result.map(|()| ExitCode::SUCCESS);
    match cli.command {
        Command::Demo(args) => done(demo::run(args)),
        Command::Simulate(args) => done(simulate::run(args)),
        Command::Decode(args) => done(decode::run(args)),
        Command::Replay(args) => replay::run(args),
        Command::Align(args) => done(align::run(args)),
        Command::Allan(args) => done(allan::run(args)),
        Command::Arfit(args) => done(arfit::run(args)),
        Command::Calibrate(args) => done(calibrate::run(args)),
        Command::Observability(args) => done(observability::run(args)),
        Command::Survey(args) => done(survey::run(args)),
        Command::Study(cmd) => done(study::run(cmd)),
        Command::Probe(args) => done(probe::run(args)),
        #[cfg(feature = "dashboard")]
        Command::Dashboard(args) => done(dashboard::run(args)),
        Command::Paper(cmd) => done(paper::run(cmd)),
    }
}
