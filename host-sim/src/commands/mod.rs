//! The CLI: one module per subcommand, each with its clap `Args` and a
//! `run` that checks the arguments, calls the library (`host_sim`) and
//! prints; the computing, the tables and the files are the library's.
//! Leaves the commands share: [`output`] (`outln!`, `out!`: standard
//! output that a closed pipe does not turn into a panic), [`limits`] and
//! [`site`] (the numbers checked when parsed), [`runs`] (the studies'
//! threads, progress bar and Ctrl-C).
use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};
use std::process::ExitCode;

#[macro_use]
pub(crate) mod output;

mod align;
mod allan;
mod arfit;
mod calibrate;
#[cfg(feature = "dashboard")]
mod dashboard;
mod decode;
mod demo;
mod drill;
mod limits;
mod observability;
mod paper;
mod paper_mgwd;
mod paper_rins;
mod probe;
mod replay;
mod runs;
mod simulate;
mod site;
pub(crate) mod status;
mod study;
mod study_coverage;
mod study_grade_table;
mod study_indexing;
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
    /// A survey while drilling on a simulated run, end to end: drill the
    /// job's plan, survey the probe's capture (positions, ellipses, the
    /// bit) and check it against the simulation's truth.
    Drill(drill::Args),
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

/// The command line read from the arguments; every command's `--help`
/// ends with its exit statuses ([`status`]), the general ones where the
/// command does not say its own.
pub fn parse() -> Result<Cli, clap::Error> {
    let command = with_exit_status(Cli::command()).after_help(status::HELP_ALL);
    Cli::from_arg_matches(&command.try_get_matches()?)
}

fn with_exit_status(command: clap::Command) -> clap::Command {
    let command = if command.get_after_help().is_none() && !command.has_subcommands() {
        let help = match command.get_name() {
            "survey" => status::HELP_SURVEY,
            "decode" => status::HELP_DECODE,
            _ => status::HELP_COMPLETE_OR_ERROR,
        };
        command.after_help(help)
    } else {
        command
    };
    command.mut_subcommands(with_exit_status)
}

/// Runs a command; its exit status ([`status`]: `replay` and `survey`
/// have others than 0 and 1, see their `--help`).
pub fn run(cli: Cli) -> anyhow::Result<ExitCode> {
    let done = |result: anyhow::Result<()>| result.map(|()| ExitCode::SUCCESS);
    match cli.command {
        Command::Drill(args) => done(drill::run(args)),
        Command::Demo(args) => done(demo::run(args)),
        Command::Simulate(args) => done(simulate::run(args)),
        Command::Decode(args) => decode::run(args),
        Command::Replay(args) => replay::run(args),
        Command::Align(args) => done(align::run(args)),
        Command::Allan(args) => done(allan::run(args)),
        Command::Arfit(args) => done(arfit::run(args)),
        Command::Calibrate(args) => done(calibrate::run(args)),
        Command::Observability(args) => done(observability::run(args)),
        Command::Survey(args) => survey::run(args),
        Command::Study(cmd) => done(study::run(cmd)),
        Command::Probe(args) => done(probe::run(args)),
        #[cfg(feature = "dashboard")]
        Command::Dashboard(args) => done(dashboard::run(args)),
        Command::Paper(cmd) => done(paper::run(cmd)),
    }
}
