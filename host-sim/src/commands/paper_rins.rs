//! `host-sim paper rins`: the redundant-RINS paper's 120 h semi-physical
//! simulation (section 4.1, Figures 3-6) reproduced, ours beside the
//! paper's figures. The experiment is `host_sim::paper::rins`'s; this module reads
//! the options and reports.

use anyhow::Result;
use host_sim::paper::rins::{self, Results, Scenario};
use std::path::PathBuf;

#[derive(clap::Args, Debug)]
pub struct RinsArgs {
    /// Seed of the noise and the initial errors.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Length of the run (h).
    #[arg(long, default_value_t = Scenario::paper().hours)]
    pub hours: f64,
    /// When the master fails (h).
    #[arg(long, default_value_t = Scenario::paper().failure_hour)]
    pub failure_hour: f64,
    /// Filter step (s); the systems are simulated in 1 s substeps.
    #[arg(long, default_value_t = Scenario::paper().filter_step)]
    pub filter_step: f64,
    /// Vehicle speed (m/s), due east at the scenario's latitude.
    #[arg(long, default_value_t = Scenario::paper().speed)]
    pub speed: f64,
    /// Gyro angle random walk of both systems (deg/sqrt(h)); the paper's
    /// bound 0.001 by default.
    #[arg(long, default_value_t = 0.001)]
    pub gyro_arw: f64,
    /// Write the SVG and PNG plots of Figures 3-6 into this directory.
    #[arg(long, value_name = "DIR")]
    pub plot: Option<PathBuf>,
    /// Print the summary and the history as JSON instead of the report.
    #[arg(long)]
    pub json: bool,
    /// Instead of the paper's run: each system's error-state propagation
    /// against a full strapdown run of the same sensor errors over `--hours`
    /// (4 h if not given), docs/redundant-rins.md.
    #[arg(long)]
    pub strapdown_check: bool,
    /// Strapdown sample rate of `--strapdown-check` (Hz).
    #[arg(long, default_value_t = 100.0)]
    pub strapdown_rate: f64,
}

pub fn run(args: RinsArgs) -> Result<()> {
    if !(args.gyro_arw.is_finite() && args.gyro_arw >= 0.0) {
        anyhow::bail!(
            "--gyro-arw must be a non-negative number (deg/sqrt(h)), got {}",
            args.gyro_arw
        );
    }
    let mut scenario = Scenario {
        seed: args.seed,
        hours: args.hours,
        failure_hour: args.failure_hour,
        filter_step: args.filter_step,
        speed: args.speed,
        ..Scenario::paper()
    };
    if args.strapdown_check {
        // the paper's 120 h default is far longer than the check needs
        let hours_given = args.hours != Scenario::paper().hours;
        let hours = if hours_given { args.hours } else { 4.0 };
        return strapdown_check(&scenario, hours, args.strapdown_rate, args.json);
    }
    let arw = args.gyro_arw * mwd_core::conventions::DEG / 60.0;
    scenario.backup.gyro_arw = arw;
    scenario.master.gyro_arw = arw;
    let started = std::time::Instant::now();
    let results = rins::run(&scenario)?;
    let wall = started.elapsed().as_secs_f64();
    if let Some(dir) = &args.plot {
        host_sim::formats::figure::prepare_dir(dir)?;
        let files = rins::plot::write_figures(dir, &results, scenario.failure_hour)?;
        if !args.json {
            outln!("Figures 3-6: {} files in {}", files.len(), dir.display());
        }
    }
    if args.json {
        super::output::print_out(&(serde_json::to_string_pretty(&results)? + "\n"))
    } else {
        super::output::print_out(&report(&scenario, &results, wall))
    }
}

/// A number or "undetermined" (never a number for a NaN).
fn num(x: f64, decimals: usize) -> String {
    if x.is_finite() {
        format!("{x:.decimals$}")
    } else {
        "undetermined".into()
    }
}

fn report(s: &Scenario, r: &Results, wall: f64) -> String {
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
    row(
        "drift estimate error at failure, reduced (deg/h, 1 sigma)",
        format!(
            "{} +- {}",
            num(red.error_at_failure, 6),
            num(red.sigma_at_failure, 6)
        ),
        "accuracy 0.00005 (Fig. 3)",
    );
    row(
        "best possible 1 sigma: ARW sqrt(2 / T_failure) (deg/h)",
        num(m.drift_sigma_bound, 6),
        "(none; 0.00005 needs ARW ~0.0001)",
    );
    row(
        "drift estimate error at failure, full (deg/h, 1 sigma)",
        format!(
            "{} +- {}",
            num(full.error_at_failure, 6),
            num(full.sigma_at_failure, 6)
        ),
        "not given",
    );
    row(
        "reduced error inside 3 sigma, before failure / whole run",
        format!(
            "{} / {}",
            pct(red.inside_3sigma_before_failure),
            pct(red.inside_3sigma_run)
        ),
        "within bounds (Fig. 3)",
    );
    row(
        "full error inside 3 sigma, before failure / whole run",
        format!(
            "{} / {}",
            pct(full.inside_3sigma_before_failure),
            pct(full.inside_3sigma_run)
        ),
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
        format!(
            "{} / {}",
            num(m.radial_compensated_reduced_end, 0),
            num(m.radial_compensated_full_end, 0)
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
        format!(
            "{} / {} / {}",
            num(m.radial_master_max, 0),
            num(m.radial_backup_max, 0),
            num(m.radial_compensated_reduced_max, 0)
        ),
        "curve only",
    );
    row(
        "cost per step, reduced / full filter (us, this build)",
        format!(
            "{} / {}",
            num(red.micros_per_step, 1),
            num(full.micros_per_step, 1)
        ),
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

/// `--strapdown-check`: both systems with their sensor errors, and the
/// master error-free (the mechanization's own error, the floor).
fn strapdown_check(s: &Scenario, hours: f64, rate: f64, json: bool) -> Result<()> {
    use rins::strapdown_check::{compare, Agreement, Check, System};
    let started = std::time::Instant::now();
    let mut runs = Vec::new();
    for system in [System::Backup, System::Master] {
        runs.push(compare(s, &Check::new(system, hours, rate, s))?);
    }
    let mut perfect = Check::new(System::Master, hours, rate, s);
    perfect.sensor_errors = false;
    let floor = compare(s, &perfect)?;
    let wall = started.elapsed().as_secs_f64();
    if json {
        let all = serde_json::json!({ "with_sensor_errors": runs, "error_free_master": floor });
        return super::output::print_out(&(serde_json::to_string_pretty(&all)? + "\n"));
    }
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
    for c in &runs {
        lines.push(format!(
            "{:<8} {:>34} {:>34} {:>34}",
            format!("{:?}", c.system),
            cell(&c.attitude_arcsec, 4),
            cell(&c.velocity, 6),
            cell(&c.position_m, 3)
        ));
    }
    lines.push(format!(
        "Error-free master (the strapdown's own error): attitude {} arcsec, velocity {} m/s, position {} m.",
        num(floor.attitude_arcsec.max_difference, 5),
        num(floor.velocity.max_difference, 7),
        num(floor.position_m.max_difference, 4)
    ));
    super::output::print_out(&(lines.join("\n") + "\n"))
}
