//! The simulation loop: both systems' errors every substep, both filters
//! and the prediction model every filter step, the master's output gone
//! from the failure on.

use super::filters::{micros_per_step, DriftFilter, Tuning};
use super::rotation::{PhasedScheme, RotationScheme, Timing};
use super::system::{Ins, NavErrors, Propagation};
use super::{deg_per_hour, Scenario};
use mwd_core::conventions::DEG;
use mwd_core::earth::{normal_gravity, radii};
use mwd_core::redundant::index::{DV_E, DV_N, D_LAT, D_LON, PHI_E};
use mwd_core::redundant::{
    compensate, navigation_block, reduced_dynamics, transition, BackupOutput,
    DifferenceMeasurement, DriftPrediction, Motion,
};
use nalgebra::Matrix3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use serde::Serialize;

/// One recorded point (drifts in deg/h, positions in m).
#[derive(Debug, Clone, Serialize)]
pub struct Record {
    pub hour: f64,
    /// Drift estimate minus truth and 1-sigma, reduced and full filter.
    pub drift_error_reduced: f64,
    pub drift_sigma_reduced: f64,
    pub drift_error_full: f64,
    pub drift_sigma_full: f64,
    /// The backup's true latitude and longitude errors (north, east, m)
    /// and the reduced filter's prediction of them (eq. 31).
    pub backup_north: f64,
    pub backup_east: f64,
    pub predicted_north: f64,
    pub predicted_east: f64,
    /// The part of the backup's error its true azimuth drift causes (the
    /// prediction with a perfect estimate).
    pub drift_north: f64,
    pub drift_east: f64,
    /// Radial position errors: the master, the backup as it is, the backup
    /// compensated with the reduced and with the full filter's drift.
    pub radial_master: f64,
    pub radial_backup: f64,
    pub radial_compensated_reduced: f64,
    pub radial_compensated_full: f64,
}

/// One filter's figures.
#[derive(Debug, Clone, Serialize)]
pub struct FilterSummary {
    /// Drift estimate minus truth and its 1-sigma at the failure (deg/h).
    pub error_at_failure: f64,
    pub sigma_at_failure: f64,
    /// Share of filter steps with |error| <= 3 sigma, over the whole run and
    /// before the failure.
    pub inside_3sigma_run: f64,
    pub inside_3sigma_before_failure: f64,
    /// Mean cost of one step (predict + update), microseconds.
    pub micros_per_step: f64,
}

/// The run's figures.
#[derive(Debug, Clone, Serialize)]
pub struct Summary {
    pub drift_true_deg_h: f64,
    /// The smallest 1-sigma any filter can reach at the failure (deg/h):
    /// the two systems' headings random-walk apart with density
    /// 2 ARW^2, and the drift of a random walk observed without noise for a
    /// time T is known to sqrt(2 ARW^2 / T) at best (its Fisher information
    /// is T / (2 ARW^2)). Even a directly measured heading difference could
    /// not do better.
    pub drift_sigma_bound: f64,
    pub reduced: FilterSummary,
    pub full: FilterSummary,
    /// Radial position errors at the end of the run (m).
    pub radial_master_end: f64,
    pub radial_backup_end: f64,
    pub radial_compensated_reduced_end: f64,
    pub radial_compensated_full_end: f64,
    /// Compensated backup over master, radial error at the end.
    pub compensated_over_master: f64,
    /// Largest radial errors after the failure (m).
    pub radial_master_max: f64,
    pub radial_backup_max: f64,
    pub radial_compensated_reduced_max: f64,
    /// Reduced minus full drift estimate at the failure, and the root sum
    /// square of their sigmas (deg/h).
    pub reduced_minus_full: f64,
    pub combined_sigma: f64,
    /// Filter steps run and the filter step (s).
    pub steps: u64,
    pub filter_step: f64,
}

/// Summary and history of a run.
#[derive(Debug, Clone, Serialize)]
pub struct Results {
    pub summary: Summary,
    pub history: Vec<Record>,
}

/// The vehicle's body-to-ENU rotation for a level vehicle on `course`
/// (x right, y forward, z up, as `mwd_core::conventions`' body frame).
pub(super) fn vehicle(course: f64) -> Matrix3<f64> {
    let (s, c) = course.sin_cos();
    Matrix3::new(c, s, 0.0, -s, c, 0.0, 0.0, 0.0, 1.0)
}

/// Horizontal position error (north, east) in metres.
fn north_east(x: &NavErrors, rn: f64, re_cos: f64) -> (f64, f64) {
    (x[D_LAT] * rn, x[D_LON] * re_cos)
}

fn radial(x: &NavErrors, rn: f64, re_cos: f64) -> f64 {
    let (n, e) = north_east(x, rn, re_cos);
    n.hypot(e)
}

/// Initial attitude errors drawn with the scenario's sigmas.
fn initial(sigma: [f64; 2], rng: &mut ChaCha8Rng) -> NavErrors {
    let mut x = NavErrors::zeros();
    for (i, s) in [sigma[0], sigma[0], sigma[1]].into_iter().enumerate() {
        x[PHI_E + i] = s * rng.sample::<f64, _>(StandardNormal);
    }
    x
}

/// The backup's errors after eq. 33's compensation with `predicted`.
fn compensated(x: &NavErrors, predicted: &nalgebra::SVector<f64, 8>) -> NavErrors {
    let output = BackupOutput {
        lat: x[D_LAT],
        lon: x[D_LON],
        v_east: x[DV_E],
        v_north: x[DV_N],
    };
    let fixed = compensate(&output, predicted);
    let mut out = *x;
    (out[D_LAT], out[D_LON], out[DV_E], out[DV_N]) =
        (fixed.lat, fixed.lon, fixed.v_east, fixed.v_north);
    out
}

/// Counts of |error| <= 3 sigma.
#[derive(Default)]
struct Inside {
    run: (u64, u64),
    before: (u64, u64),
}

impl Inside {
    fn count(&mut self, (estimate, sigma): (f64, f64), truth: f64, before: bool) {
        let ok = u64::from((estimate - truth).abs() <= 3.0 * sigma);
        self.run = (self.run.0 + ok, self.run.1 + 1);
        if before {
            self.before = (self.before.0 + ok, self.before.1 + 1);
        }
    }
}

fn share((n, of): (u64, u64)) -> f64 {
    if of == 0 {
        f64::NAN
    } else {
        n as f64 / of as f64
    }
}

/// See [`Summary::drift_sigma_bound`] (rad/s); +inf with no time to learn.
fn drift_sigma_bound(s: &Scenario) -> f64 {
    let density = s.backup.gyro_arw.powi(2) + s.master.gyro_arw.powi(2);
    let seconds = s.failure_hour * 3600.0;
    if seconds > 0.0 {
        (density / seconds).sqrt()
    } else {
        f64::INFINITY
    }
}

/// Runs the scenario.
pub fn run(s: &Scenario) -> anyhow::Result<Results> {
    s.validate()?;
    let lat = s.latitude_deg * DEG;
    let g = normal_gravity(lat, 0.0);
    let motion = Motion::uniform(lat, 0.0, s.speed, s.course_deg * DEG, g);
    let r = radii(lat);
    let (rn, re_cos) = (r.meridian, r.transverse * lat.cos());
    let propagation = Propagation::new(&navigation_block::<f64>(&motion), s.substep);
    let body = vehicle(s.course_deg * DEG);
    let backup_scheme = PhasedScheme::single_axis_four_dwell(Timing::ours());
    let master_scheme = PhasedScheme::dual_axis_sixteen_phase(Timing::ours());
    let mut rng = ChaCha8Rng::seed_from_u64(s.seed);
    let mut backup = Ins {
        sensors: s.backup,
        errors: initial(s.initial_attitude, &mut rng),
    };
    let mut master = Ins {
        sensors: s.master,
        errors: initial(s.initial_attitude, &mut rng),
    };
    let tuning = Tuning {
        attitude: s.initial_attitude,
        drift: deg_per_hour(0.001),
        other_drift: deg_per_hour(0.01),
        accel_bias: 100e-6 * g,
        gyro_arw: s.backup.gyro_arw.max(s.master.gyro_arw),
        accel_vrw: s.backup.accel_vrw.max(s.master.accel_vrw),
        velocity_sigma: s.velocity_sigma,
        position_sigma: s.position_sigma_m / rn,
    };
    let mut reduced = DriftFilter::reduced(&tuning);
    let mut full = DriftFilter::full(&tuning);
    let mut prediction = DriftPrediction::<f64>::new();
    let truth = s.backup.gyro_drift.z;

    let substeps = (s.filter_step / s.substep).round() as usize;
    let steps = (s.hours * 3600.0 / s.filter_step).round() as u64;
    let failure = (s.failure_hour * 3600.0 / s.filter_step).round() as u64;
    let record_every = ((s.record_every / s.filter_step).round() as u64).max(1);
    let (mut inside_reduced, mut inside_full) = (Inside::default(), Inside::default());
    let mut at_failure = [(f64::NAN, f64::NAN); 2];
    let mut history = Vec::new();
    let mut max = [0.0f64; 3];
    for k in 0..steps {
        let t0 = k as f64 * s.filter_step;
        let (mut c1_sum, mut c2_sum) = (Matrix3::zeros(), Matrix3::zeros());
        for j in 0..substeps {
            let t = t0 + (j as f64 + 0.5) * s.substep;
            let c1 = body * backup_scheme.orientation(t);
            let c2 = body * master_scheme.orientation(t);
            backup.step(&propagation, &c1, &mut rng);
            master.step(&propagation, &c2, &mut rng);
            c1_sum += c1;
            c2_sum += c2;
        }
        let (c1, c2) = (c1_sum / substeps as f64, c2_sum / substeps as f64);
        let t_mid = t0 + 0.5 * s.filter_step;
        let mid = [
            body * backup_scheme.orientation(t_mid),
            body * master_scheme.orientation(t_mid),
        ];
        reduced.predict(&motion, &c1, [&mid[0], &mid[1]], s.filter_step, &tuning);
        full.predict(
            &motion,
            [&c1, &c2],
            [&mid[0], &mid[1]],
            s.filter_step,
            &tuning,
        );
        // eq. 31-32: A_1 = F_r with the backup's orientation
        prediction.propagate(&transition(&reduced_dynamics(&motion, &c1), s.filter_step));
        let before = k < failure;
        if before {
            let d = backup.errors - master.errors;
            let z = DifferenceMeasurement {
                dv_east: d[DV_E],
                dv_north: d[DV_N],
                d_lat: d[D_LAT],
                d_lon: d[D_LON],
                velocity_variance: tuning.velocity_sigma.powi(2),
                position_variance: tuning.position_sigma.powi(2),
            };
            reduced.update(&z);
            full.update(&z);
        } else if k == failure {
            at_failure = [reduced.drift(), full.drift()];
        }
        inside_reduced.count(reduced.drift(), truth, before);
        inside_full.count(full.drift(), truth, before);

        let comp_r = compensated(&backup.errors, &prediction.predicted(reduced.drift().0));
        let comp_f = compensated(&backup.errors, &prediction.predicted(full.drift().0));
        let radii_now = [
            radial(&master.errors, rn, re_cos),
            radial(&backup.errors, rn, re_cos),
            radial(&comp_r, rn, re_cos),
            radial(&comp_f, rn, re_cos),
        ];
        if !before {
            for (m, r) in max.iter_mut().zip(radii_now) {
                *m = m.max(r);
            }
        }
        if (k + 1) % record_every == 0 || k + 1 == steps {
            let to_deg_h = 3600.0 / DEG;
            let (er, sr) = reduced.drift();
            let (ef, sf) = full.drift();
            let (bn, be) = north_east(&backup.errors, rn, re_cos);
            let nav_part = |drift: f64| {
                let mut p = NavErrors::zeros();
                p.copy_from(&prediction.predicted(drift).fixed_rows::<7>(0));
                north_east(&p, rn, re_cos)
            };
            let (pn, pe) = nav_part(er);
            let (dn, de) = nav_part(truth);
            history.push(Record {
                hour: (t0 + s.filter_step) / 3600.0,
                drift_error_reduced: (er - truth) * to_deg_h,
                drift_sigma_reduced: sr * to_deg_h,
                drift_error_full: (ef - truth) * to_deg_h,
                drift_sigma_full: sf * to_deg_h,
                backup_north: bn,
                backup_east: be,
                predicted_north: pn,
                predicted_east: pe,
                drift_north: dn,
                drift_east: de,
                radial_master: radii_now[0],
                radial_backup: radii_now[1],
                radial_compensated_reduced: radii_now[2],
                radial_compensated_full: radii_now[3],
            });
        }
    }
    if failure >= steps {
        at_failure = [reduced.drift(), full.drift()];
    }
    let to_deg_h = 3600.0 / DEG;
    let last = history.last().cloned();
    let end = |f: fn(&Record) -> f64| last.as_ref().map_or(f64::NAN, f);
    let filter_summary = |(e, sd): (f64, f64), inside: &Inside, micros: f64| FilterSummary {
        error_at_failure: (e - truth) * to_deg_h,
        sigma_at_failure: sd * to_deg_h,
        inside_3sigma_run: share(inside.run),
        inside_3sigma_before_failure: share(inside.before),
        micros_per_step: micros,
    };
    let summary = Summary {
        drift_true_deg_h: truth * to_deg_h,
        drift_sigma_bound: drift_sigma_bound(s) * to_deg_h,
        reduced: filter_summary(at_failure[0], &inside_reduced, micros_per_step(&reduced)),
        full: filter_summary(at_failure[1], &inside_full, micros_per_step(&full)),
        radial_master_end: end(|r| r.radial_master),
        radial_backup_end: end(|r| r.radial_backup),
        radial_compensated_reduced_end: end(|r| r.radial_compensated_reduced),
        radial_compensated_full_end: end(|r| r.radial_compensated_full),
        compensated_over_master: end(|r| r.radial_compensated_reduced / r.radial_master),
        radial_master_max: max[0],
        radial_backup_max: max[1],
        radial_compensated_reduced_max: max[2],
        reduced_minus_full: (at_failure[0].0 - at_failure[1].0) * to_deg_h,
        combined_sigma: at_failure[0].1.hypot(at_failure[1].1) * to_deg_h,
        steps,
        filter_step: s.filter_step,
    };
    Ok(Results { summary, history })
}
