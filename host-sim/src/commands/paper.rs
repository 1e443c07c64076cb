//! `host-sim paper ...`: reproductions of the papers' experiments, each a
//! subcommand of [`PaperCommand`] with its own arguments.

use super::output::print_out;
use anyhow::Result;
use host_sim::paper::tls::{tables, Experiment};
use host_sim::paper::tls_report::tls_report;

#[derive(clap::Subcommand, Debug)]
pub enum PaperCommand {
    /// The TLS decoupling paper's nine-accelerometer experiment (Tables 1-2),
    /// ours beside the paper's figures.
    Tls(TlsArgs),
    /// The MGWD paper's 60 s static fine alignment (section 4, Figures 13-15),
    /// ours beside the paper's figures.
    Mgwd(super::paper_mgwd::MgwdArgs),
    /// The redundant-RINS paper's 120 h simulation (section 4.1, Figures
    /// 3-6): reduced-order filter, master failure, compensated backup.
    Rins(super::paper_rins::RinsArgs),
}

pub fn run(cmd: PaperCommand) -> Result<()> {
    match cmd {
        PaperCommand::Tls(args) => run_tls(args),
        PaperCommand::Mgwd(args) => super::paper_mgwd::run(args),
        PaperCommand::Rins(args) => super::paper_rins::run(args),
    }
}

#[derive(clap::Args, Debug)]
pub struct TlsArgs {
    /// Seed of the single run shown in the tables.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Monte Carlo runs behind the mean-error columns.
    #[arg(long, default_value_t = 200)]
    pub runs: usize,
    /// Lever arm l (m); the paper gives none.
    #[arg(long, default_value_t = Experiment::default().lever_arm)]
    pub lever_arm: f64,
    /// Reference and output error (m/s^2, 1 sigma); the paper gives none.
    #[arg(long, default_value_t = Experiment::default().noise)]
    pub noise: f64,
    /// Calibration excitation about the static point (m/s^2, 1 sigma).
    #[arg(long, default_value_t = Experiment::default().excitation)]
    pub excitation: f64,
    /// Print JSON rows instead of tables.
    #[arg(long)]
    pub json: bool,
}

fn run_tls(args: TlsArgs) -> Result<()> {
    let exp = Experiment {
        lever_arm: args.lever_arm,
        noise: args.noise,
        excitation: args.excitation,
        ..Experiment::default()
    };
    let rows = tables(&exp, args.seed, args.runs)?;
    if args.json {
        print_out(&(serde_json::to_string_pretty(&rows)? + "\n"))
    } else {
        print_out(&tls_report(&exp, args.runs, &rows))
    }
}
