//! The survey of a drilling capture (`host-sim survey CAPTURE.bin --depth
//! DEPTH.csv`): the probe's station surveys read from the capture as a
//! stream, replayed through the probe's navigation for their links,
//! paired with MD from the surface depth log and given the probe's own
//! position uncertainty ([`drilling::survey`]); and the continuous
//! trajectory from the 20 Hz solutions ([`drilling::trajectory`]).
//! docs/drilling-survey.md.

use crate::formats::capture::{Item, ProbeCaptureFile};
use crate::formats::depth_log::DepthLog;
use crate::formats::files::read_depth_log;
use crate::replay::{replayed_station_links, Replayer, FILE_BATCH_ITEMS};
use crate::survey::iscwsa::{ErrorTerm, Site};
use crate::survey::listing::drilling::{self, DrillingSurvey, TrajectoryPoint};
use crate::survey::listing::{drilling_text, TieOnInput};
use crate::survey::stations::{StationCollector, SurveySetup};
use anyhow::{Context, Result};
use mwd_core::calibration::ProbeCalibration;
use mwd_core::earth::Position;
use mwd_core::probe::{StationLink, TieIn};
use mwd_core::protocol::uplink::StillSettings;
use mwd_core::protocol::{DecoderStats, Frame, Payload};
use std::path::{Path, PathBuf};

/// What a capture's replay needs of the probe's configuration: the site,
/// the calibration, still settings and tie-in it ran with.
#[derive(Clone, Copy, Debug)]
pub struct ProbeSetup {
    pub site: Position,
    pub calibration: ProbeCalibration,
    pub still: StillSettings,
    pub tie_in: Option<TieIn>,
}

/// A capture survey's inputs.
#[derive(Clone, Debug)]
pub struct CaptureSurveyInputs {
    /// The probe's capture (`.bin`).
    pub capture: PathBuf,
    /// The surface depth log (CSV: time_s, md_m).
    pub depth: PathBuf,
    /// The tie-on, in metres (the depth log's unit).
    pub tie: TieOnInput,
    /// Latitude of the site, rad (the model's site).
    pub latitude: f64,
    pub probe: ProbeSetup,
}

/// A capture's survey and what its listing says about the capture.
pub struct CaptureSurvey {
    pub survey: DrillingSurvey,
    /// The capture's decoding: bad frames, frames lost.
    pub stats: DecoderStats,
    /// Why the stations have no links from the capture's replay, if so.
    pub links_missing: Option<String>,
    capture: PathBuf,
    depth: DepthLog,
    tie: TieOnInput,
    terms: Vec<ErrorTerm>,
    site: Site,
}

impl CaptureSurvey {
    /// Reads the capture (one pass) and the depth log, and surveys the
    /// stations.
    pub fn run(inputs: &CaptureSurveyInputs) -> Result<Self> {
        let read = read_stations(&inputs.capture, &inputs.probe)?;
        let depth = read_depth_log(&inputs.depth)?;
        let setup = SurveySetup::probe(inputs.tie, inputs.latitude)?;
        let links = read.links;
        let survey = read
            .collected
            .survey(links.as_deref().unwrap_or(&[]), &setup, &depth)
            .with_context(|| format!("{}", inputs.capture.display()))?;
        let SurveySetup { tie, terms, site } = setup;
        Ok(Self {
            survey,
            stats: read.stats,
            links_missing: links.err(),
            capture: inputs.capture.clone(),
            depth,
            tie,
            terms,
            site,
        })
    }

    /// The listing: the capture's bad and lost frames (if any), where the
    /// station links came from, and the stations with their uncertainty
    /// (the ellipse at `confidence`).
    pub fn report(&self, confidence: f64) -> String {
        let mut text = String::new();
        let s = &self.stats;
        let bad = s.crc_errors + s.malformed + s.unknown_kind;
        if bad > 0 || s.lost > 0 {
            text += &format!(
                "capture: {bad} bad frames skipped, {} frames lost in sequence gaps\n",
                s.lost
            );
        }
        text += &match &self.links_missing {
            None => "station links: from the capture's replay (every station frame replayed bit \
                     for bit)\n"
                .to_string(),
            Some(why) => format!(
                "station links: none ({why}); the survey chains the stations' azimuth alone, \
                 which understates the position sigma when the gyro bias estimates tie the \
                 stations (docs/drilling-survey.md)\n"
            ),
        };
        text + &drilling_text::listing(&self.survey, confidence)
    }

    /// One row per station (CSV).
    pub fn stations_csv(&self, confidence: f64) -> String {
        drilling_text::stations_csv(&self.survey, confidence)
    }

    /// The continuous trajectory every `step_m` of MD, from the capture's
    /// 20 Hz solutions (a second pass over the file: the trajectory starts
    /// from the survey's tie-on, known only after the first).
    pub fn trajectory(&self, step_m: f64) -> Result<Vec<TrajectoryPoint>> {
        let mut capture = ProbeCaptureFile::open(&self.capture)?;
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
            &self.depth,
            &self.survey,
            self.tie,
            &self.terms,
            &self.site,
            step_m,
        );
        if let Some(e) = failed {
            return Err(e);
        }
        points
    }
}

/// The trajectory as CSV (the ellipse at `confidence`).
pub fn trajectory_csv(points: &[TrajectoryPoint], confidence: f64) -> String {
    drilling_text::trajectory_csv(points, confidence)
}

/// What the survey takes from a capture, read in one pass as a stream (a
/// day and a half of drilling is 5 M frames: none of them is kept).
struct CaptureStations {
    /// The probe's station surveys in order, each with the azimuth sigma
    /// just before its still period began.
    collected: StationCollector,
    /// The stations' links from the capture's replay
    /// (`replay::replayed_station_links`), or why there are none.
    links: Result<Vec<Option<StationLink>>, String>,
    stats: DecoderStats,
}

fn read_stations(path: &Path, probe: &ProbeSetup) -> Result<CaptureStations> {
    let mut capture = ProbeCaptureFile::open(path)?;
    let mut replayer = Replayer::with_settings(probe.site, probe.calibration, probe.still)
        .with_tie_in(probe.tie_in);
    let mut collected = StationCollector::default();
    let mut items = 0usize;
    while let Some(item) = capture.next_item()? {
        if let Item::Frame(frame) = &item {
            collected.push_frame(frame);
        }
        replayer.push_received(item.received());
        items += 1;
        if items % FILE_BATCH_ITEMS == 0 {
            // No CSV here: the rows are only forgotten (never fails).
            replayer.write_settled(None, false)?;
        }
    }
    let links = replayed_station_links(&mut replayer, collected.stations());
    Ok(CaptureStations {
        collected,
        links,
        stats: *capture.stats(),
    })
}
