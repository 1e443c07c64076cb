//! `host-sim study rins-probe`: the [RINS] paper's master/backup idea for
//! the probe (docs/redundant-rins.md, "The probe").
//! A reference heading (magnetic-MWD-like station azimuths, sigma ~0.5 deg)
//! is the master for the first K stations of a simulated lateral and is
//! then lost; the gyro probe is the backup. Each seeded run drives two
//! `Navigator`s through the same sensor stream from the same tie-in
//! ([`super::drilling_run`]'s): one never sees the reference, the other
//! gets `Navigator::aid_heading` at each of the first K stations, which
//! learns the azimuth drift through the filter's rate-bias states
//! (`mwd_core::aid_sources::HeadingReference`) and keeps compensating it
//! after the loss. Compared: the azimuth error at TD and whether the
//! reported sigma covers it, by gyro grade.
//!
//! Grades scale the SCC1300 gyro budget (`ImuNoise::scc1300`): white noise
//! (ARW), AR(4) coloured noise, bias instability and residual bias all
//! divided by the grade's factor. The probe's navigator keeps its SCC1300
//! budget (it is built in), so for better grades its sigmas are those of an
//! SCC1300 probe; the raw frame's gyro count (18 LSB per deg/s) stays too.

use super::drilling_coverage::Fraction;
use super::drilling_run::{raw, tie_in};
use super::stats::{percentile, rms};
use super::{Interruption, StudyRuns};
use crate::sim::{BuiltPlan, DrillState, Drilling, DrillingSimulator, SensorErrors, SensorModel};
use crate::survey::listing::drilling::azimuth_usable;
use anyhow::Result;
use mwd_core::conventions::{dcm_from_quat, wrap_pi, DrillingAngles};
use mwd_core::probe::navigator::MAX_STATION_SAMPLES;
use mwd_core::probe::station::{angle_uncertainty, angles_and_jacobian};
use mwd_core::probe::Navigator;
use mwd_core::protocol::StationSurvey;
use mwd_core::timing::SAMPLE_INTERVAL_S;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use serde::Serialize;

/// A gyro grade: the SCC1300's gyro errors divided by `factor`.
#[derive(Clone, Copy, Debug, Serialize, PartialEq)]
pub struct Grade {
    pub name: &'static str,
    pub factor: f64,
}

/// The named grades of the brief: the part itself, a tactical gyro
/// (ARW ~0.09 deg/sqrt(h), bias ~0.2 deg/h) and a navigation gyro
/// (ARW ~0.001 deg/sqrt(h), bias ~0.002 deg/h, the [RINS] paper's class).
pub const GRADES: [Grade; 3] = [
    Grade {
        name: "scc1300",
        factor: 1.0,
    },
    Grade {
        name: "tactical",
        factor: 10.0,
    },
    Grade {
        name: "navigation",
        factor: 1000.0,
    },
];

/// The SCC1300 model with its gyro errors divided by `factor` (> 0); with
/// `white_noise_kept` the white noise (ARW) stays the SCC1300's. A better
/// part is not the SCC1300 and has not its LSB: only the SCC1300 grade is
/// quantised at the sensor (the raw frame's count still is, 18 LSB per
/// deg/s: a quiet gyro at rest is rounded without dither, a bias of up to
/// half a count, 100 deg/h; the SCC1300's own noise, ~0.06 deg/s per
/// sample, dithers it, and so does `white_noise_kept`).
pub fn graded_model(seed: u64, factor: f64, white_noise_kept: bool) -> SensorModel {
    let mut model = SensorModel::scc1300(seed);
    for axis in &mut model.noise.gyro {
        if !white_noise_kept {
            axis.white_density /= factor;
        }
        axis.bias_instability /= factor;
        axis.residual_bias /= factor;
        if let Some(ar) = axis.coloured.as_mut() {
            ar.noise_variance /= factor * factor;
        }
    }
    model.quantize = factor == 1.0;
    model
}

/// What a run is given besides its seed.
#[derive(Clone, Debug)]
pub struct ProbeConfig {
    pub plan: BuiltPlan,
    /// 1-sigma of the parent well's azimuth at the tie-in (rad).
    pub tie_in_azimuth_sigma: f64,
    /// 1-sigma of each reference azimuth (rad).
    pub reference_sigma: f64,
    /// Stations (the window's first) that get a reference azimuth.
    pub reference_stations: usize,
    pub grade: Grade,
    /// Keep the SCC1300's white gyro noise (see [`graded_model`]).
    pub white_noise_kept: bool,
}

/// An azimuth against the truth.
#[derive(Clone, Copy, Debug, Serialize, PartialEq)]
pub struct AzimuthCheck {
    /// Computed minus true (rad, wrapped).
    pub error: f64,
    /// 1-sigma (rad); `None`: undetermined (flagged, or not finite).
    pub sigma: Option<f64>,
}

/// One run: both navigators at TD, and the aided one just after its last
/// reference update.
#[derive(Clone, Debug, Serialize)]
pub struct PairOutcome {
    pub seed: u64,
    /// `None` when that navigator's last station is not at TD.
    pub without: Option<AzimuthCheck>,
    pub with: Option<AzimuthCheck>,
    /// The aided navigator's azimuth after its last reference update.
    pub last_reference: Option<AzimuthCheck>,
    pub references_applied: usize,
    pub stations: usize,
}

fn station_check(survey: &StationSurvey, truth_azimuth: f64) -> AzimuthCheck {
    let sigma = f64::from(survey.angles_std[1]);
    let determined = azimuth_usable(survey);
    AzimuthCheck {
        error: wrap_pi(f64::from(survey.angles[1]) - truth_azimuth),
        sigma: determined.then_some(sigma),
    }
}

/// The navigator's azimuth now (its filter's attitude and covariance).
fn current_check(navigator: &Navigator, truth_azimuth: f64) -> AzimuthCheck {
    let filter = navigator.filter();
    let (angles, jacobian) = angles_and_jacobian(&dcm_from_quat(&filter.state().attitude));
    let sigma = angle_uncertainty(&jacobian, &filter.attitude_error_covariance()).sigma[1];
    AzimuthCheck {
        error: wrap_pi(angles.azimuth - truth_azimuth),
        sigma: sigma.is_finite().then_some(sigma),
    }
}

/// Runs seed `seed`: the drilling simulator (the grade's gyros), the
/// tie-in of `drilling_run`, both navigators.
pub fn run(config: &ProbeConfig, seed: u64) -> Result<PairOutcome> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x57D7_0000_0000_0017);
    let end_md = config.plan.end_md();
    let drilling = Drilling::new(config.plan.clone(), seed);
    let site = drilling.truth(0.0).position;
    let model = graded_model(seed, config.grade.factor, config.white_noise_kept);
    let calibration = model.deterministic.calibration();
    let mut without = Navigator::with_calibration(site, calibration);
    let mut with = Navigator::with_calibration(site, calibration);
    let mut tied = false;
    let mut last_surveys: [Option<StationSurvey>; 2] = [None, None];
    let mut with_stations = 0;
    let mut references_applied = 0;
    let mut last_reference = None;
    let mut stations = 0;
    let mut samples = 0;
    let mut last = None;
    let sim = DrillingSimulator::new(&drilling, model.clone(), SAMPLE_INTERVAL_S);
    for (index, d) in sim.enumerate() {
        let s = &d.sample;
        let frame = raw(index, &s.gyro, &s.accel)?;
        without.step(&frame);
        with.step(&frame);
        samples += 1;
        last = Some((
            s.true_rate,
            s.true_accel,
            d.truth.state == DrillState::Still,
        ));
        if !tied && without.is_navigating() && with.is_navigating() {
            let truth = DrillingAngles::from_euler(&d.truth.euler());
            let t = tie_in(&truth, config.tie_in_azimuth_sigma, &mut rng)?;
            without.start_from_tie_in(&t);
            with.start_from_tie_in(&t);
            tied = true;
            continue;
        }
        if let Some(st) = without.take_station() {
            last_surveys[0] = Some(st);
            stations += 1;
        }
        if let Some(st) = with.take_station() {
            last_surveys[1] = Some(st);
            with_stations += 1;
            if with_stations <= config.reference_stations {
                // the reference station's azimuth: the truth now (the
                // station has just ended) plus its error
                let truth = d.truth.point.azimuth;
                let drawn: f64 = StandardNormal.sample(&mut rng);
                let reference = truth + config.reference_sigma * drawn;
                if with
                    .aid_heading(reference, config.reference_sigma)
                    .is_some()
                {
                    references_applied += 1;
                    last_reference = Some(current_check(&with, truth));
                }
            }
        }
    }
    // As drilling_run: the run ends still at TD and the still goes on
    // (fresh noise, the last true means) until each navigator sends its
    // last station.
    if let Some((rate, accel, true)) = last {
        let mut tail = SensorErrors::new(SensorModel {
            seed: seed ^ 0x7A11_0000_0000_0001,
            ..model
        });
        let mut pending = [true, true];
        for k in 0..MAX_STATION_SAMPLES as usize {
            let (gyro, force) = tail.measure(SAMPLE_INTERVAL_S, &rate, &accel);
            let frame = raw(samples + k, &gyro, &force)?;
            for (i, navigator) in [&mut without, &mut with].into_iter().enumerate() {
                navigator.step(&frame);
                if let Some(st) = navigator.take_station() {
                    if pending[i] {
                        last_surveys[i] = Some(st);
                        stations += usize::from(i == 0);
                        pending[i] = false;
                    }
                }
            }
            if pending == [false, false] {
                break;
            }
        }
    }
    let at_td = |survey: &Option<StationSurvey>| {
        let st = survey.as_ref()?;
        let truth = drilling.truth((f64::from(st.end_sample) + 1.0) * SAMPLE_INTERVAL_S);
        ((truth.md - end_md).abs() <= 1.0).then(|| station_check(st, truth.point.azimuth))
    };
    Ok(PairOutcome {
        seed,
        without: at_td(&last_surveys[0]),
        with: at_td(&last_surveys[1]),
        last_reference,
        references_applied,
        stations,
    })
}

/// TD azimuths of one navigator over the runs.
#[derive(Clone, Debug, Default, Serialize)]
pub struct TdSummary {
    /// Runs whose last station is at TD.
    pub runs_at_td: usize,
    /// RMS and 95th percentile (nearest rank) of |error| (deg), over every
    /// run at TD whether its azimuth is flagged determined or not (the
    /// study's view of the number the navigator holds).
    pub rms_error_deg: Option<f64>,
    pub p95_abs_error_deg: Option<f64>,
    /// RMS of the reported sigma (deg) over the determined ones.
    pub rms_sigma_deg: Option<f64>,
    /// |error| <= 2 sigma, over the determined azimuths.
    pub within_2_sigma: Fraction,
    /// Flagged undetermined (no sigma): never counted as inside.
    pub undetermined: usize,
}

fn within(checks: &[AzimuthCheck], k: f64) -> Fraction {
    let determined: Vec<_> = checks
        .iter()
        .filter_map(|c| Some((c.error, c.sigma?)))
        .collect();
    let inside = determined.iter().filter(|(e, s)| e.abs() <= k * s).count();
    Fraction::of(inside, determined.len())
}

fn td_summary(checks: &[AzimuthCheck]) -> TdSummary {
    let errors: Vec<f64> = checks.iter().map(|c| c.error.abs().to_degrees()).collect();
    TdSummary {
        runs_at_td: checks.len(),
        rms_error_deg: rms(&errors),
        p95_abs_error_deg: percentile(&errors, 0.95),
        rms_sigma_deg: rms(&checks
            .iter()
            .filter_map(|c| c.sigma)
            .map(f64::to_degrees)
            .collect::<Vec<_>>()),
        within_2_sigma: within(checks, 2.0),
        undetermined: checks.iter().filter(|c| c.sigma.is_none()).count(),
    }
}

/// One grade's results.
#[derive(Clone, Debug, Serialize)]
pub struct GradeSummary {
    pub grade: Grade,
    pub runs: usize,
    pub failed_runs: Vec<String>,
    pub without_reference: TdSummary,
    pub with_reference: TdSummary,
    /// After the last reference update: sigma <= the reference's sigma,
    /// and |error| <= 3 sigma.
    pub last_reference_sigma_at_most_reference: Fraction,
    pub last_reference_within_3_sigma: Fraction,
    /// Set when the study was stopped (Ctrl-C) before this grade's last
    /// run: its figures are over the runs done.
    pub interrupted: Option<Interruption>,
    pub wall_s: f64,
}

fn summarise(
    grade: Grade,
    reference_sigma: f64,
    results: &[Result<PairOutcome, String>],
) -> GradeSummary {
    let ok: Vec<&PairOutcome> = results.iter().filter_map(|r| r.as_ref().ok()).collect();
    let without: Vec<AzimuthCheck> = ok.iter().filter_map(|o| o.without).collect();
    let with: Vec<AzimuthCheck> = ok.iter().filter_map(|o| o.with).collect();
    let last: Vec<AzimuthCheck> = ok.iter().filter_map(|o| o.last_reference).collect();
    let bounded = last
        .iter()
        .filter(|c| c.sigma.is_some_and(|s| s <= reference_sigma))
        .count();
    GradeSummary {
        grade,
        runs: results.len(),
        failed_runs: results
            .iter()
            .filter_map(|r| r.as_ref().err().cloned())
            .collect(),
        without_reference: td_summary(&without),
        with_reference: td_summary(&with),
        last_reference_sigma_at_most_reference: Fraction::of(bounded, last.len()),
        last_reference_within_3_sigma: within(&last, 3.0),
        interrupted: None,
        wall_s: 0.0,
    }
}

/// Runs the seeds of `runs` of `config` (on its threads; `progress` and
/// `stop` as there). Setting `stop` (Ctrl-C)
/// ends it early: the runs under way finish, and the summary is over the
/// runs done ([`GradeSummary::interrupted`]).
pub fn study(config: &ProbeConfig, runs: &StudyRuns) -> GradeSummary {
    let started = std::time::Instant::now();
    let results = runs.run(|seed| run(config, seed));
    let outcomes: Vec<_> = results.into_iter().map(|r| r.1).collect();
    let mut summary = summarise(config.grade, config.reference_sigma, &outcomes);
    summary.interrupted = Interruption::of(outcomes.len(), runs.runs);
    summary.wall_s = started.elapsed().as_secs_f64();
    summary
}

fn deg(v: Option<f64>) -> String {
    v.map_or_else(|| "undetermined".into(), |v| format!("{v:.3}"))
}

fn percent(f: &Fraction) -> String {
    f.text().unwrap_or_else(|| "undetermined (no cases)".into())
}

/// The terminal table: one row per grade and navigator.
pub fn table(summaries: &[GradeSummary]) -> String {
    let mut out = format!(
        "{:<11} {:<8} {:>5} {:>10} {:>10} {:>10} {:<24} {:>6}\n",
        "grade", "ref", "TD", "RMS deg", "p95 deg", "RMS sig", "within 2 sigma", "undet"
    );
    for s in summaries {
        for (label, t) in [
            ("without", &s.without_reference),
            ("with", &s.with_reference),
        ] {
            out += &format!(
                "{:<11} {:<8} {:>5} {:>10} {:>10} {:>10} {:<24} {:>6}\n",
                s.grade.name,
                label,
                t.runs_at_td,
                deg(t.rms_error_deg),
                deg(t.p95_abs_error_deg),
                deg(t.rms_sigma_deg),
                percent(&t.within_2_sigma),
                t.undetermined
            );
        }
        out += &format!(
            "{:<11} after the last reference: sigma <= reference {}, within 3 sigma {}; {} failed runs, {:.0} s\n",
            s.grade.name,
            percent(&s.last_reference_sigma_at_most_reference),
            percent(&s.last_reference_within_3_sigma),
            s.failed_runs.len(),
            s.wall_s
        );
        if let Some(i) = &s.interrupted {
            out += &format!(
                "{:<11} INTERRUPTED after {} of {} runs: its figures are over the runs done\n",
                s.grade.name, i.jobs_done, i.jobs
            );
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grades_divide_the_gyro_budget_only() {
        let base = graded_model(3, 1.0, false);
        let tactical = graded_model(3, 10.0, false);
        let kept = graded_model(3, 10.0, true);
        for (b, t) in base.noise.gyro.iter().zip(&tactical.noise.gyro) {
            assert!((t.white_density * 10.0 - b.white_density).abs() <= 1e-15);
            assert!((t.residual_bias * 10.0 - b.residual_bias).abs() <= 1e-15);
        }
        assert_eq!(base.noise.accel, tactical.noise.accel);
        assert_eq!(
            kept.noise.gyro[0].white_density,
            base.noise.gyro[0].white_density
        );
        assert_eq!(
            kept.noise.gyro[0].residual_bias,
            tactical.noise.gyro[0].residual_bias
        );
        assert!(base.quantize && !tactical.quantize);
    }
}
