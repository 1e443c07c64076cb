//! `host-sim paper ...`: reproductions of the papers' experiments, each a
//! subcommand of [`PaperCommand`] with its own arguments.

use super::output::print_out;
use anyhow::Result;
use host_sim::paper::tls::{error_percent, tables, Experiment, TableRow, PAPER_TABLES};
use std::fmt::Write;

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

/// Tables 1-2, ours beside the paper's.
fn tls_report(exp: &Experiment, runs: usize, rows: &[TableRow]) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "Nine-accelerometer static decoupling (TLS paper section 5): bias 1e-5 g, dt 10 ms, true w_z = 0.005 sin t\n\
         our choices: l = {} m, calibration excitation {:.1e} m/s^2, reference and output errors {:.1e} m/s^2 (1 sigma)\n\
         rates in rad/s; err = |w_hat - w| / |w|; mean err over {} seeded runs",
        exp.lever_arm, exp.excitation, exp.noise, runs
    );
    for (table, (angle, _)) in PAPER_TABLES.iter().enumerate() {
        let _ = writeln!(out, "\nTable {}: coupling angle {angle} rad", table + 1);
        let rows: Vec<&TableRow> = rows.iter().filter(|r| r.coupling_angle == *angle).collect();
        tls_table(&mut out, &rows);
    }
    let _ = writeln!(
        out,
        "\nThe paper's true-rate column equals 0.005 sin(N dt) except N = 200, 300 (printed 0.004564, 0.000756)."
    );
    out
}

/// One table's rows: our run, its errors and the mean errors, the paper's.
fn tls_table(out: &mut String, rows: &[&TableRow]) {
    let _ = writeln!(
        out,
        "{:>4} {:>10} {:>10} {:>10} {:>7} {:>10} {:>7} | {:>8} {:>8} | {:>10} {:>10} {:>7}",
        "N",
        "true",
        "before",
        "TLS",
        "err %",
        "LS",
        "err %",
        "mean TLS",
        "mean LS",
        "paper bef",
        "paper aft",
        "err %"
    );
    for r in rows {
        let (row, mean) = (&r.row, r.mean_error_percent_before_tls_ls);
        let (_, p_before, p_after, p_err) = r.paper;
        let _ = writeln!(
            out,
            "{:>4} {:>10.6} {:>10.6} {:>10.6} {:>7.2} {:>10.6} {:>7.2} | {:>8.2} {:>8.2} | {:>10.6} {:>10.6} {:>7.2}",
            row.n,
            row.true_rate,
            row.before,
            row.after_tls,
            error_percent(row.after_tls, row.true_rate),
            row.after_ls,
            error_percent(row.after_ls, row.true_rate),
            mean[1],
            mean[2],
            p_before,
            p_after,
            p_err
        );
    }
}
