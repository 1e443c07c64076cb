//! The lateral study's jobs ([`study`]): N seeded runs of each well
//! ([`crate::study::drilling_run`]: simulator, navigator, stations, survey,
//! TD check) for each gyro grade ([`crate::study::grade`]), one covariance
//! analysis per grade and well ([`super::covariance`]) and the sweep's
//! points, all in one pool over the cores; per grade and well the station
//! azimuth errors, the error growth along MD against the predicted sigmas,
//! the TD horizontal error against the predicted 1-sigma and 95 % ellipse,
//! and whether the requirement is met. Summaries are in
//! [`super::summary`], tables and CSV in [`super::table`].

use super::covariance::{
    agreement, predict, Agreement, CovariancePrediction, SweepGrid, SweepResult,
};
use super::summary::{summarise, GradeWellSummary};
use super::wells::Well;
use crate::study::drilling_run::{run, RunConfig, RunOutcome, Scalar};
use crate::study::grade::Grade;
use crate::study::owsg::OwsgPrediction;
use crate::study::{run_jobs_until, Interruption};
use anyhow::{bail, Context, Result};
use serde::Serialize;
use std::sync::atomic::AtomicBool;

/// What the study is given.
#[derive(Clone, Debug)]
pub struct StudyConfig {
    pub grades: Vec<Grade>,
    pub wells: Vec<Well>,
    /// Runs per grade and well: seeds first_seed, first_seed + 1, ...
    pub runs: usize,
    pub first_seed: u64,
    pub threads: usize,
    /// 1-sigma of the parent well's azimuth at the tie-in (rad).
    pub tie_in_azimuth_sigma: f64,
    /// The Monte Carlo runs (`false`: covariance analysis only).
    pub monte_carlo: bool,
    /// A sweep of the first grade's gyro bias and ARW on each well
    /// (covariance analysis).
    pub sweep: Option<SweepGrid>,
    /// The navigator's filter scalar in every run.
    pub scalar: Scalar,
}

/// A grade as the output lists it.
#[derive(Clone, Debug, Serialize)]
pub struct GradeInfo {
    #[serde(flatten)]
    pub file: crate::study::grade::GradeFile,
}

/// A well as the output lists it.
#[derive(Clone, Debug, Serialize)]
pub struct WellInfo {
    pub label: String,
    pub tie_on_md_m: f64,
    pub td_md_m: f64,
    pub lateral_length_m: f64,
    pub rop_m_per_h: f64,
    pub stand_length_m: f64,
    pub connection_still_s: f64,
    /// The still time's dwells, the toolface indexed between them (1:
    /// none, then left out of the output).
    #[serde(skip_serializing_if = "crate::sim::plan::is_single_dwell")]
    pub connection_dwells: u32,
    /// The hole's tortuosity (`drilling.tortuosity`).
    pub tortuosity: crate::sim::plan::Tortuosity,
}

/// The study's results.
#[derive(Clone, Debug, Serialize)]
pub struct LateralStudy {
    pub runs_per_grade_and_well: usize,
    pub first_seed: u64,
    pub threads: usize,
    pub tie_in_azimuth_sigma_deg: f64,
    /// The navigator's filter scalar.
    pub filter_scalar: Scalar,
    pub wall_s: f64,
    /// Set when the study was stopped (Ctrl-C) before its last job: every
    /// figure is then over the jobs done (each summary's `runs`).
    pub interrupted: Option<Interruption>,
    pub grades: Vec<GradeInfo>,
    pub wells: Vec<WellInfo>,
    /// One per grade and well, grade-major in the order given (empty
    /// without the Monte Carlo).
    pub summaries: Vec<GradeWellSummary>,
    /// Covariance analysis, one per grade and well, the same order.
    pub covariance: Vec<CovariancePrediction>,
    /// Covariance analysis against the Monte Carlo, the same order.
    pub agreement: Vec<Agreement>,
    /// The OWSG gyro models on each well (`owsg`), valid or not.
    pub owsg: Vec<WellOwsg>,
    /// The sweeps, one per well.
    pub sweeps: Vec<SweepResult>,
    pub errors: Vec<String>,
}

/// The OWSG gyro models' predictions on one well.
#[derive(Clone, Debug, Serialize)]
pub struct WellOwsg {
    pub well: String,
    pub models: Vec<OwsgPrediction>,
}

/// One job of the pool.
#[derive(Clone, Copy, Debug)]
enum Job {
    /// Config index, run index.
    MonteCarlo(usize, u64),
    Covariance(usize),
    /// Well index, bias index, ARW index.
    Sweep(usize, usize, usize),
}

/// What one job gave: a run, or a prediction (covariance analysis, sweep
/// point); the error text when it failed.
pub enum JobOutcome {
    Run(Result<RunOutcome, String>),
    Prediction(Result<CovariancePrediction, String>),
}

/// Runs the study; `progress` is called after each of the
/// grades x wells x runs jobs. Setting `stop` (Ctrl-C) ends it early: the
/// runs under way finish, and the study is over the jobs done
/// ([`LateralStudy::interrupted`]).
pub fn study(
    config: &StudyConfig,
    progress: &(dyn Fn() + Sync),
    stop: &AtomicBool,
) -> Result<LateralStudy> {
    let started = std::time::Instant::now();
    let plan = StudyJobs::new(config)?;
    let all: Vec<usize> = (0..plan.jobs.len()).collect();
    let outcomes = plan.run(&all, progress, stop);
    Ok(plan.assemble(outcomes, started.elapsed().as_secs_f64(), config.threads))
}

/// The study's jobs in their fixed order (longest wells first; the same
/// whatever the threads), the runs' configurations they share and the
/// sweep's grades: what a whole study or one shard of it runs.
pub struct StudyJobs<'a> {
    config: &'a StudyConfig,
    configs: Vec<RunConfig>,
    jobs: Vec<Job>,
    sweep_grades: Vec<Vec<Grade>>,
}

impl<'a> StudyJobs<'a> {
    pub fn new(config: &'a StudyConfig) -> Result<Self> {
        let mut configs = Vec::new();
        for grade in &config.grades {
            for well in &config.wells {
                configs.push(RunConfig {
                    scalar: config.scalar,
                    ..RunConfig::new(
                        well.plan.clone(),
                        config.tie_in_azimuth_sigma,
                        grade.clone(),
                    )?
                });
            }
        }
        let jobs = job_list(config, &configs)?;
        let sweep_grades = sweep_grades(config)?;
        Ok(Self {
            config,
            configs,
            jobs,
            sweep_grades,
        })
    }

    /// How many jobs the whole study has.
    pub fn len(&self) -> usize {
        self.jobs.len()
    }

    /// Never: a study without jobs is refused by [`Self::new`].
    pub fn is_empty(&self) -> bool {
        self.jobs.is_empty()
    }

    /// Whether job `index` is a Monte Carlo run (the rest are covariance
    /// analyses and sweep points, one run each).
    pub fn is_monte_carlo(&self, index: usize) -> bool {
        matches!(self.jobs.get(index), Some(Job::MonteCarlo(..)))
    }

    /// Runs the jobs of `selected` (indices into the study's jobs) on the
    /// configuration's threads; every other job, and those `stop` kept
    /// from starting, is `None`.
    pub fn run(
        &self,
        selected: &[usize],
        progress: &(dyn Fn() + Sync),
        stop: &AtomicBool,
    ) -> Vec<Option<JobOutcome>> {
        let config = self.config;
        let length = |c: usize| self.configs[c].plan.end_md() - self.configs[c].plan.tie_on.md();
        let ran = run_jobs_until(
            selected.len(),
            config.threads,
            progress,
            stop,
            |k| match self.jobs[selected[k]] {
                Job::MonteCarlo(c, r) => {
                    let seed = config.first_seed + r;
                    JobOutcome::Run(
                        run(&self.configs[c], seed).map_err(|e| format!("seed {seed}: {e:#}")),
                    )
                }
                Job::Covariance(c) => {
                    let (g, w) = (c / config.wells.len(), c % config.wells.len());
                    JobOutcome::Prediction(predict(
                        &self.configs[c],
                        &config.grades[g],
                        &config.wells[w].label,
                        length(c),
                        config.first_seed,
                    ))
                }
                Job::Sweep(w, i, j) => {
                    let grade = &self.sweep_grades[i][j];
                    JobOutcome::Prediction(predict(
                        &self.configs[w],
                        grade,
                        &config.wells[w].label,
                        length(w),
                        config.first_seed,
                    ))
                }
            },
        );
        let mut outcomes: Vec<Option<JobOutcome>> = (0..self.jobs.len()).map(|_| None).collect();
        for (&index, outcome) in selected.iter().zip(ran) {
            outcomes[index] = outcome;
        }
        outcomes
    }

    /// The study's results from every job's outcome (`None`: not run),
    /// `wall_s` and `threads` as they are reported.
    pub fn assemble(
        &self,
        outcomes: Vec<Option<JobOutcome>>,
        wall_s: f64,
        threads: usize,
    ) -> LateralStudy {
        let (config, configs, jobs) = (self.config, &self.configs, &self.jobs);
        let n = configs.len();
        let mut per_config: Vec<Vec<(u64, Result<RunOutcome, String>)>> =
            (0..n).map(|_| Vec::new()).collect();
        let mut covariance: Vec<Option<CovariancePrediction>> = vec![None; n];
        let mut sweeps: Vec<SweepResult> = Vec::new();
        let mut errors = Vec::new();
        if let Some(grid) = &config.sweep {
            let empty = vec![vec![None; grid.arw_deg_per_sqrt_h.len()]; grid.bias_deg_per_h.len()];
            for well in &config.wells {
                sweeps.push(SweepResult {
                    base_grade: config.grades[0].name().to_string(),
                    well: well.label.clone(),
                    grid: grid.clone(),
                    td_sigma_per_1000_m: empty.clone(),
                    azimuth_sigma_deg: empty.clone(),
                    failures: Vec::new(),
                });
            }
        }
        let interrupted = Interruption::of(outcomes.iter().flatten().count(), jobs.len());
        for (job, outcome) in jobs.iter().zip(outcomes) {
            let Some(outcome) = outcome else { continue };
            match (*job, outcome) {
                (Job::MonteCarlo(c, r), JobOutcome::Run(o)) => {
                    per_config[c].push((config.first_seed + r, o))
                }
                (Job::Covariance(c), JobOutcome::Prediction(p)) => match p {
                    Ok(p) => covariance[c] = Some(p),
                    Err(e) => errors.push(format!("covariance analysis: {e}")),
                },
                (Job::Sweep(w, i, j), JobOutcome::Prediction(p)) => match p {
                    Ok(p) => {
                        sweeps[w].td_sigma_per_1000_m[i][j] = p
                            .td_horizontal_1_sigma_m
                            .map(|v| v * 1000.0 / p.lateral_length_m);
                        sweeps[w].azimuth_sigma_deg[i][j] = p.rms_station_azimuth_sigma_deg;
                    }
                    Err(e) => sweeps[w].failures.push(e),
                },
                _ => errors.push("internal: a job's outcome of the wrong kind".into()),
            }
        }
        let mut summaries = Vec::new();
        if config.monte_carlo {
            for (c, mut results) in per_config.into_iter().enumerate() {
                results.sort_by_key(|r| r.0);
                let (grade, well) = (
                    &config.grades[c / config.wells.len()],
                    &config.wells[c % config.wells.len()],
                );
                summaries.push(summarise(
                    grade.name(),
                    &well.label,
                    well.lateral_length_m(),
                    &results,
                ));
            }
        }
        let covariance: Vec<CovariancePrediction> = covariance.into_iter().flatten().collect();
        let agreement_rows = summaries
            .iter()
            .filter_map(|m| {
                covariance
                    .iter()
                    .find(|c| c.grade == m.grade && c.well == m.well)
                    .map(|c| agreement(c, m))
            })
            .collect();
        let mut owsg = Vec::new();
        for well in &config.wells {
            let site = crate::study::owsg::study_site(well.plan.site.lat);
            match crate::study::owsg::predict_all(&well.plan, &site) {
                Ok(models) => owsg.push(WellOwsg {
                    well: well.label.clone(),
                    models,
                }),
                Err(e) => errors.push(format!("OWSG models on {}: {e:#}", well.label)),
            }
        }
        LateralStudy {
            runs_per_grade_and_well: if config.monte_carlo { config.runs } else { 0 },
            first_seed: config.first_seed,
            threads,
            tie_in_azimuth_sigma_deg: config.tie_in_azimuth_sigma.to_degrees(),
            filter_scalar: config.scalar,
            wall_s,
            interrupted,
            grades: config
                .grades
                .iter()
                .map(|g| GradeInfo {
                    file: g.file.clone(),
                })
                .collect(),
            wells: config
                .wells
                .iter()
                .map(|w| WellInfo {
                    label: w.label.clone(),
                    tie_on_md_m: w.plan.tie_on.md(),
                    td_md_m: w.plan.end_md(),
                    lateral_length_m: w.lateral_length_m(),
                    rop_m_per_h: w.plan.drilling.rop_m_per_h,
                    stand_length_m: w.plan.drilling.stand_length_m,
                    connection_still_s: w.plan.drilling.connection_still_s,
                    connection_dwells: w.plan.drilling.connection_dwells,
                    tortuosity: w.plan.drilling.tortuosity,
                })
                .collect(),
            summaries,
            covariance,
            agreement: agreement_rows,
            owsg,
            sweeps,
            errors,
        }
    }
}

/// Every job: the Monte Carlo runs, one covariance analysis per grade and
/// well, the sweep's points; the longest wells first (no long run left
/// alone at the end while the other cores idle).
fn job_list(config: &StudyConfig, configs: &[RunConfig]) -> Result<Vec<Job>> {
    // The covariance analyses first (one run each), so that a study
    // stopped early has them.
    let mut jobs: Vec<Job> = (0..configs.len()).map(Job::Covariance).collect();
    if config.monte_carlo {
        for c in 0..configs.len() {
            jobs.extend((0..config.runs as u64).map(|r| Job::MonteCarlo(c, r)));
        }
    }
    if let Some(grid) = &config.sweep {
        for w in 0..config.wells.len() {
            for i in 0..grid.bias_deg_per_h.len() {
                for j in 0..grid.arw_deg_per_sqrt_h.len() {
                    jobs.push(Job::Sweep(w, i, j));
                }
            }
        }
    }
    let length = |job: &Job| {
        let c = match *job {
            Job::MonteCarlo(c, _) | Job::Covariance(c) | Job::Sweep(c, _, _) => c,
        };
        configs[c].plan.end_md() - configs[c].plan.tie_on.md()
    };
    jobs.sort_by(|a, b| length(b).total_cmp(&length(a)));
    if jobs.is_empty() {
        bail!("nothing to do: no grade or no well");
    }
    Ok(jobs)
}

/// The sweep's grades: the first grade with each grid point's gyro bias
/// instability and ARW ([bias index][arw index]).
fn sweep_grades(config: &StudyConfig) -> Result<Vec<Vec<Grade>>> {
    let Some(grid) = &config.sweep else {
        return Ok(Vec::new());
    };
    let base = config.grades.first().context("a sweep needs a grade")?;
    grid.bias_deg_per_h
        .iter()
        .map(|&b| {
            grid.arw_deg_per_sqrt_h
                .iter()
                .map(|&a| base.with_gyro(b, a))
                .collect()
        })
        .collect()
}
