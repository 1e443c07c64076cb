//! `host-sim drill`: a survey while drilling, end to end, on a simulated
//! run: the job's plan drilled, the probe's capture and the depth log,
//! the capture surveyed as `survey CAPTURE --depth --job` does (positions,
//! ellipses, the bit), its outputs written, and a one-screen summary
//! against the simulation's truth (`host_sim::survey::simulated`).
use super::limits::number_in;
use anyhow::{Context, Result};
use host_sim::survey::job::Job;
use host_sim::survey::simulated::{SimulatedRun, SimulatedRunInputs};
use std::path::PathBuf;

/// The example job (`examples/lateral-100m/`), found from the source tree
/// this binary was built from.
const EXAMPLE_JOB: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../examples/lateral-100m/job.json"
);

fn confidence(text: &str) -> Result<f64, String> {
    let p = number_in(text, "the confidence", (0.5, 0.9999), "(probability)")?;
    Ok(p)
}

#[derive(clap::Args, Debug)]
pub struct Args {
    /// The job file: site, well names, plan, tie-in, calibration, survey
    /// tie-on and sensor-to-bit distance (paths relative to the job file).
    /// Default: the example lateral drilled out of a horizontal parent
    /// well (examples/lateral-100m/job.json).
    #[arg(long, value_name = "JOB.json")]
    pub job: Option<PathBuf>,
    /// Folder of the run's files (created if missing).
    #[arg(long, short = 'o', value_name = "DIR", default_value = "out/drill")]
    pub out: PathBuf,
    /// Seed of the simulation (the parts' random errors, the vibration).
    #[arg(long, default_value_t = 7)]
    pub seed: u64,
    /// Probability held by the ellipses (horizontal: 2-D normal;
    /// vertical: 1-D).
    #[arg(long, default_value_t = 0.95, value_parser = confidence)]
    pub confidence: f64,
    /// The hole's tortuosity: RMS of each component (build, walk) of its
    /// curvature's deviation from the plan, deg/30 m; 0 drills the plan
    /// exactly (default: the plan's, else 1 deg/100 ft;
    /// docs/drilling-simulation.md).
    #[arg(long = "tortuosity", value_name = "DEG_PER_30M", value_parser = super::study_lateral::tortuosity)]
    pub tortuosity_deg_per_30m: Option<f64>,
    /// The tortuosity's correlation length along MD, m (default: the
    /// plan's, else 10 m).
    #[arg(long = "tortuosity-length", value_name = "M", value_parser = super::study_lateral::tortuosity_length)]
    pub tortuosity_length_m: Option<f64>,
}

pub fn run(args: Args) -> Result<()> {
    let job_path = args.job.clone().unwrap_or_else(|| {
        // "/../" read as the folder it names, where it exists
        let example = PathBuf::from(EXAMPLE_JOB);
        std::fs::canonicalize(&example).unwrap_or(example)
    });
    let job = Job::load(&job_path).with_context(|| {
        if args.job.is_none() {
            "the example job ships with the source tree; give --job JOB.json elsewhere".into()
        } else {
            format!("--job {}", job_path.display())
        }
    })?;
    eprintln!(
        "drilling {} (job {}) ...",
        job.well.wellbore,
        job_path.display()
    );
    let run = SimulatedRun::run(&SimulatedRunInputs {
        job: &job,
        out_dir: &args.out,
        seed: args.seed,
        confidence: args.confidence,
        tortuosity_deg_per_30m: args.tortuosity_deg_per_30m,
        tortuosity_length_m: args.tortuosity_length_m,
    })?;
    out!("{}", run.survey.report(args.confidence));
    outln!();
    out!("{}", run.summary());
    outln!("files in {}:", args.out.display());
    for f in &run.files {
        let name = f.strip_prefix(&args.out).unwrap_or(f);
        outln!("  {}", name.display());
    }
    Ok(())
}
