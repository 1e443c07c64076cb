//! The report of the TLS paper's nine-accelerometer experiment (Tables
//! 1-2; [`crate::paper::tls`] computes it): our run, its errors and the
//! mean errors over the seeded runs, beside the paper's figures.

use crate::paper::tls::{error_percent, Experiment, TableRow, PAPER_TABLES};
use std::fmt::Write;

/// Tables 1-2, ours beside the paper's.
pub fn tls_report(exp: &Experiment, runs: usize, rows: &[TableRow]) -> String {
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
