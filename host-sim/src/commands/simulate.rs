//! `host-sim simulate`: a trajectory through the probe's sensor model,
//! written as a sample CSV, or as the bytes the probe would send (`.bin`).
use anyhow::{Context, Result};
use clap::ValueEnum;
use host_sim::analysis::calibration_file::CalibrationFile;
use host_sim::formats::capture::ProbeSetup;
use host_sim::sim::outputs::{drill, write_samples, LateralOutputs, SampleSink};
use host_sim::sim::plan::Vibration;
use host_sim::sim::{
    DeterministicErrors, Drilling, Motion, Plan, SensorModel, SensorModelFile, SensorSimulator,
    Trajectory,
};
use host_sim::survey::job::Job;
use mwd_core::conventions::DEG;
use mwd_core::earth::Position;
use mwd_core::probe::TieIn;
use mwd_core::timing::SAMPLE_INTERVAL_S;
use nalgebra::Vector3;
use std::path::PathBuf;

use super::limits::{self, BodyRate};
use super::site::{AttitudeArgs, SiteArgs};

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum MotionKind {
    /// At rest.
    Static,
    /// Toolface indexing: dwell, turn about the tool axis, dwell...
    Toolface,
    /// Constant body rate relative to the earth.
    Rotate,
    /// Six-position calibration tumble (--dwell s per position); the CSV
    /// gets the `position` column `host-sim calibrate` reads.
    SixPosition,
    /// Drilling a lateral along a well plan (--plan FILE; see
    /// docs/drilling-simulation.md): the run lasts as the plan takes.
    Lateral,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum SensorKind {
    /// SCC1300-D04 with the paper's error figures.
    Scc1300,
    /// A perfect probe (no errors, no quantisation).
    Ideal,
}

/// Where and how the probe sits and moves (shared with `demo`).
#[derive(clap::Args, Debug, Clone)]
pub struct TrajectoryArgs {
    #[command(flatten)]
    pub attitude: AttitudeArgs,
    #[command(flatten)]
    pub site: SiteArgs,
    #[arg(long, value_enum, default_value_t = MotionKind::Static)]
    pub motion: MotionKind,
    /// Toolface indexing: turn per step, degrees.
    #[arg(long, default_value_t = 180.0, allow_hyphen_values = true)]
    pub step: f64,
    /// Toolface indexing / six-position: time at rest at each position, seconds.
    #[arg(long, default_value_t = 30.0, value_parser = limits::duration_s)]
    pub dwell: f64,
    /// Toolface indexing: number of turns.
    #[arg(long, default_value_t = 1)]
    pub steps: usize,
    /// Toolface indexing: turn rate, degrees per second.
    #[arg(long, default_value_t = 30.0)]
    pub turn_rate: f64,
    /// Constant rotation: body rate x,y,z in degrees per second.
    #[arg(long, value_name = "X,Y,Z", default_value_t = BodyRate([0.0, 1.0, 0.0]),
          value_parser = BodyRate::parse, allow_hyphen_values = true)]
    pub body_rate: BodyRate,
}

impl TrajectoryArgs {
    pub fn trajectory(&self) -> Trajectory {
        let motion = match self.motion {
            MotionKind::Static => Motion::Static,
            MotionKind::Toolface => Motion::ToolfaceSteps {
                step: self.step * DEG,
                turn_rate: self.turn_rate * DEG,
                dwell: self.dwell,
                steps: self.steps,
            },
            MotionKind::SixPosition => Motion::SixPosition { dwell: self.dwell },
            // The drilling simulator has its own trajectory (`run`); a
            // command that only knows scripted motions sees the tool at rest.
            MotionKind::Lateral => Motion::Static,
            MotionKind::Rotate => {
                let r = |i: usize| self.body_rate.get(i).copied().unwrap_or(0.0) * DEG;
                Motion::ConstantRate {
                    body_rate: Vector3::new(r(0), r(1), r(2)),
                }
            }
        };
        Trajectory {
            position: self.site.position(),
            start: self.attitude.euler(),
            motion,
        }
    }
}

#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    pub trajectory: TrajectoryArgs,
    /// Length of the run, seconds (toolface indexing: at least its script;
    /// --motion lateral: the plan sets it and this is not used).
    #[arg(long, default_value_t = 60.0, value_parser = limits::duration_s)]
    pub duration: f64,
    #[arg(long, value_enum, default_value_t = SensorKind::Scc1300)]
    pub sensor: SensorKind,
    /// Sensor model JSON in datasheet units (overrides --sensor); see
    /// --print-sensor-model for the defaults.
    #[arg(long)]
    pub sensor_model: Option<PathBuf>,
    /// Calibration JSON (as `host-sim calibrate` writes): the simulated
    /// probe gets exactly the deterministic errors it describes.
    #[arg(long)]
    pub calibration_file: Option<PathBuf>,
    /// Print the default SCC1300 sensor model as JSON and exit.
    #[arg(long)]
    pub print_sensor_model: bool,
    /// Seed of the sensor noise.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Output file (`-` for standard output, CSV only).
    #[arg(short, long, default_value = "simulated.csv")]
    pub output: PathBuf,
    /// Output format; by default `bin` for a `.bin` output, else `csv`.
    #[arg(long, value_enum)]
    pub format: Option<OutputFormat>,
    /// --motion lateral: the well plan (JSON, docs/drilling-simulation.md).
    #[arg(long)]
    pub plan: Option<PathBuf>,
    /// --motion lateral: write the truth trajectory (CSV) here.
    #[arg(long)]
    pub truth: Option<PathBuf>,
    /// --motion lateral: one truth row every N samples (20 = 1 s).
    #[arg(long, default_value_t = 20, value_parser = clap::value_parser!(u32).range(1..=72_000))]
    pub truth_every: u32,
    /// --motion lateral: write the surface depth log (CSV: time_s, md_m,
    /// with the plan's depth errors) here.
    #[arg(long)]
    pub depth_log: Option<PathBuf>,
    /// --motion lateral: vibration level instead of the plan's.
    #[arg(long, value_enum)]
    pub vibration: Option<VibrationLevel>,
    /// --motion lateral: also write the probe's physical input stream here
    /// (what each part senses in its own axes, sensor errors applied; the
    /// QEMU probe's `qemu-drilling` build reads it; format in
    /// `hil_mock::stream`).
    #[arg(long, value_name = "FILE")]
    pub sensor_stream: Option<PathBuf>,
    /// A .bin capture from a probe configured with this job's tie-in (its
    /// `tie_in` only; host-sim/src/job.rs), which its navigator takes as
    /// the probe does, after its first navigating cycle: the capture
    /// `survey CAPTURE --depth --job JOB.json` replays with the same job.
    #[arg(long, value_name = "JOB.json")]
    pub tie_in_job: Option<PathBuf>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum VibrationLevel {
    /// None at all.
    None,
    /// The default: 2 g RMS lateral, 1 g axial over 5-500 Hz, 6 shocks/h.
    Moderate,
    /// The paper's environment: 15 g RMS over 5-500 Hz, 60 shocks/h of 100 g.
    Harsh,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum OutputFormat {
    /// Sample CSV in SI units with the truth (what `align` reads).
    Csv,
    /// The bytes the probe would send over its UART: raw-sample frames
    /// (`docs/protocol.md`), quantised to sensor counts.
    Bin,
}

pub fn run(args: Args) -> Result<()> {
    if args.print_sensor_model {
        let file = SensorModelFile::from_model(&SensorModel::scc1300(args.seed));
        outln!("{}", serde_json::to_string_pretty(&file)?);
        return Ok(());
    }
    if matches!(args.trajectory.motion, MotionKind::Lateral) {
        return run_lateral(&args);
    }
    for (flag, given) in [
        ("--plan", args.plan.is_some()),
        ("--truth", args.truth.is_some()),
        ("--depth-log", args.depth_log.is_some()),
        ("--vibration", args.vibration.is_some()),
        ("--sensor-stream", args.sensor_stream.is_some()),
    ] {
        anyhow::ensure!(!given, "{flag} goes with --motion lateral");
    }
    let trajectory = args.trajectory.trajectory();
    let site = trajectory.position;
    let duration = args.duration.max(trajectory.scripted_duration());
    anyhow::ensure!(
        duration.is_finite() && duration > 0.0,
        "duration must be positive"
    );
    let model = sensor_model(&args)?;
    let n = (duration / SAMPLE_INTERVAL_S).round() as usize;
    let samples = SensorSimulator::new(trajectory, model, SAMPLE_INTERVAL_S).take(n);
    let sink = sample_sink(&args, site)?;
    let bytes = write_samples(sink, samples)?;
    let output = args.output.display();
    match sink {
        SampleSink::Capture { .. } => eprintln!(
            "wrote a boot event and {n} raw-sample and navigation frames ({bytes} bytes) to {output}"
        ),
        SampleSink::Csv(_) => {
            eprintln!("wrote {n} samples ({duration} s at 20 Hz) to {output}")
        }
        SampleSink::Stdout => {}
    }
    Ok(())
}

/// The simulated probe: `--sensor` or `--sensor-model`, with the
/// deterministic errors of `--calibration-file` when given.
fn sensor_model(args: &Args) -> Result<SensorModel> {
    let mut model = match (&args.sensor_model, args.sensor) {
        (Some(path), _) => SensorModelFile::load(path, args.seed)?,
        (None, SensorKind::Scc1300) => SensorModel::scc1300(args.seed),
        (None, SensorKind::Ideal) => SensorModel::ideal(),
    };
    if let Some(path) = &args.calibration_file {
        let cal = CalibrationFile::load(path)?.to_probe();
        model.deterministic = DeterministicErrors::from_calibration(&cal).with_context(|| {
            format!(
                "{}: the accelerometer correction is not invertible or a gyro scale is zero",
                path.display()
            )
        })?;
    }
    Ok(model)
}

/// Where the samples go: `--output` in `--format` (by default `bin` for a
/// `.bin` output and `csv` otherwise), a capture of a probe at `site` with
/// `--tie-in-job`'s tie-in.
fn sample_sink(args: &Args, site: Position) -> Result<SampleSink<'_>> {
    let output = args.output.as_path();
    let to_stdout = output.as_os_str() == "-";
    let format = args
        .format
        .unwrap_or(if output.extension().is_some_and(|e| e == "bin") {
            OutputFormat::Bin
        } else {
            OutputFormat::Csv
        });
    Ok(match format {
        OutputFormat::Bin => {
            anyhow::ensure!(
                !to_stdout,
                "binary captures go to a file, not standard output"
            );
            let tie_in = tie_in(args)?;
            SampleSink::Capture {
                path: output,
                probe: ProbeSetup {
                    tie_in,
                    ..ProbeSetup::at(site)
                },
            }
        }
        OutputFormat::Csv if to_stdout => SampleSink::Stdout,
        OutputFormat::Csv => SampleSink::Csv(output),
    })
}

/// `--tie-in-job`'s tie-in.
fn tie_in(args: &Args) -> Result<Option<TieIn>> {
    let Some(path) = &args.tie_in_job else {
        return Ok(None);
    };
    match Job::load(path)?.tie_in {
        Some(t) => Ok(Some(t)),
        None => anyhow::bail!("{}: the job has no tie_in", path.display()),
    }
}

/// `--motion lateral`: the drilling simulator along `--plan`.
fn run_lateral(args: &Args) -> Result<()> {
    let path = args
        .plan
        .as_ref()
        .context("--motion lateral needs --plan FILE (a well plan, docs/drilling-simulation.md)")?;
    let mut plan = Plan::load(path)?;
    if let Some(level) = args.vibration {
        plan.drilling.vibration = level.vibration();
    }
    let model = sensor_model(args)?;
    let started = std::time::Instant::now();
    let drilling = Drilling::new(plan, args.seed);
    // The site the probe's navigator is configured with: the plan's (the
    // wellhead; the QEMU probe's default is the same paper site), not the
    // probe's position down hole, so `replay` of the capture (which knows
    // only the configured site) is bit for bit the probe's.
    let site = drilling.plan().site;
    let outputs = LateralOutputs {
        truth: args.truth.as_deref(),
        truth_every: args.truth_every as usize,
        sensor_stream: args.sensor_stream.as_deref(),
        depth_log: args.depth_log.as_deref(),
    };
    let over_range = drill(&drilling, model, &outputs, |samples| {
        write_samples(sample_sink(args, site)?, samples).map(drop)
    })?;
    let plan = drilling.plan();
    eprintln!(
        "drilled MD {:.2} -> {:.2} m in {:.2} h ({} connections, {} shocks): {} samples to {} in {:.1} s; \
         {} samples with an accelerometer axis beyond 6 g, {} with a gyro beyond 300 deg/s",
        plan.start_md(),
        plan.end_md(),
        drilling.duration() / 3600.0,
        drilling.connections().len(),
        drilling.shocks().len(),
        drilling.sample_count(SAMPLE_INTERVAL_S),
        args.output.display(),
        started.elapsed().as_secs_f64(),
        over_range.accel,
        over_range.gyro,
    );
    Ok(())
}

impl VibrationLevel {
    /// The plan's vibration at this level.
    pub fn vibration(self) -> Vibration {
        match self {
            Self::None => Vibration::NONE,
            Self::Moderate => Vibration::MODERATE,
            Self::Harsh => Vibration::HARSH,
        }
    }
}
