//! The report of `host-sim observability`: the ranks of each toolface
//! segment's and of the stripped observability matrix, each state's
//! unobservable share and the unobservable directions
//! ([`crate::alignment::observability`] computes them).

use crate::alignment::observability::{Analysis, STATE_NAMES};
use std::fmt::Write;

/// Ranks, each state's unobservable share and the unobservable directions.
///
/// `toolfaces_deg` are the segments' toolface offsets and `measurements`
/// the updates' name, as given.
pub fn report(toolfaces_deg: &[f64], measurements: &str, a: &Analysis) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "{} states, {} toolface segment(s) {:?} deg, measurements: {}",
        a.states,
        toolfaces_deg.len(),
        toolfaces_deg,
        measurements
    );
    let _ = writeln!(
        out,
        "rank of each segment's obsv(F, H): {:?}",
        a.segment_ranks
    );
    let _ = writeln!(
        out,
        "rank of the stripped observability matrix: {} of {} (stripping condition {})",
        a.stripped_rank,
        a.states,
        if a.stripping_condition {
            "holds: this is the total rank"
        } else {
            "does not hold: a lower bound"
        }
    );
    // Shares are of each state's unit vector (states scaled to 1 mrad,
    // 1 cm/s, 1 cm, 1 mg, 2 deg/h) lying in the unobservable subspace.
    let _ = writeln!(out, "\n{:<28} {:>13}", "state", "unobservable");
    for (i, name) in STATE_NAMES.iter().enumerate().take(a.states) {
        let _ = writeln!(
            out,
            "{:<28} {:>12.0}%",
            name,
            100.0 * a.report.unobservable_share[i]
        );
    }
    for (k, v) in a.report.unobservable_directions.iter().enumerate() {
        let parts: Vec<String> = v
            .iter()
            .enumerate()
            .filter(|(_, c)| c.abs() > 0.1)
            .map(|(i, c)| format!("{c:+.2} {}", STATE_NAMES[i]))
            .collect();
        let _ = writeln!(
            out,
            "unobservable direction {}: {}",
            k + 1,
            parts.join(", ")
        );
    }
    out
}
