//! One seeded run of the drilling-coverage study: a lateral simulated in
//! process (no files), the probe's `Navigator` driven through it from a
//! tie-in, its station surveys paired with the truth and surveyed as
//! `host-sim survey CAPTURE --depth` does ([`crate::survey::listing::drilling`]).
//! The gyro grade ([`super::grade`]) decides the sensors: the SCC1300 (the
//! default) reaches the navigator as the probe's raw frames, as today;
//! other gyros as calibrated SI samples (`Navigator::step_sample`) with
//! the navigator modelling their error budget.

use super::grade::Grade;
pub use super::run_checks::{PositionCheck, StationCheck, TdCheck};
use crate::formats::capture::raw_sample_from_body;
use crate::formats::depth_log::DepthLog;
use crate::sim::{
    BuiltPlan, DeterministicErrors, DrillState, Drilling, DrillingSimulator, SensorErrors,
    SensorModel,
};
use crate::survey::iscwsa::{ErrorTerm, Site};
use crate::survey::listing::drilling::{self, DrillingSurvey, StationStart};
use crate::survey::listing::{
    compute, AzimuthReference, InputStation, LengthUnit, StationFile, TieOnInput,
};
use crate::survey::stations::{StationCollector, SurveySetup};
use anyhow::{anyhow, Context, Result};
use mwd_core::calibration::ProbeCalibration;
use mwd_core::conventions::{wrap_pi, wrap_two_pi, DrillingAngles};
use mwd_core::probe::navigator::MAX_STATION_SAMPLES;
use mwd_core::probe::NavigatorScalar;
use mwd_core::probe::{Navigator, StationLink, TieIn};
use mwd_core::probe_sample::ProbeSample;
use mwd_core::protocol::{NavSolution, RawSample, StationSurvey};
use mwd_core::timing::{sample_time_us, SAMPLE_INTERVAL_S};
use nalgebra::Vector3;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use serde::{Deserialize, Serialize};

/// The scalar of the navigator's filter (`Navigator<T>`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum Scalar {
    /// The probe's: its M4F computes in f32 (the default of a run, which
    /// stands for the probe).
    #[default]
    F32,
    /// The same study figures (docs/lateral-study.md, "The host's
    /// speed"), about 1.8 times faster on x86 hosts.
    F64,
}

impl Scalar {
    /// "f32" or "f64", as the command line names it.
    pub fn name(self) -> &'static str {
        match self {
            Scalar::F32 => "f32",
            Scalar::F64 => "f64",
        }
    }
}

/// What a run is given besides its seed.
#[derive(Clone, Debug)]
pub struct RunConfig {
    pub plan: BuiltPlan,
    /// 1-sigma of the parent well's azimuth at the tie-in (rad).
    pub tie_in_azimuth_sigma: f64,
    /// Draw the depth log's scale and stretch per run from these 1-sigma
    /// (the tool model's DSFS, DSTG); `None`: the plan's values.
    pub depth_sigma: Option<(f64, f64)>,
    /// Run the navigator without the calibration that removes the
    /// simulated parts' deterministic errors (as the QEMU probe and
    /// `simulate`'s captures run); default: calibrated, as a probe in a
    /// well is (residual errors: the noise model's).
    pub uncalibrated: bool,
    /// Covariance analysis instead of a Monte Carlo draw: the same plan
    /// (and its seed's vibration and orienter steps) with error-free
    /// sensors, an error-free tie-in (sent with its sigmas) and depth log,
    /// so the navigator's and the survey's covariances are what it reports
    /// while its errors stay ~0 ([`covariance_analysis`]).
    pub noise_free: bool,
    pub terms: Vec<ErrorTerm>,
    pub site: Site,
    /// The gyros (`Grade::scc1300()`: the probe's part, today's run).
    pub grade: Grade,
    /// The navigator's filter scalar (default the probe's f32).
    pub scalar: Scalar,
}

impl RunConfig {
    /// A calibrated run of `plan` with `grade`: the depth log's scale and
    /// stretch drawn from the probe tool model's DSFS and DSTG, the survey
    /// with its terms ([`drilling::survey_terms`]) at the plan's latitude.
    pub fn new(plan: BuiltPlan, tie_in_azimuth_sigma: f64, grade: Grade) -> Result<Self> {
        let terms = drilling::survey_terms()?;
        let magnitude = |w: &str| {
            terms
                .iter()
                .find(|t| t.weighting == w)
                .map(|t| t.magnitude_si)
        };
        let depth_sigma = magnitude("DSF").zip(magnitude("DST"));
        let latitude = plan.site.lat;
        Ok(Self {
            plan,
            tie_in_azimuth_sigma,
            depth_sigma,
            uncalibrated: false,
            noise_free: false,
            terms,
            site: super::owsg::study_site(latitude),
            grade,
            scalar: Scalar::default(),
        })
    }
}

/// What one run gave.
#[derive(Clone, Debug)]
pub struct RunOutcome {
    pub seed: u64,
    pub stations: Vec<StationCheck>,
    /// `None`: the last station is not at TD or its position is
    /// undetermined (`td_note` says which).
    pub td: Option<TdCheck>,
    pub td_note: Option<String>,
    /// The survey method's own TD error, north and east (m): minimum
    /// curvature through the true MD and angles at the survey's stations
    /// against the drilled path's TD (the path changes its curvature
    /// between stations). No sensor is in it; the survey's XCLA and XCLH
    /// terms are its envelope.
    pub method_td_error_ne: Option<[f64; 2]>,
    /// Simulated samples, each one navigator epoch.
    pub samples: usize,
    /// Wall time of the run on its thread (s).
    pub elapsed_s: f64,
    /// CPU time of its thread (s), where the system tells it
    /// ([`thread_cpu_s`]): on a shared machine the wall time is not the
    /// work.
    pub cpu_s: Option<f64>,
    /// The probe ran without the calibration of its parts' deterministic
    /// errors ([`RunConfig::uncalibrated`] with parts that have them):
    /// every station is flagged "uncalibrated", as a capture's survey
    /// flags them (`SurveySetup::uncalibrated`).
    pub uncalibrated: bool,
}

#[cfg(test)]
impl RunOutcome {
    /// A run of `stations` alone, without a TD or timings: for the
    /// summaries' tests.
    pub(crate) fn of_stations(seed: u64, stations: Vec<StationCheck>) -> Self {
        Self {
            seed,
            stations,
            td: None,
            td_note: None,
            method_td_error_ne: None,
            samples: 0,
            elapsed_s: 0.0,
            cpu_s: None,
            uncalibrated: false,
        }
    }
}

impl RunOutcome {
    /// The survey method's own TD horizontal error (m).
    pub fn method_td_error_m(&self) -> Option<f64> {
        self.method_td_error_ne.map(|[n, e]| n.hypot(e))
    }

    /// Why the TD was not checked, by the reason's kind, not its numbers:
    /// the summaries count the runs by it.
    pub fn td_unchecked_kind(&self) -> String {
        let reason = self.td_note.as_deref().unwrap_or("unknown");
        if reason.starts_with("last station at MD") {
            "last station not at TD".to_string()
        } else {
            reason.split(':').next().unwrap_or("").to_string()
        }
    }
}

/// The runs of a study that gave an outcome, in seed order.
pub fn outcomes(
    results: &[(u64, Result<RunOutcome, String>)],
) -> impl Iterator<Item = &RunOutcome> {
    results.iter().filter_map(|(_, r)| r.as_ref().ok())
}

/// The errors of the runs of a study that failed, in seed order.
pub fn failures(results: &[(u64, Result<RunOutcome, String>)]) -> Vec<String> {
    results
        .iter()
        .filter_map(|(_, r)| r.as_ref().err().cloned())
        .collect()
}

/// The calling thread's CPU time so far (s): Linux's
/// `/proc/thread-self/schedstat` (its first field: ns on a CPU); `None`
/// elsewhere or when the kernel does not keep it.
pub fn thread_cpu_s() -> Option<f64> {
    let text = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    let ns: u64 = text.split_whitespace().next()?.parse().ok()?;
    Some(ns as f64 * 1e-9)
}

/// The parent well's survey at the window: its inclination is the
/// truth's plus an error drawn with [`TIE_IN_INCLINATION_SIGMA_DEG`], its
/// azimuth the truth's plus one drawn with `sigma_azi`; a survey gives no
/// toolface of the probe, so the toolface is sent with the largest sigma a
/// tie-in takes (3 deg, the truth plus an error drawn with it), which the
/// probe's own levelling outweighs. The navigator fuses inclination and
/// toolface with its levelling and takes the azimuth
/// (`Navigator::start_from_tie_in`).
pub(crate) fn tie_in(
    truth: &DrillingAngles,
    sigma_azi: f64,
    rng: &mut ChaCha8Rng,
) -> Result<TieIn> {
    let mut draw = |sigma: f64| -> f64 {
        let z: f64 = StandardNormal.sample(rng);
        sigma * z
    };
    let sigma = DrillingAngles {
        inclination: TIE_IN_INCLINATION_SIGMA_DEG.to_radians(),
        azimuth: sigma_azi,
        toolface: TIE_IN_TOOLFACE_SIGMA_DEG.to_radians(),
    };
    let angles = DrillingAngles {
        inclination: (truth.inclination + draw(sigma.inclination)).clamp(0.0, std::f64::consts::PI),
        azimuth: wrap_two_pi(truth.azimuth + draw(sigma.azimuth)),
        toolface: wrap_two_pi(truth.toolface + draw(sigma.toolface)),
    };
    TieIn::new(angles, sigma).map_err(|e| anyhow!("tie-in refused: {e:?}"))
}

/// The tie-in of the covariance analysis: the truth, sent with the sigmas
/// [`tie_in`] draws its errors with.
fn exact_tie_in(truth: &DrillingAngles, sigma_azi: f64) -> Result<TieIn> {
    let sigma = DrillingAngles {
        inclination: TIE_IN_INCLINATION_SIGMA_DEG.to_radians(),
        azimuth: sigma_azi,
        toolface: TIE_IN_TOOLFACE_SIGMA_DEG.to_radians(),
    };
    TieIn::new(*truth, sigma).map_err(|e| anyhow!("tie-in refused: {e:?}"))
}

/// Covariance analysis of `config`'s well and grade (the lateral study's
/// fast path): one run with error-free sensors ([`RunConfig::noise_free`]).
/// The filter is linear in its errors, so its covariance does not depend
/// on the noise drawn, only on the trajectory and the probe's decisions
/// (still or drilling, which the seed's vibration and orienter steps
/// drive); the stations' sigmas and the survey's TD covariance of this one
/// run are the prediction a Monte Carlo's spread is checked against.
pub fn covariance_analysis(config: &RunConfig, seed: u64) -> Result<RunOutcome> {
    let config = RunConfig {
        noise_free: true,
        ..config.clone()
    };
    run(&config, seed)
}

/// 1-sigma of the parent well's inclination at the window (deg): a
/// gyro or MWD survey's, ISCWSA MWD's inclination terms at a station.
pub const TIE_IN_INCLINATION_SIGMA_DEG: f64 = 0.1;
/// The toolface sigma sent with the tie-in (deg): the largest `TieIn`
/// takes; the parent well's survey says nothing of the probe's toolface.
pub const TIE_IN_TOOLFACE_SIGMA_DEG: f64 = 3.0;

/// The raw frame of sample `index` of measured body rates and force
/// ([`raw_sample_from_body`]).
pub(crate) fn raw(index: usize, gyro: &Vector3<f64>, accel: &Vector3<f64>) -> Result<RawSample> {
    let index = u32::try_from(index).context("more than 2^32 samples")?;
    Ok(raw_sample_from_body(index, gyro, accel))
}

/// One measured sample into the navigator: the probe's raw frame for the
/// SCC1300 part, else the calibrated sample at full resolution.
fn feed<T: NavigatorScalar>(
    navigator: &mut Navigator<T>,
    raw_frames: bool,
    index: usize,
    gyro: &Vector3<f64>,
    accel: &Vector3<f64>,
) -> Result<NavSolution> {
    Ok(if raw_frames {
        navigator.step(&raw(index, gyro, accel)?)
    } else {
        let n = u32::try_from(index).context("more than 2^32 samples")?;
        let sample = ProbeSample::new(gyro.x, gyro.z, *accel);
        navigator.step_sample(sample_time_us(n), n, &sample)
    })
}

/// The navigator's link for the station it just finished.
fn link_of<T: NavigatorScalar>(
    navigator: &Navigator<T>,
    station: &StationSurvey,
) -> Option<StationLink> {
    navigator
        .station_link()
        .filter(|l| l.station == station.station)
        .copied()
}

/// Runs seed `seed`, the navigator's filter in `config.scalar`.
pub fn run(config: &RunConfig, seed: u64) -> Result<RunOutcome> {
    match config.scalar {
        Scalar::F32 => run_in::<f32>(config, seed),
        Scalar::F64 => run_in::<f64>(config, seed),
    }
}

/// [`run`] with the navigator's filter in `T`.
fn run_in<T: NavigatorScalar>(config: &RunConfig, seed: u64) -> Result<RunOutcome> {
    let started = std::time::Instant::now();
    let cpu_start = thread_cpu_s();
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x57D7_0000_0000_0013);
    let mut plan = config.plan.clone();
    if config.noise_free {
        plan.drilling.depth_errors.scale_ppm = 0.0;
        plan.drilling.depth_errors.stretch_per_m = 0.0;
    } else if let Some((scale, stretch)) = config.depth_sigma {
        let a: f64 = StandardNormal.sample(&mut rng);
        let b: f64 = StandardNormal.sample(&mut rng);
        plan.drilling.depth_errors.scale_ppm = a * scale * 1e6;
        plan.drilling.depth_errors.stretch_per_m = b * stretch;
    }
    let tie_on = plan.tie_on;
    let end_md = plan.end_md();
    let drilling = Drilling::new(plan, seed);
    let site = drilling.truth(0.0).position;
    let model = if config.noise_free {
        SensorModel {
            seed,
            ..SensorModel::ideal()
        }
    } else {
        config.grade.sensor_model(seed)
    };
    // (error-free samples through the SCC1300's counts would be rounded
    // without the noise that dithers them: a bias of up to half a count)
    let raw_frames = config.grade.is_scc1300_part() && !config.noise_free;
    // the navigator sees the parts' deterministic errors uncorrected: its
    // station sigmas (the calibrated residual's) do not cover them
    let uncalibrated = config.uncalibrated && model.deterministic != DeterministicErrors::none();
    let calibration = if config.uncalibrated || !raw_frames {
        // other parts' samples come calibrated (`Grade::sensor_model`)
        ProbeCalibration::default()
    } else {
        model.deterministic.calibration()
    };
    let mut navigator = Navigator::<T>::calibrated(site, calibration);
    // the SCC1300's is the navigator's own static: unchanged
    navigator.set_noise_budget(config.grade.budget_ref());
    // the survey's chain in the links' states (`survey_error::link_chain`)
    navigator.track_station_links(true);
    let mut tied = false;
    // each station's azimuth sigma at its start, for the survey's chain
    let mut collected = StationCollector::default();
    // and the error of that solution's azimuth
    let mut err_before = Vec::new();
    let mut links = Vec::new();
    let mut samples = 0;
    let sim = DrillingSimulator::new(&drilling, model.clone(), SAMPLE_INTERVAL_S);
    // the last sample's true means and whether the run ends still
    let mut last: Option<(Vector3<f64>, Vector3<f64>, bool)> = None;
    for (index, d) in sim.enumerate() {
        let s = &d.sample;
        collected.push_solution(&feed(&mut navigator, raw_frames, index, &s.gyro, &s.accel)?);
        samples += 1;
        last = Some((
            s.true_rate,
            s.true_accel,
            d.truth.state == DrillState::Still,
        ));
        if !tied && navigator.is_navigating() {
            // levelled and still at the window: the tie-in replaces the
            // gyrocompass azimuth
            let truth = DrillingAngles::from_euler(&d.truth.euler());
            let t = if config.noise_free {
                exact_tie_in(&truth, config.tie_in_azimuth_sigma)?
            } else {
                tie_in(&truth, config.tie_in_azimuth_sigma, &mut rng)?
            };
            navigator.start_from_tie_in(&t);
            tied = true;
            continue;
        }
        if let Some(station) = navigator.take_station() {
            let start = collected.push_station(&station);
            err_before.push(start_error(start, &drilling));
            links.push(link_of(&navigator, &station));
        }
    }
    // The run ends still at TD, where the probe sends its station when the
    // string next moves or at its longest station: the still goes on (the
    // same true means, fresh sensor noise) until the station comes out.
    let run_samples = samples;
    if let Some((rate, accel, true)) = last {
        let mut tail = SensorErrors::new(SensorModel {
            seed: seed ^ 0x7A11_0000_0000_0001,
            ..model
        });
        for k in 0..MAX_STATION_SAMPLES as usize {
            let (gyro, force) = tail.measure(SAMPLE_INTERVAL_S, &rate, &accel);
            collected.push_solution(&feed(
                &mut navigator,
                raw_frames,
                run_samples + k,
                &gyro,
                &force,
            )?);
            samples += 1;
            if let Some(station) = navigator.take_station() {
                let start = collected.push_station(&station);
                err_before.push(start_error(start, &drilling));
                links.push(link_of(&navigator, &station));
                break;
            }
        }
    }
    let mut checks: Vec<StationCheck> = collected
        .stations()
        .iter()
        .zip(&collected.azimuth_sigma_before())
        .zip(&err_before)
        .zip(&links)
        .map(|(((st, before), err_before), link)| {
            let truth = drilling.truth((f64::from(st.end_sample) + 1.0) * SAMPLE_INTERVAL_S);
            let a = st.angles.map(f64::from);
            StationCheck {
                survey: *st,
                error: [
                    a[0] - truth.point.inclination,
                    wrap_pi(a[1] - truth.point.azimuth),
                    wrap_pi(a[2] - truth.toolface),
                ],
                truth_md: truth.md,
                azimuth_sigma_before: *before,
                azimuth_error_before: *err_before,
                link: *link,
                position: None,
            }
        })
        .collect();
    // the log goes on through the extended still, at the last MD
    let log: Vec<(f64, f64)> = drilling.depth_log().collect();
    let end = samples as f64 * SAMPLE_INTERVAL_S;
    let tail = log
        .last()
        .filter(|(t, _)| *t < end)
        .map(|&(_, md)| (end, md));
    let depth = DepthLog::new(log.into_iter().chain(tail))?;
    let tie = TieOnInput {
        md: Some(tie_on.md()),
        tvd: tie_on.nev().z,
        north: tie_on.nev().x,
        east: tie_on.nev().y,
        covariance: None,
    };
    let setup = SurveySetup {
        tie,
        terms: config.terms.clone(),
        site: config.site,
        sensor_to_bit_m: None,
        first_station: drilling::FIRST_STATION,
        uncalibrated,
        depth_gap_limit_s: drilling::DEPTH_GAP_LIMIT_S,
    };
    let survey = collected.survey(&links, &setup, &depth);
    let (td, td_note, method_td_error_ne) = match survey {
        Ok(survey) => {
            // the survey's stations: one superseded by a later one at the
            // same MD (an indexed connection's earlier dwells) is not one
            checks.retain(|c| {
                !survey.skipped.iter().any(|k| {
                    k.superseded_by.is_some() && k.survey.end_sample == c.survey.end_sample
                })
            });
            attach_positions(&mut checks, &survey, &drilling);
            let (td, note) = td_check(&survey, &drilling, end_md);
            let method = td.and(method_td_error(&survey, &drilling));
            (td, note, method)
        }
        Err(e) => (None, Some(format!("no survey: {e:#}")), None),
    };
    Ok(RunOutcome {
        seed,
        stations: checks,
        td,
        td_note,
        method_td_error_ne,
        samples,
        elapsed_s: started.elapsed().as_secs_f64(),
        cpu_s: cpu_start.zip(thread_cpu_s()).map(|(a, b)| b - a),
        uncalibrated,
    })
}

/// The azimuth error of a station's start (`StationCollector::push_station`):
/// azimuth sigma and the error of the same solution's azimuth against the
/// truth at that solution's time (rad, wrapped; `None` if not finite).
fn start_error(start: Option<StationStart>, drilling: &Drilling) -> Option<f64> {
    let start = start?;
    let truth = drilling.truth((f64::from(start.sample_counter) + 1.0) * SAMPLE_INTERVAL_S);
    let error = wrap_pi(start.azimuth - truth.point.azimuth);
    error.is_finite().then_some(error)
}

/// Minimum curvature through the true MD and angles at the survey's
/// stations from the true tie-on position, less the drilled path's
/// position at its last station: north and east (m).
fn method_td_error(survey: &DrillingSurvey, drilling: &Drilling) -> Option<[f64; 2]> {
    let truths: Vec<_> = survey
        .rows
        .iter()
        .map(|r| drilling.truth((f64::from(r.survey.end_sample) + 1.0) * SAMPLE_INTERVAL_S))
        .collect();
    let (first, last) = (truths.first()?, truths.last()?);
    let file = StationFile {
        unit: LengthUnit::Metre,
        stations: truths
            .iter()
            .map(|t| InputStation {
                md: t.md,
                inc_deg: t.point.inclination.to_degrees(),
                azi_deg: wrap_two_pi(t.point.azimuth).to_degrees(),
                toolface_deg: None,
                time_s: None,
            })
            .collect(),
    };
    let tie = TieOnInput {
        md: None,
        tvd: first.point.nev.z,
        north: first.point.nev.x,
        east: first.point.nev.y,
        covariance: None,
    };
    let (rows, _) = compute(&file, AzimuthReference::True, tie, None).ok()?;
    let end = rows.last()?;
    Some([
        end.north_m - last.point.nev.x,
        end.east_m - last.point.nev.y,
    ])
}

/// The NE covariance of a survey row (north-north, east-east, north-east)
/// and the survey method's part of it, if its position is determined.
fn cov_ne(row: &drilling::DrillingRow) -> Option<([f64; 3], [f64; 3])> {
    let ne = |c: [f64; 6]| [c[0], c[1], c[3]];
    let total = row.row.cov.filter(|_| row.position_determined)?;
    Some((ne(total), ne(row.method_cov?)))
}

/// Each surveyed station's position against the truth at its last still
/// sample (the station the survey row is made of: same end sample).
fn attach_positions(checks: &mut [StationCheck], survey: &DrillingSurvey, drilling: &Drilling) {
    for row in &survey.rows {
        let Some((cov, _)) = cov_ne(row) else {
            continue;
        };
        let Some(check) = checks
            .iter_mut()
            .find(|c| c.survey.end_sample == row.survey.end_sample)
        else {
            continue;
        };
        let truth = drilling.truth((f64::from(row.survey.end_sample) + 1.0) * SAMPLE_INTERVAL_S);
        check.position = Some(PositionCheck {
            error_ne: [
                row.row.north_m - truth.point.nev.x,
                row.row.east_m - truth.point.nev.y,
            ],
            cov_ne: cov,
        });
    }
}

/// The last surveyed station against the truth, if it is at TD (within
/// 1 m) and positioned.
fn td_check(
    survey: &DrillingSurvey,
    drilling: &Drilling,
    end_md: f64,
) -> (Option<TdCheck>, Option<String>) {
    let Some(last) = survey.rows.last() else {
        return (None, Some("no station".into()));
    };
    let truth = drilling.truth((f64::from(last.survey.end_sample) + 1.0) * SAMPLE_INTERVAL_S);
    if (truth.md - end_md).abs() > 1.0 {
        return (
            None,
            Some(format!("last station at MD {:.1} m, not at TD", truth.md)),
        );
    }
    let Some((c, method_c)) = cov_ne(last) else {
        return (None, Some("TD position undetermined".into()));
    };
    let position = PositionCheck {
        error_ne: [
            last.row.north_m - truth.point.nev.x,
            last.row.east_m - truth.point.nev.y,
        ],
        cov_ne: c,
    };
    let Some(d2) = position.mahalanobis2() else {
        return (None, Some("TD covariance singular".into()));
    };
    (
        Some(TdCheck {
            error_ne: position.error_ne,
            d2,
            cov_ne: c,
            method_cov_ne: method_c,
        }),
        None,
    )
}
