//! The CLI: one module per subcommand, each with its clap `Args` and a `run`.
use clap::{Parser, Subcommand};

mod align;
mod demo;
mod simulate;

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
    /// Coarse alignment of a recorded or simulated static file.
    Align(align::Args),
}

pub fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Demo(args) => demo::run(args),
        Command::Simulate(args) => simulate::run(args),
        Command::Align(args) => align::run(args),
    }
}
