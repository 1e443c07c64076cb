//! The redundant-RINS reproduction (`host_sim::paper::rins`, `host-sim paper
//! rins`) against the checks. Each 120 h scenario runs once (~9 s
//! in the debug test build) and its results are shared by the tests.

use host_sim::paper::rins::{run, Results, Scenario};
use mwd_core::conventions::DEG;
use std::process::Command;
use std::sync::OnceLock;

/// The paper's figures (section 4.1), seed 1.
fn paper() -> &'static Results {
    static R: OnceLock<Results> = OnceLock::new();
    R.get_or_init(|| run(&Scenario::paper()).expect("the paper scenario runs"))
}

/// The same with a 10x smaller gyro ARW, 0.0001 deg/sqrt(h): the level at
/// which the paper's drift accuracy (0.00005 deg/h) is reachable at all.
fn quiet_gyros() -> &'static Results {
    static R: OnceLock<Results> = OnceLock::new();
    R.get_or_init(|| {
        let mut s = Scenario::paper();
        let arw = 0.0001 * DEG / 60.0;
        s.backup.gyro_arw = arw;
        s.master.gyro_arw = arw;
        run(&s).expect("the quiet-gyro scenario runs")
    })
}

#[test]
fn drift_estimate_error_stays_inside_3_sigma() {
    let m = &paper().summary;
    assert!(
        m.reduced.inside_3sigma_run >= 0.99,
        "{}",
        m.reduced.inside_3sigma_run
    );
    assert!(
        m.full.inside_3sigma_run >= 0.99,
        "{}",
        m.full.inside_3sigma_run
    );
    // the bounds are earned: the sigma fell from its initial 0.001 deg/h,
    // and stays within 1.5x of what any filter could reach at all
    let s = m.reduced.sigma_at_failure;
    assert!(
        s < 0.0006 && s >= m.drift_sigma_bound,
        "{s} vs bound {}",
        m.drift_sigma_bound
    );
    assert!(
        s < 1.5 * m.drift_sigma_bound,
        "{s} vs bound {}",
        m.drift_sigma_bound
    );
}

#[test]
fn quiet_gyros_reach_the_papers_accuracy() {
    let m = &quiet_gyros().summary;
    assert!(
        m.reduced.sigma_at_failure < 0.00006,
        "{}",
        m.reduced.sigma_at_failure
    );
    assert!(m.reduced.error_at_failure.abs() < 3.0 * m.reduced.sigma_at_failure);
}

/// The stated factors: with the paper's figures the compensated backup's
/// radial error at 120 h is within 3.5x the master's (seed 1: 2.9x; the
/// drift is learned only to +-0.00045 deg/h, so compensation cannot do
/// much); with quiet gyros the compensation at least halves the backup's
/// error and ends within 2x the master's (seed 1: 1.4x).
#[test]
fn compensated_backup_is_within_a_factor_of_the_master() {
    let m = &paper().summary;
    assert!(
        m.compensated_over_master < 3.0,
        "{}",
        m.compensated_over_master
    );
    let q = &quiet_gyros().summary;
    assert!(
        q.compensated_over_master < 3.0,
        "{}",
        q.compensated_over_master
    );
    assert!(
        q.radial_compensated_reduced_end < 0.5 * q.radial_backup_end,
        "{} vs {}",
        q.radial_compensated_reduced_end,
        q.radial_backup_end
    );
}

/// The drift estimates of the two filters differ by at most the root sum
/// square of their sigmas: at the failure (the estimate the compensation
/// uses) and, with the paper's figures, at every recorded point (seed 1:
/// 0.54 at most). With quiet gyros the early transient reaches 1.4 of it
/// (seed 1), so there the history is held to 1.5.
#[test]
fn reduced_and_full_filters_agree_within_their_sigmas() {
    for (r, history_factor) in [(paper(), 1.0), (quiet_gyros(), 1.5)] {
        let m = &r.summary;
        assert!(
            m.reduced_minus_full.abs() <= m.combined_sigma,
            "{} vs {}",
            m.reduced_minus_full,
            m.combined_sigma
        );
        for p in &r.history {
            let both = p.drift_sigma_reduced.hypot(p.drift_sigma_full);
            let gap = (p.drift_error_reduced - p.drift_error_full).abs();
            assert!(
                gap <= history_factor * both,
                "at {} h: {gap} vs {both}",
                p.hour
            );
        }
    }
}

#[test]
fn prediction_follows_the_drift_part_of_the_backup_error() {
    // with quiet gyros the estimate is good: at 120 h the prediction is
    // within 30 % of the part of the error the true drift causes
    let last = quiet_gyros().history.last().unwrap();
    let truth = last.drift_north.hypot(last.drift_east);
    let miss =
        (last.predicted_north - last.drift_north).hypot(last.predicted_east - last.drift_east);
    assert!(truth > 500.0, "the drift must matter: {truth} m");
    assert!(miss < 0.3 * truth, "{miss} of {truth} m");
}

fn host_sim(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_host-sim"))
        .args(args)
        .output()
        .expect("host-sim runs")
}

#[test]
fn cli_json_and_plots() {
    let dir = std::env::temp_dir().join(format!("paper-rins-{}", std::process::id()));
    let dir_s = dir.to_str().unwrap();
    let out = host_sim(&[
        "paper",
        "rins",
        "--hours",
        "3",
        "--failure-hour",
        "2",
        "--json",
        "--plot",
        dir_s,
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON");
    assert!(
        v["summary"]["reduced"]["sigma_at_failure"]
            .as_f64()
            .unwrap()
            > 0.0
    );
    assert_eq!(v["history"].as_array().unwrap().len(), 18);
    for stem in [
        "fig3-drift-estimate",
        "fig4-latitude",
        "fig4-longitude",
        "fig5-radial",
        "fig6-reduced-vs-full",
    ] {
        for ext in ["svg", "png"] {
            let f = dir.join(format!("{stem}.{ext}"));
            assert!(
                std::fs::metadata(&f)
                    .map(|m| m.len() > 1000)
                    .unwrap_or(false),
                "{}",
                f.display()
            );
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn cli_refuses_bad_numbers() {
    for args in [
        &["paper", "rins", "--hours=-1"][..],
        &["paper", "rins", "--hours", "2", "--failure-hour", "5"],
        &["paper", "rins", "--filter-step", "2.5"],
        &["paper", "rins", "--gyro-arw", "nan"],
    ] {
        let out = host_sim(args);
        assert!(!out.status.success(), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!err.contains("panicked"), "{args:?}: {err}");
        assert!(err.contains("must"), "{args:?}: {err}");
    }
}
