//! `host-sim survey CAPTURE.bin --depth DEPTH.csv`: the probe's station
//! surveys of a drilling capture, paired with MD from the surface depth
//! log, listed with their position uncertainty; `--trajectory OUT.csv`: the
//! continuous trajectory from the 20 Hz solutions. docs/drilling-survey.md.

use super::limits::number_in;
use super::survey::{Args, Resolved};
use anyhow::{bail, Context, Result};
use host_sim::formats::capture::{Item, ProbeCaptureFile};
use host_sim::formats::depth_log::DepthLog;
use host_sim::replay::{replayed_station_links, Replayer, FILE_BATCH_ITEMS};
use host_sim::survey::iscwsa::Site;
use host_sim::survey::listing::drilling::AzimuthSigmaTrack;
use host_sim::survey::listing::{drilling, drilling_text, LengthUnit};
use mwd_core::probe::StationLink;
use mwd_core::protocol::{DecoderStats, Frame, Payload, StationSurvey};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

fn step_m(text: &str) -> Result<f64, String> {
    let v = number_in(text, "the trajectory step", (0.0, 1000.0), "m")?;
    if v == 0.0 {
        return Err("the trajectory step must be above 0 m".into());
    }
    Ok(v)
}

/// Options of a capture survey.
#[derive(clap::Args, Debug)]
pub struct CaptureArgs {
    /// The surface depth log (CSV: time_s, md_m): the input is then a probe
    /// capture (.bin), and its station surveys are listed.
    #[arg(long, value_name = "DEPTH.csv")]
    pub depth: Option<PathBuf>,
    /// With --depth: write the continuous trajectory (20 Hz attitude and
    /// the depth log by minimum curvature) here (CSV).
    #[arg(long, value_name = "OUT.csv", requires = "depth")]
    pub trajectory: Option<PathBuf>,
    /// MD step of the trajectory, m.
    #[arg(long, default_value_t = 1.0, value_parser = step_m, requires = "trajectory")]
    pub trajectory_step_m: f64,
}

pub fn run(args: &Args, resolved: &Resolved) -> Result<()> {
    let unsupported = [
        ("--json", args.json.is_some()),
        ("--witsml", args.witsml.is_some()),
        ("--plot", args.plot.is_some()),
        ("--offset", args.sep.offset.is_some()),
        ("--error-model", args.error_model.is_some()),
        ("--vsec-azimuth-deg", args.vsec_azimuth_deg.is_some()),
        ("--convergence-deg", args.convergence_deg.is_some()),
    ];
    if let Some((flag, _)) = unsupported.iter().find(|u| u.1) {
        bail!(
            "{flag} is not available for a capture survey (--depth): its uncertainty is the \
             probe's own (docs/drilling-survey.md)"
        );
    }
    // The capture's uncertainty is the probe's own model: a job naming
    // another is a job for another tool.
    if let Some(name) = &resolved.job.error_model {
        let probe = drilling::MODEL_NAME;
        if host_sim::survey::listing::model(name)?.name != probe {
            bail!(
                "the job's error model {name} is not the probe's ({probe}): a capture survey \
                 (--depth) has the probe's own uncertainty"
            );
        }
    }
    let Some(depth_path) = &args.capture.depth else {
        bail!("a capture survey needs --depth");
    };
    let read = read_stations(&args.stations, resolved)?;
    let file = std::fs::File::open(depth_path)
        .with_context(|| format!("reading {}", depth_path.display()))?;
    let depth = DepthLog::read(file).with_context(|| format!("{}", depth_path.display()))?;
    // The depth log is in metres.
    let tie = resolved.tie_on(args, LengthUnit::Metre);
    let site = Site {
        gravity: 9.806_65,
        b_total: 0.0,
        dip: 0.0,
        declination: 0.0,
        vertical_limit: 0.0001_f64.to_radians(),
        latitude: resolved.latitude,
        gyro_noise_reduction: 1.0,
    };
    let terms = drilling::survey_terms()?;
    let links = read.links;
    let survey = drilling::survey(
        &read.stations,
        &read.azimuth_sigma_before,
        links.as_deref().unwrap_or(&[]),
        &depth,
        tie,
        &terms,
        &site,
    )
    .with_context(|| format!("{}", args.stations.display()))?;
    let s = &read.stats;
    let bad = s.crc_errors + s.malformed + s.unknown_kind;
    if bad > 0 || s.lost > 0 {
        outln!(
            "capture: {bad} bad frames skipped, {} frames lost in sequence gaps",
            s.lost
        );
    }
    match &links {
        Ok(_) => outln!(
            "station links: from the capture's replay (every station frame replayed bit for bit)"
        ),
        Err(why) => outln!(
            "station links: none ({why}); the survey chains the stations' azimuth alone, which \
             understates the position sigma when the gyro bias estimates tie the stations \
             (docs/drilling-survey.md)"
        ),
    }
    out!("{}", drilling_text::listing(&survey, args.confidence));
    let write = |path: &PathBuf, text: String| {
        std::fs::write(path, text).with_context(|| format!("writing {}", path.display()))
    };
    if let Some(path) = &args.csv {
        write(path, drilling_text::stations_csv(&survey, args.confidence))?;
    }
    if let Some(path) = &args.capture.trajectory {
        // A second pass over the file: the trajectory starts from the
        // survey's tie-on, known only now.
        let mut capture = ProbeCaptureFile::open(&args.stations)?;
        let mut failed = None;
        let solutions = std::iter::from_fn(|| loop {
            match capture.next_item() {
                Ok(Some(Item::Frame(Frame {
                    payload: Payload::Nav(n),
                    ..
                }))) => return Some(n),
                Ok(Some(_)) => {}
                Ok(None) => return None,
                Err(e) => {
                    failed = Some(e);
                    return None;
                }
            }
        });
        let points = drilling::trajectory(
            solutions,
            &depth,
            &survey,
            tie,
            &terms,
            &site,
            args.capture.trajectory_step_m,
        );
        if let Some(e) = failed {
            return Err(e);
        }
        let points = points?;
        write(
            path,
            drilling_text::trajectory_csv(&points, args.confidence),
        )?;
        outln!("wrote {} ({} points)", path.display(), points.len());
    }
    Ok(())
}

/// What the survey takes from a capture, read in one pass as a stream (a
/// day and a half of drilling is 5 M frames: none of them is kept).
struct CaptureStations {
    /// The probe's station surveys, in order.
    stations: Vec<StationSurvey>,
    /// Each one's azimuth sigma just before its still period began.
    azimuth_sigma_before: Vec<Option<f64>>,
    /// The stations' links from the capture's replay
    /// (`replay::replayed_station_links`), or why there are none.
    links: Result<Vec<Option<StationLink>>, String>,
    stats: DecoderStats,
}

fn read_stations(path: &Path, resolved: &Resolved) -> Result<CaptureStations> {
    let mut capture = ProbeCaptureFile::open(path)?;
    let probe = &resolved.probe;
    let mut replayer = Replayer::with_settings(probe.site, probe.calibration, probe.still)
        .with_tie_in(probe.tie_in);
    let mut track = AzimuthSigmaTrack::default();
    let mut stations = Vec::new();
    let mut azimuth_sigma_before = Vec::new();
    // A station frame sent again (on request) starts where the first did.
    let mut starts: HashMap<(u16, u32), Option<f64>> = HashMap::new();
    let mut items = 0usize;
    while let Some(item) = capture.next_item()? {
        if let Item::Frame(frame) = &item {
            match &frame.payload {
                Payload::Nav(n) => track.push(n),
                Payload::Station(st) => {
                    let sigma = *starts
                        .entry((st.station, st.start_sample))
                        .or_insert_with(|| track.station_start(st));
                    stations.push(*st);
                    azimuth_sigma_before.push(sigma);
                }
                _ => {}
            }
        }
        replayer.push_received(item.received());
        items += 1;
        if items % FILE_BATCH_ITEMS == 0 {
            // No CSV here: the rows are only forgotten (never fails).
            replayer.write_settled(None, false)?;
        }
    }
    let links = replayed_station_links(&mut replayer, &stations);
    Ok(CaptureStations {
        stations,
        azimuth_sigma_before,
        links,
        stats: *capture.stats(),
    })
}
