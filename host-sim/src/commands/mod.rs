//! The CLI: one module per subcommand, each with its clap `Args` and a `run`.
use clap::{Parser, Subcommand};

mod align;
mod allan;
mod arfit;
mod calibrate;
mod decode;
mod demo;
mod limits;
mod observability;
mod paper;
mod paper_mgwd;
mod replay;
mod simulate;
mod site;

#[derive(Parser, Debug)]
#[command(name = "host-sim", version, about = "Host tool of the gyro MWD probe")]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// The main job on built-in defaults: simulate the paper's 60 s static
    /// test and print the coarse alignment next to the truth.
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
    /// Reproductions of the papers' experiments.
    #[command(subcommand)]
    Paper(paper::PaperCommand),
}

/// Prints to stdout; a closed pipe (`| head`) ends the output quietly.
fn print_out(text: &str) -> anyhow::Result<()> {
    use std::io::Write;
    match std::io::stdout().lock().write_all(text.as_bytes()) {
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        other => Ok(other?),
    }
}

pub fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Demo(args) => demo::run(args),
        Command::Simulate(args) => simulate::run(args),
        Command::Decode(args) => decode::run(args),
        Command::Replay(args) => replay::run(args),
        Command::Align(args) => align::run(args),
        Command::Allan(args) => allan::run(args),
        Command::Arfit(args) => arfit::run(args),
        Command::Calibrate(args) => calibrate::run(args),
        Command::Observability(args) => observability::run(args),
        Command::Paper(cmd) => paper::run(cmd),
    }
}
