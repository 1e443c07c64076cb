//! The report of `host-sim arfit`: every column's AR fits by every method
//! in the paper's sign convention (Tables 4-5), each column's
//! autocorrelation and AIC/BIC by order, and where the model file went
//! ([`crate::analysis::ar_analysis`] computes them).

use crate::analysis::ar_analysis::{ArOptions, ColumnAr};
use crate::analysis::units::Quantity;
use mwd_core::conventions::DEG;
use std::fmt::Write;
use std::path::Path;

/// The fits table, each column's autocorrelation and order scores, and
/// where the model file went.
pub fn report(columns: &[ColumnAr], options: &ArOptions, path: &Path) -> String {
    let mut out = String::new();
    fits_table(&mut out, columns, options.order);
    for column in columns {
        order_table(&mut out, column, options);
    }
    let _ = writeln!(
        out,
        "\nmodel file ({}, order {}) written to {}",
        options.method,
        options.order,
        path.display()
    );
    out
}

/// Every column's fits by every method, like the paper's Tables 4-5.
fn fits_table(out: &mut String, columns: &[ColumnAr], order: usize) {
    let _ = writeln!(
        out,
        "AR({order}) fits, paper convention z_k = -sum a_i z_(k-i) + e_k, beta = var(e)"
    );
    let header: String = (1..=order)
        .map(|i| format!("{:>10}", format!("a{i}")))
        .collect();
    let _ = writeln!(
        out,
        "{:<14} {:<12}{header} {:>13} {:>13}",
        "sensor", "method", "beta (SI)", "beta (report)"
    );
    for column in columns {
        for fit in &column.fits {
            let coeffs: String = fit
                .coefficients
                .iter()
                .map(|a| format!("{a:>10.4}"))
                .collect();
            let (report, report_unit) = match column.unit.quantity() {
                // The paper's Table 5 betas are (deg/s)^2 (project assumption).
                Quantity::AngularRate => (fit.noise_variance * (1.0 / DEG).powi(2), "(deg/s)^2"),
                Quantity::SpecificForce => (fit.noise_variance, "(m/s^2)^2"),
                Quantity::Other => (fit.noise_variance, "u^2"),
            };
            let _ = writeln!(
                out,
                "{:<14} {:<12}{coeffs} {:>13.4e} {:>9.4e} {report_unit}",
                column.name,
                fit.method.to_string(),
                fit.noise_variance,
                report
            );
        }
    }
}

/// One column's autocorrelation and its AIC/BIC by order, best marked.
fn order_table(out: &mut String, column: &ColumnAr, options: &ArOptions) {
    let acf: String = column
        .autocorrelation
        .iter()
        .skip(1)
        .map(|r| format!("{r:>8.3}"))
        .collect();
    let _ = writeln!(
        out,
        "\n{}: autocorrelation at lags 1..{}:{acf}",
        column.name, options.lags
    );
    let _ = writeln!(
        out,
        "{:>4} {:>13} {:>9} {:>15} {:>15}  ({})",
        "p", "sigma^2", "k_p", "AIC", "BIC", options.method
    );
    let (best_aic, best_bic) = (column.best_aic(), column.best_bic());
    for s in &column.scores {
        let mark = match (s.order == best_aic, s.order == best_bic) {
            (true, true) => "  <- AIC, BIC",
            (true, false) => "  <- AIC",
            (false, true) => "  <- BIC",
            _ => "",
        };
        let _ = writeln!(
            out,
            "{:>4} {:>13.5e} {:>9.4} {:>15.2} {:>15.2}{mark}",
            s.order, s.noise_variance, s.reflection, s.aic, s.bic
        );
    }
}
