//! `host-sim`: the host tool of the gyro MWD probe. Each subcommand lives in
//! its own module under `commands/`.
use clap::Parser;

mod commands;

fn main() {
    let cli = commands::Cli::parse();
    if let Err(err) = commands::run(cli) {
        eprintln!("error: {err:#}");
        std::process::exit(1);
    }
}
