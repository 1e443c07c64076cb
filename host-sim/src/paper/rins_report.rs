//! The reports of the redundant-RINS paper's simulation (section 4.1,
//! Figures 3-6; [`crate::paper::rins`] computes it): ours beside the
//! paper's figures; and the strapdown check, each system's error-state
//! propagation against a full strapdown run of the same sensor errors
//! (docs/redundant-rins.md).

use crate::paper::rins::strapdown_check::{compare, Agreement, Check, Comparison, System};
use crate::paper::rins::{Results, Scenario};
use anyhow::Result;

/// A number or "undetermined" (never a number for a NaN).
fn num(x: f64, decimals: usize) -> String {
    if x.is_finite() {
        format!("{x:.decimals$}")
    } else {
        "undetermined".into()
    }
}

/// The report of a run: the scenario, then ours beside the paper's, row
/// by row; `wall` is the run's wall-clock time (s).
pub fn report(s: &Scenario, r: &Results, wall: f64) -> String {
    let m = &r.summary;
    let (red, full) = (&m.reduced, &m.full);
    let pct = |x: f64| {
        if x.is_finite() {
            format!("{:.1} %", 100.0 * x)
        } else {
            "undetermined".into()
        }
    };
    let mut lines = vec![
        format!(
            "Redundant RINS paper, section 4.1: {} h, master fails at hour {}, {:.0} deg N, {} m/s due east (seed {}).",
            s.hours, s.failure_hour, s.latitude_deg, s.speed, s.seed
        ),
        format!(
            "Error-state simulation in {} s substeps, filters every {} s ({} steps), {:.2} s wall.",
            s.substep, s.filter_step, m.steps, wall
        ),
        format!("Backup azimuth drift (truth) {:.5} deg/h.\n", m.drift_true_deg_h),
        format!("{:<58} {:>26} | {}", "", "ours", "paper"),
    ];
    let mut row = |what: &str, ours: String, paper: &str| {
        lines.push(format!("{what:<58} {ours:>26} | {paper}"))
    };
    let pm = |value: f64, sigma: f64| format!("{} +- {}", num(value, 6), num(sigma, 6));
    let slash = |parts: &[String]| parts.join(" / ");
    let nums = |values: &[f64], decimals: usize| {
        slash(&values.iter().map(|&v| num(v, decimals)).collect::<Vec<_>>())
    };
    row(
        "drift estimate error at failure, reduced (deg/h, 1 sigma)",
        pm(red.error_at_failure, red.sigma_at_failure),
        "accuracy 0.00005 (Fig. 3)",
    );
    row(
        "best possible 1 sigma: ARW sqrt(2 / T_failure) (deg/h)",
        num(m.drift_sigma_bound, 6),
        "(none; 0.00005 needs ARW ~0.0001)",
    );
    row(
        "drift estimate error at failure, full (deg/h, 1 sigma)",
        pm(full.error_at_failure, full.sigma_at_failure),
        "not given",
    );
    row(
        "reduced error inside 3 sigma, before failure / whole run",
        slash(&[
            pct(red.inside_3sigma_before_failure),
            pct(red.inside_3sigma_run),
        ]),
        "within bounds (Fig. 3)",
    );
    row(
        "full error inside 3 sigma, before failure / whole run",
        slash(&[
            pct(full.inside_3sigma_before_failure),
            pct(full.inside_3sigma_run),
        ]),
        "not given",
    );
    row(
        "reduced - full drift at failure (deg/h; RSS of sigmas)",
        format!(
            "{} ({})",
            num(m.reduced_minus_full, 6),
            num(m.combined_sigma, 6)
        ),
        "comparable (Fig. 6)",
    );
    row(
        &format!("radial error at {} h: master (m)", s.hours),
        num(m.radial_master_end, 0),
        "curve only (Fig. 5)",
    );
    row(
        "  backup uncompensated (m)",
        num(m.radial_backup_end, 0),
        "curve only (Fig. 5)",
    );
    row(
        "  backup compensated, reduced / full filter (m)",
        nums(
            &[
                m.radial_compensated_reduced_end,
                m.radial_compensated_full_end,
            ],
            0,
        ),
        "comparable with master (Fig. 5-6)",
    );
    row(
        "  compensated / master",
        num(m.compensated_over_master, 2),
        "comparable",
    );
    row(
        "largest radial error after failure: master / backup / comp. (m)",
        nums(
            &[
                m.radial_master_max,
                m.radial_backup_max,
                m.radial_compensated_reduced_max,
            ],
            0,
        ),
        "curve only",
    );
    row(
        "cost per step, reduced / full filter (us, this build)",
        nums(&[red.micros_per_step, full.micros_per_step], 1),
        "reduced 'relaxes the burden'",
    );
    lines.push(String::new());
    lines.push(
        "Our choices where the paper gives none: the rotation timing (10 deg/s, 60 s dwells), the \
         route, the initial errors and the measurement noise (docs/redundant-rins.md)."
            .into(),
    );
    lines.join("\n") + "\n"
}

/// The strapdown check's comparisons: both systems with their sensor
/// errors, and the master error-free (the mechanization's own error, the
/// floor).
pub struct StrapdownCheck {
    pub hours: f64,
    /// Strapdown sample rate (Hz).
    pub rate: f64,
    pub runs: Vec<Comparison>,
    pub floor: Comparison,
    /// Wall-clock time of the check (s).
    pub wall: f64,
}

/// Runs the strapdown check over `hours` at `rate` Hz.
pub fn strapdown_check(s: &Scenario, hours: f64, rate: f64) -> Result<StrapdownCheck> {
    let started = std::time::Instant::now();
    let mut runs = Vec::new();
    for system in [System::Backup, System::Master] {
        runs.push(compare(s, &Check::new(system, hours, rate, s))?);
    }
    let mut perfect = Check::new(System::Master, hours, rate, s);
    perfect.sensor_errors = false;
    let floor = compare(s, &perfect)?;
    Ok(StrapdownCheck {
        hours,
        rate,
        runs,
        floor,
        wall: started.elapsed().as_secs_f64(),
    })
}

impl StrapdownCheck {
    /// The comparisons as JSON.
    pub fn json(&self) -> serde_json::Value {
        serde_json::json!({ "with_sensor_errors": self.runs, "error_free_master": self.floor })
    }

    /// The comparisons as a table, with the error-free master's floor.
    pub fn text(&self, s: &Scenario) -> String {
        let (hours, rate, wall) = (self.hours, self.rate, self.wall);
        let cell = |a: &Agreement, decimals: usize| {
            format!(
                "{} of {} ({})",
                num(a.max_difference, decimals),
                num(a.max_error, decimals),
                num(a.relative(), 5)
            )
        };
        let mut lines = vec![
            format!(
                "Strapdown (mwd_core::mechanization, {rate} Hz) against the error-state propagation (1 s), {hours} h, {:.0} deg N, {} m/s due east; {:.1} s wall.",
                s.latitude_deg, s.speed, wall
            ),
            "Largest |strapdown - error-state| of the largest error-state error (relative):".into(),
            format!(
                "{:<8} {:>34} {:>34} {:>34}",
                "system", "attitude (arcsec)", "velocity (m/s)", "position (m)"
            ),
        ];
        for c in &self.runs {
            lines.push(format!(
                "{:<8} {:>34} {:>34} {:>34}",
                format!("{:?}", c.system),
                cell(&c.attitude_arcsec, 4),
                cell(&c.velocity, 6),
                cell(&c.position_m, 3)
            ));
        }
        let floor = &self.floor;
        lines.push(format!(
            "Error-free master (the strapdown's own error): attitude {} arcsec, velocity {} m/s, position {} m.",
            num(floor.attitude_arcsec.max_difference, 5),
            num(floor.velocity.max_difference, 7),
            num(floor.position_m.max_difference, 4)
        ));
        lines.join("\n") + "\n"
    }
}
