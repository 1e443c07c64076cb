//! `host-sim demo`'s pieces: the coarse alignment on built-in defaults.
//! The paper's 60 s static test (section 4) simulated with the SCC1300
//! error model, each case calibrated with the paper's Table 3 and
//! coarse-aligned, its report next to the truth; and the toolface
//! indexing that separates the gyro bias from earth rate.

use crate::alignment::coarse;
use crate::formats::samples_csv::Record;
use crate::sim::{DeterministicErrors, Motion, SensorModel, SensorSimulator, Trajectory};
use anyhow::Result;
use mwd_core::alignment::AlignmentConfig;
use mwd_core::conventions::DEG;
use mwd_core::timing::SAMPLE_INTERVAL_S;

/// The alignment's configuration at the trajectory's site. The paper's
/// heading is known to be south-westerly from the parent well: a prior
/// within 90 deg resolves the north/south ambiguity.
pub fn config(traj: &Trajectory) -> AlignmentConfig {
    AlignmentConfig::probe(traj.position.lat)
        .with_heading_prior(Some(traj.start.heading + 30.0 * DEG))
}

/// Where the simulated probe is and how it sits.
pub fn setup_text(traj: &Trajectory) -> String {
    format!(
        "Simulated SCC1300 probe at rest, {:.5} N {:.6} E {:.0} m; truth roll {:.4} pitch {:.4} azimuth {:.4} deg (the paper's coarse result).\n\
         Prior heading for the north/south ambiguity: truth + 30 deg.\n\n",
        traj.position.lat / DEG,
        traj.position.lon / DEG,
        traj.position.height,
        traj.start.roll / DEG,
        traj.start.pitch / DEG,
        crate::formats::display::deg_0_360(traj.start.heading)
    )
}

/// `seconds` of the SCC1300 model on `trajectory`.
pub fn simulate(trajectory: &Trajectory, seconds: f64, seed: u64) -> Vec<Record> {
    let n = (seconds / SAMPLE_INTERVAL_S).round() as usize;
    let model = SensorModel::scc1300(seed);
    SensorSimulator::new(trajectory.clone(), model, SAMPLE_INTERVAL_S)
        .take(n)
        .map(|s| Record::from(&s))
        .collect()
}

/// The trajectory with toolface indexing: 10 min at the start toolface,
/// a turn of 180 deg, 10 min.
pub fn indexed(traj: &Trajectory) -> Trajectory {
    Trajectory {
        motion: Motion::ToolfaceSteps {
            step: std::f64::consts::PI,
            turn_rate: 30.0 * DEG,
            dwell: 600.0,
            steps: 1,
        },
        ..traj.clone()
    }
}

/// Calibrates `records` with the paper's Table 3, coarse-aligns their
/// static segments and gives the report under `title`.
pub fn case_text(title: &str, records: &[Record], config: &AlignmentConfig) -> Result<String> {
    let cal = DeterministicErrors::paper_table3().calibration();
    let records: Vec<_> = records
        .iter()
        .map(|r| coarse::calibrated(r, &cal))
        .collect();
    let report = coarse::align_run(&records, config)?;
    Ok(format!("== {title}\n{}\n", report.render()))
}
