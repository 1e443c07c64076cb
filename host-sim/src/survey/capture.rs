//! The survey of a drilling capture (`host-sim survey CAPTURE.bin --depth
//! DEPTH.csv`): the probe's station surveys read from the capture as a
//! stream, replayed through the probe's navigation for their links,
//! paired with MD from the surface depth log and given the probe's own
//! position uncertainty ([`drilling::survey`]); and the continuous
//! trajectory from the 20 Hz solutions ([`trajectory::trajectory`]).
//! docs/drilling-survey.md.

pub use crate::formats::capture::ProbeSetup;
use crate::formats::capture::{Item, ProbeCaptureFile};
use crate::formats::depth_log::DepthLog;
use crate::formats::files::read_depth_log;
use crate::replay::{replayed_station_links, Replayer, FILE_BATCH_ITEMS};
use crate::survey::iscwsa::{ErrorTerm, Site};
use crate::survey::listing::drilling::{self, DrillingSurvey, QcReference};
use crate::survey::listing::station_gaps::numbers_text;
use crate::survey::listing::trajectory::{self, TrajectoryPoint};
use crate::survey::listing::{self, drilling_text, LengthUnit, Row, TieOnInput};
use crate::survey::station_qc::{CheckedStations, QcCollector, QcTolerances};
use crate::survey::stations::{StationCollector, SurveySetup};
use crate::survey::well_survey::WellSurvey;
use anyhow::{bail, Context, Result};
use mwd_core::probe::StationLink;
use mwd_core::protocol::frame::MAX_BODY_LEN;
use mwd_core::protocol::{encode_body, DecoderStats, Frame, Payload, StationSurvey};
use std::collections::hash_map::{Entry, HashMap};
use std::path::{Path, PathBuf};

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
    /// From the survey sensors to the bit, m: the survey ends with the
    /// bit's projection.
    pub sensor_to_bit_m: Option<f64>,
    /// A station whose MD the depth log interpolates across a longer
    /// interval, s, is flagged (`drilling::DEPTH_GAP_LIMIT_S` by default).
    pub depth_gap_limit_s: f64,
}

/// A capture's survey and what its listing says about the capture.
pub struct CaptureSurvey {
    pub survey: DrillingSurvey,
    /// The capture's decoding: bad frames, frames lost.
    pub stats: DecoderStats,
    /// Station frames repeated identically, taken once.
    pub repeated_stations: u64,
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
        let setup = SurveySetup::probe(inputs.tie, inputs.latitude)?
            .with_sensor_to_bit(inputs.sensor_to_bit_m)
            .with_uncalibrated(inputs.probe.is_uncalibrated());
        let setup = SurveySetup {
            depth_gap_limit_s: inputs.depth_gap_limit_s,
            ..setup
        };
        let links = read.links;
        let mut survey = read
            .collected
            .survey(links.as_deref().unwrap_or(&[]), &setup, &depth)
            .with_context(|| format!("{}", inputs.capture.display()))?;
        if let Some((reference, checked)) = read.qc {
            for row in survey.rows.iter_mut() {
                row.qc = checked
                    .iter()
                    .find(|(station, end, _)| {
                        (*station, *end) == (row.survey.station, row.survey.end_sample)
                    })
                    .map(|c| c.2);
            }
            survey.qc_reference = Some(reference);
        }
        let SurveySetup {
            tie, terms, site, ..
        } = setup;
        Ok(Self {
            survey,
            stats: read.stats,
            repeated_stations: read.repeated_stations,
            links_missing: links.err(),
            capture: inputs.capture.clone(),
            depth,
            tie,
            terms,
            site,
        })
    }

    /// The listing: whether the probe ran uncalibrated, the capture's bad
    /// and lost frames (if any), where the
    /// station links came from, and the stations with their uncertainty
    /// (the ellipse at `confidence`).
    pub fn report(&self, confidence: f64) -> String {
        // a probe without a calibration: said first
        let mut text = drilling_text::top_note(&self.survey);
        if let Some(note) = placement_note(&self.tie) {
            text += &format!("note: {note}\n");
        }
        let s = &self.stats;
        let bad = s.crc_errors + s.malformed + s.unknown_kind;
        let repeated = s.duplicated + self.repeated_stations;
        if bad > 0 || s.lost > 0 || repeated > 0 || s.reordered > 0 {
            text += &format!(
                "capture: {bad} bad frames skipped, {} frames lost in sequence gaps, {repeated} \
                 repeated frames taken once ({} station frames), {} reordered frames\n",
                s.lost, self.repeated_stations, s.reordered
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
        text + &drilling_text::stations_listing(&self.survey, confidence)
    }

    /// What the survey could not use, if anything: frames lost in the
    /// capture (sequence gaps) and stations lost among them. A survey with
    /// losses is written but incomplete (`survey` exits 2).
    pub fn incomplete(&self) -> Option<String> {
        let frames = self.stats.lost;
        let stations: u64 = self
            .survey
            .lost
            .iter()
            .map(|(first, last)| u64::from(last - first) + 1)
            .sum();
        (frames > 0 || stations > 0).then(|| {
            let named: Vec<String> = self
                .survey
                .lost
                .iter()
                .map(|(first, last)| numbers_text(*first, *last))
                .collect();
            let which = if named.is_empty() {
                "no station among them (the others' positions stand)".to_string()
            } else {
                format!("{stations} stations among them ({})", named.join(", "))
            };
            format!("the survey is incomplete: {frames} frames lost in the capture, {which}")
        })
    }

    /// The survey as a station file's survey is exported (JSON, WITSML,
    /// figures, an offset well's separation: [`crate::survey::outputs`]):
    /// the stations up to the first undetermined position, metres along
    /// true north, with the probe's covariance at `confidence`; the
    /// vertical section along `vsec_azimuth` (rad; `None`: the last
    /// exported station's closure azimuth).
    pub fn well_survey(&self, confidence: f64, vsec_azimuth: Option<f64>) -> Result<WellSurvey> {
        let exported: Vec<_> = self
            .survey
            .rows
            .iter()
            .take_while(|r| r.position_determined && r.row.cov.is_some())
            .collect();
        let station_qc = exported.iter().map(|r| r.qc).collect();
        let row_flags = exported.iter().map(|r| r.flags(false)).collect();
        let mut rows: Vec<Row> = exported.iter().map(|r| r.row).collect();
        let left_out = self.survey.rows.len() - rows.len();
        let bit = self
            .survey
            .bit
            .map(|b| b.row)
            .filter(|b| left_out == 0 && b.cov.is_some());
        let direction = vsec_azimuth.unwrap_or_else(|| {
            rows.last().map_or(0.0, |r| {
                r.east_m.atan2(r.north_m).rem_euclid(std::f64::consts::TAU)
            })
        });
        let (sin, cos) = direction.sin_cos();
        for r in rows.iter_mut() {
            r.vsec_m = r.north_m * cos + r.east_m * sin;
        }
        let bit = bit.map(|b| Row {
            vsec_m: b.north_m * cos + b.east_m * sin,
            ..b
        });
        let mut notes: Vec<String> = placement_note(&self.tie).into_iter().collect();
        if let Some(first) = self.survey.rows.get(rows.len()) {
            notes.push(format!(
                "{left_out} stations from station {} (MD {:.2} m) on have no determined position \
                 (their azimuth or an earlier one is undetermined) and are not in this output",
                first.survey.station, first.row.md_m
            ));
        }
        Ok(WellSurvey {
            rows,
            vsec_azimuth_deg: direction.to_degrees(),
            model: Some(listing::model(drilling::MODEL_NAME)?),
            invalid_from: None,
            confidence,
            unit: LengthUnit::Metre,
            offset: None,
            bit,
            header_note: (!notes.is_empty()).then(|| notes.join("; ")),
            well: crate::survey::job::WellNames::default(),
            tie_on_cov_m2: self.survey.tie_on_cov_m2,
            output_unit: LengthUnit::Metre,
            station_qc,
            uncalibrated: self.survey.uncalibrated,
            row_flags,
        })
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
        let points = trajectory::trajectory(
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

/// How the stations are placed when no tie-on was given (all zero: the
/// survey's default), as the listing and the exports say on top.
fn placement_note(tie: &TieOnInput) -> Option<String> {
    tie.is_surface().then(|| {
        "no tie-on given: the stations are placed from N 0, E 0, TVD 0 at the first station's \
         MD, not where the well is (give the job's survey.tie_on or --tie-on-*)"
            .to_string()
    })
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
    /// Station frames repeated identically (the probe sent one again),
    /// taken once.
    repeated_stations: u64,
    /// The stations' quality checks (station number, last sample, checks)
    /// and what they were made against; `None` where the tool model has no
    /// tolerances.
    qc: Option<(QcReference, CheckedStations)>,
}

fn read_stations(path: &Path, probe: &ProbeSetup) -> Result<CaptureStations> {
    let mut capture = ProbeCaptureFile::open(path)?;
    let mut replayer = Replayer::with_settings(probe.site, probe.calibration, probe.still)
        .with_tie_in(probe.tie_in);
    let mut collected = StationCollector::default();
    let mut qc = qc_collector(probe)?;
    let mut items = 0usize;
    let mut taken = StationsTaken::default();
    while let Some(item) = capture.next_item()? {
        if let Item::Frame(Frame {
            payload: Payload::Station(station),
            ..
        }) = &item
        {
            if !taken.take(station)? {
                continue;
            }
        }
        if let Item::Frame(frame) = &item {
            collected.push_frame(frame);
            if let Some(qc) = qc.as_mut() {
                match &frame.payload {
                    Payload::Raw(raw) => qc.push_raw(raw),
                    Payload::Station(s) => qc.push_station(s),
                    _ => {}
                }
            }
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
        repeated_stations: taken.repeated,
        qc: qc.map(|q| {
            let reference = QcReference {
                gravity_m_s2: q.gravity(),
                tolerances: q.tolerances(),
            };
            (reference, q.into_checked())
        }),
    })
}

/// The stations' quality checks with the probe's calibration at its site,
/// to the probe's tool model's tolerances.
fn qc_collector(probe: &ProbeSetup) -> Result<Option<QcCollector>> {
    let terms = listing::terms(listing::model(drilling::MODEL_NAME)?)?;
    let gravity = mwd_core::earth::normal_gravity(probe.site.lat, probe.site.height);
    Ok(QcTolerances::from_terms(&terms, gravity)
        .map(|t| QcCollector::new(probe.calibration, probe.site, t)))
}

/// The station frames read so far, by number, as their bytes: one repeated
/// identically (the probe sends a station again for a repeated request) is
/// taken once; another station under a number already taken is refused.
#[derive(Default)]
struct StationsTaken {
    bodies: HashMap<u16, Vec<u8>>,
    repeated: u64,
}

impl StationsTaken {
    /// Whether `station` is new (false: a repeat, to skip).
    fn take(&mut self, station: &StationSurvey) -> Result<bool> {
        let mut body = [0u8; MAX_BODY_LEN];
        let len = encode_body(0, &Payload::Station(*station), &mut body)
            .context("encoding a station survey")?;
        let body = body.get(..len).unwrap_or_default().to_vec();
        match self.bodies.entry(station.station) {
            Entry::Vacant(slot) => {
                slot.insert(body);
                Ok(true)
            }
            Entry::Occupied(slot) if *slot.get() == body => {
                self.repeated += 1;
                Ok(false)
            }
            Entry::Occupied(_) => bail!(
                "two different station frames numbered {} (the second at {:.2} s): a station \
                 number stands for one station of a run; does the capture hold more than one \
                 run? (split it at the boot event)",
                station.station,
                station.time_us as f64 * 1e-6
            ),
        }
    }
}
