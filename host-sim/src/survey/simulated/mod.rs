//! A survey while drilling, end to end, on a simulated run (`host-sim
//! drill`): the job's plan drilled by the probe's simulated parts, the
//! probe's capture and the surface depth log written as a real run leaves
//! them, the capture surveyed exactly as `survey CAPTURE --depth --job`
//! surveys it (its replay through the probe's navigator gives the station
//! links; the bit projected from the last station), its outputs written,
//! and the survey checked against the simulation's truth: each station,
//! the last station and the bit at TD inside their ellipses or not
//! ([`truth`]).
//!
//! The simulated parts carry the SCC1300's deterministic errors (the MGWD
//! paper's Table 3) and their random errors; the probe corrects them with
//! the job's calibration file (a six-position calibration's estimate, so
//! its residual is real), or runs uncalibrated if the job has none.

pub mod truth;

use crate::formats::files::write_text;
use crate::sim::outputs::{drill, write_samples, LateralOutputs, SampleSink};
use crate::sim::{Drilling, Plan, SensorModel};
use crate::survey::capture::{CaptureSurvey, CaptureSurveyInputs, ProbeSetup};
use crate::survey::job::Job;
use crate::survey::outputs::{write_outputs, OutputPaths};
use crate::survey::stations::job_tie_on;
use anyhow::{bail, Context, Result};
use mwd_core::config::default_still_settings;
use nalgebra::{Matrix3, Vector3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use std::path::{Path, PathBuf};
use truth::TruthChecks;

/// What one simulated run needs.
#[derive(Clone, Debug)]
pub struct SimulatedRunInputs<'a> {
    /// The job (with its plan).
    pub job: &'a Job,
    /// Where the run's files go (created if missing).
    pub out_dir: &'a Path,
    /// The simulation's seed (the parts' random errors, the vibration).
    pub seed: u64,
    /// Probability held by the ellipses.
    pub confidence: f64,
    /// The hole's tortuosity instead of the plan's: RMS (deg/30 m) and
    /// correlation length (m), each optional.
    pub tortuosity_deg_per_30m: Option<f64>,
    pub tortuosity_length_m: Option<f64>,
}

/// The run: its survey, the truth checks and the files written.
pub struct SimulatedRun {
    pub survey: CaptureSurvey,
    pub checks: TruthChecks,
    /// Every file written, in order.
    pub files: Vec<PathBuf>,
    /// One line: what was drilled.
    pub drilled: String,
}

impl SimulatedRun {
    /// Drills the plan, writes the capture, depth log and truth, surveys
    /// the capture and writes the survey's outputs.
    pub fn run(inputs: &SimulatedRunInputs) -> Result<Self> {
        let job = inputs.job;
        let Some(plan_path) = &job.plan else {
            bail!("the job names no plan (\"plan\": a well plan file, relative to the job file)");
        };
        let mut plan = Plan::read(plan_path)?;
        let parent_error = parent_survey_error(job, inputs.seed);
        if let Some(e) = parent_error {
            // the job's tie-on is the parent well's survey; the well is
            // where that survey is off by `e`
            plan.tie_on.north_m -= e[0];
            plan.tie_on.east_m -= e[1];
            plan.tie_on.tvd_m -= e[2];
        }
        plan.drilling.tortuosity = plan
            .drilling
            .tortuosity
            .overridden(inputs.tortuosity_deg_per_30m, inputs.tortuosity_length_m);
        let plan = plan
            .build()
            .with_context(|| format!("{}: invalid plan", plan_path.display()))?;
        check_site(job, &plan.site, plan_path)?;
        let out = inputs.out_dir;
        std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
        let files = RunFiles::in_dir(out);
        let drilling = Drilling::new(plan, inputs.seed);
        let drilled = simulate(&drilling, job, inputs.seed, &files)?;
        let tie = job_tie_on(Some(job));
        let survey = CaptureSurvey::run(&CaptureSurveyInputs {
            capture: files.capture.clone(),
            depth: files.depth.clone(),
            tie,
            latitude: job.site.lat,
            probe: probe_setup(job),
            sensor_to_bit_m: job
                .survey
                .sensor_to_bit
                .map(|d| d * job.survey.tie_on.unit.to_m()),
            depth_gap_limit_s: crate::survey::listing::drilling::DEPTH_GAP_LIMIT_S,
        })?;
        let checks = TruthChecks::new(&survey.survey, &drilling, inputs.confidence);
        let mut drilled = drilled;
        if let Some(e) = parent_error {
            drilled += &format!(
                "\nthe job's tie-on, the parent well's survey, is off the well's true position \
                 there by N {:+.2} m, E {:+.2} m, TVD {:+.2} m (drawn from its covariance)",
                e[0], e[1], e[2]
            );
        }
        let mut written = files.simulation();
        written.extend(write_survey(&survey, job, &files, inputs.confidence)?);
        Ok(Self {
            survey,
            checks,
            files: written,
            drilled,
        })
    }

    /// The one-screen summary: what was drilled, the stations, TD and the
    /// bit with their ellipses against the truth.
    pub fn summary(&self) -> String {
        let mut text = format!("{}\n", self.drilled);
        text += &self.checks.summary();
        let rows = &self.survey.survey.rows;
        let checked: Vec<_> = rows.iter().filter_map(|r| r.qc).collect();
        if !checked.is_empty() || rows.is_empty() {
            let out = checked.iter().filter(|q| !q.ok()).count();
            text += &format!(
                "station QC (gravity and earth rate against the site): {out} of {} stations out \
                 of tolerance{}\n",
                checked.len(),
                if rows.len() > checked.len() {
                    format!(", {} not checked", rows.len() - checked.len())
                } else {
                    String::new()
                }
            );
        }
        text
    }
}

/// The files of a run, in its folder.
struct RunFiles {
    capture: PathBuf,
    depth: PathBuf,
    truth: PathBuf,
    stations: PathBuf,
    json: PathBuf,
    witsml: PathBuf,
    listing: PathBuf,
    dir: PathBuf,
}

impl RunFiles {
    fn in_dir(dir: &Path) -> Self {
        Self {
            capture: dir.join("capture.bin"),
            depth: dir.join("depth.csv"),
            truth: dir.join("truth.csv"),
            stations: dir.join("stations.csv"),
            json: dir.join("survey.json"),
            witsml: dir.join("trajectory.xml"),
            listing: dir.join("listing.txt"),
            dir: dir.to_path_buf(),
        }
    }

    /// What the simulation wrote.
    fn simulation(&self) -> Vec<PathBuf> {
        vec![self.capture.clone(), self.depth.clone(), self.truth.clone()]
    }
}

/// The probe as the job configures it (`probe configure`): site,
/// calibration, still settings, tie-in.
fn probe_setup(job: &Job) -> ProbeSetup {
    ProbeSetup {
        site: job.site,
        calibration: job
            .calibration
            .as_ref()
            .map_or_else(Default::default, |(_, c)| *c),
        still: job.still.unwrap_or_else(default_still_settings),
        tie_in: job.tie_in,
    }
}

/// The probe configured by the job is where the plan is: the job's site is
/// the plan's (the navigator's earth rate and gravity are the site's).
fn check_site(job: &Job, plan_site: &mwd_core::earth::Position, plan_path: &Path) -> Result<()> {
    let (a, b) = (job.site, *plan_site);
    let close = (a.lat - b.lat).abs() < 1e-9 && (a.lon - b.lon).abs() < 1e-9;
    if !(close && (a.height - b.height).abs() < 1e-3) {
        bail!(
            "the job's site differs from the plan's ({}): the probe must be configured for \
             the place it drills",
            plan_path.display()
        );
    }
    Ok(())
}

/// The parent well survey's error at the tie-on (north, east, TVD, m),
/// drawn from the job's tie-on covariance when it has one: the job's
/// tie-on is where the parent's survey places the window, and the
/// simulated well starts where the window truly is.
fn parent_survey_error(job: &Job, seed: u64) -> Option<[f64; 3]> {
    let c = job_tie_on(Some(job)).covariance?;
    let m = crate::survey::iscwsa::cov_matrix(&c);
    // a square root by the eigenvectors: the job's covariance may be
    // singular (a sigma of 0), where Cholesky fails
    let eigen = m.symmetric_eigen();
    let root =
        eigen.eigenvectors * Matrix3::from_diagonal(&eigen.eigenvalues.map(|v| v.max(0.0).sqrt()));
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x7E0E_0000_0000_0043);
    let z = Vector3::from_fn(|_, _| StandardNormal.sample(&mut rng));
    let e = root * z;
    Some([e.x, e.y, e.z])
}

/// Drills the plan with the SCC1300's simulated parts: the capture (a
/// probe configured with the job's site and tie-in), the depth log and the
/// truth (one row a second). Returns what was drilled, as a line.
fn simulate(drilling: &Drilling, job: &Job, seed: u64, files: &RunFiles) -> Result<String> {
    let outputs = LateralOutputs {
        truth: Some(&files.truth),
        truth_every: 20,
        sensor_stream: None,
        depth_log: Some(&files.depth),
    };
    let sink = SampleSink::Capture {
        path: &files.capture,
        probe: probe_setup(job),
    };
    let over = drill(drilling, SensorModel::scc1300(seed), &outputs, |samples| {
        write_samples(sink, samples).map(drop)
    })?;
    let plan = drilling.plan();
    let mut line = format!(
        "drilled MD {:.2} -> {:.2} m in {:.2} h ({} connections), seed {seed}; the probe {}",
        plan.start_md(),
        plan.end_md(),
        drilling.duration() / 3600.0,
        drilling.connections().len(),
        match &job.calibration {
            Some((path, _)) => format!("calibrated by {}", path.display()),
            None => "uncalibrated (the job has no calibration file)".into(),
        }
    );
    if over.accel + over.gyro > 0 {
        line += &format!(
            "; {} samples beyond the accelerometers' range, {} beyond the gyros'",
            over.accel, over.gyro
        );
    }
    Ok(line)
}

/// The survey's outputs: the stations CSV (with the bit), the listing, the
/// JSON, the WITSML trajectory and the plan and section figures.
fn write_survey(
    survey: &CaptureSurvey,
    job: &Job,
    files: &RunFiles,
    confidence: f64,
) -> Result<Vec<PathBuf>> {
    write_text(&files.stations, &survey.stations_csv(confidence))?;
    write_text(&files.listing, &survey.report(confidence))?;
    let mut exported = survey.well_survey(confidence, None)?;
    exported.well = job.well.clone();
    let paths = OutputPaths {
        csv: None,
        json: Some(&files.json),
        witsml: Some(&files.witsml),
        plot: Some(&files.dir),
    };
    let figures = write_outputs(&exported, &paths, &job.well.wellbore)?;
    let mut written = vec![
        files.stations.clone(),
        files.listing.clone(),
        files.json.clone(),
        files.witsml.clone(),
    ];
    written.extend(figures);
    Ok(written)
}
