//! A drilling run's survey (`host-sim survey CAPTURE.bin --depth LOG`):
//! the probe's station surveys paired with MD from the surface depth log
//! by time, positioned by minimum curvature from the tie-on, with their
//! position covariance from the probe's own station sigmas
//! ([`crate::survey::iscwsa::probe_station`]) and the depth log's scale and
//! stretch errors (the engine's DSF/DST sources); and a continuous
//! trajectory from the 20 Hz solutions. docs/drilling-survey.md.
//!
//! The first usable station is the tie-on: the probe surveys the window
//! before drilling starts, and its position (TVD, north, east) is the
//! parent well's. Its MD is the depth log's at that time, or `--tie-on-md`:
//! then the whole log is shifted by the same amount (the driller's depth
//! referenced to the parent well's MD at the window). Either way the depth
//! errors counted are those of the MD drilled from the tie-on.

pub use super::station_gaps::FIRST_STATION;
use super::station_gaps::{lost_numbers, tie_on_station_known};
use super::{compute, AzimuthReference, InputStation, LengthUnit, Row, StationFile, TieOnInput};
use crate::formats::depth_log::DepthLog;
use crate::survey::iscwsa::probe_station::{
    angle_covariance, angle_covariance_projected, links_in_order, AngleSigma,
};
use crate::survey::iscwsa::{self, Cov6, ErrorTerm, Site, Station};
use crate::survey::station_qc::{QcTolerances, StationQc};
use anyhow::{anyhow, bail, Result};
use mwd_core::probe::StationLink;
use mwd_core::protocol::frame::station_flags;
use mwd_core::protocol::{NavSolution, StationSurvey};

/// One station of the survey.
#[derive(Clone, Copy, Debug)]
pub struct DrillingRow {
    pub survey: StationSurvey,
    /// Time of the station (its last still sample), s since boot.
    pub time_s: f64,
    /// MD, inclination, azimuth, positions; `cov` only where the position
    /// is determined.
    pub row: Row,
    /// The part of `row.cov` from the survey method's terms (XCLA, XCLH:
    /// [`survey_terms`]), where the position is determined.
    pub method_cov: Option<Cov6>,
    pub azimuth_determined: bool,
    /// Every station up to this one has a determined azimuth: N/E/TVD and
    /// their covariance mean something.
    pub position_determined: bool,
    /// The station's quality checks, where the capture had its samples
    /// ([`crate::survey::station_qc`]).
    pub qc: Option<StationQc>,
    /// The depth log's interval this station's MD was interpolated
    /// across, s, where longer than [`SurveySetup::depth_gap_limit_s`].
    pub depth_gap_s: Option<f64>,
}

impl DrillingRow {
    /// The station's flags: [`UNCALIBRATED_FLAG`] for a probe that ran
    /// without a calibration, [`DEPTH_GAP_FLAG`].
    pub fn flags(&self, uncalibrated: bool) -> Vec<&'static str> {
        let mut flags = Vec::new();
        if uncalibrated {
            flags.push(UNCALIBRATED_FLAG);
        }
        if self.depth_gap_s.is_some() {
            flags.push(DEPTH_GAP_FLAG);
        }
        flags
    }
}

/// The flag of a station whose MD the depth log gives only across a
/// longer interval than [`SurveySetup::depth_gap_limit_s`].
pub const DEPTH_GAP_FLAG: &str = "depth interpolated across a gap";

/// The longest depth-log interval a station's MD is interpolated across
/// without a flag, s: a surface system logs every few seconds, and a
/// stand's connection (the string still) takes minutes, so a longer hole
/// in the log is lost data, not a pause.
pub const DEPTH_GAP_LIMIT_S: f64 = 30.0;

/// The site's gravity and the tolerances a capture's stations were checked
/// against.
#[derive(Clone, Copy, Debug)]
pub struct QcReference {
    pub gravity_m_s2: f64,
    pub tolerances: QcTolerances,
}

/// A station left out, and why.
#[derive(Clone, Debug)]
pub struct Skipped {
    pub survey: StationSurvey,
    pub reason: String,
    /// The later station at the same MD that stands instead, if that is
    /// why.
    pub superseded_by: Option<u16>,
}

/// The survey of a drilling run.
#[derive(Clone, Debug)]
pub struct DrillingSurvey {
    pub rows: Vec<DrillingRow>,
    pub skipped: Vec<Skipped>,
    /// Station numbers the probe sent that are not in the stations (their
    /// frames were not received), as ranges `first..=last`: between the
    /// first number expected (1, the probe's first station since boot)
    /// and the last received. A lost station is left out alone: the
    /// others keep their MD (from the depth log, by time) and are
    /// positioned across the gap.
    pub lost: Vec<(u16, u16)>,
    /// Added to the depth log's MD (m): `--tie-on-md` minus the log at the
    /// first station; 0 without it.
    pub md_offset_m: f64,
    /// The bit, projected from the last station ([`SurveySetup::sensor_to_bit_m`]).
    pub bit: Option<BitProjection>,
    /// The tie-on's position covariance (m^2) in every position's;
    /// `None`: the tie-on is taken as exact.
    pub tie_on_cov_m2: Option<Cov6>,
    /// What the stations' quality checks were made against, where made.
    pub qc_reference: Option<QcReference>,
    /// The probe ran without a calibration ([`SurveySetup::uncalibrated`]):
    /// every station is flagged, its sigmas do not cover the parts'
    /// uncalibrated errors.
    pub uncalibrated: bool,
    /// The longest depth-log interval a station's MD was interpolated
    /// across unflagged, s ([`DrillingRow::depth_gap_s`]).
    pub depth_gap_limit_s: f64,
}

/// The bit at the end of the depth log (TD: the log's last MD plus the
/// sensor-to-bit distance), projected from the last station: its
/// inclination and azimuth held straight ahead (the hole drilled since
/// and the bit's own angles are not surveyed), with the last station's
/// angle errors acting over the whole projection.
#[derive(Clone, Copy, Debug)]
pub struct BitProjection {
    /// From the survey sensors to the bit, m.
    pub sensor_to_bit_m: f64,
    /// From the last station to the bit along the hole, m: what was
    /// drilled after the station, and the sensor-to-bit distance.
    pub projected_m: f64,
    /// MD, angles (the last station's) and position; `cov` where the last
    /// station's position is determined.
    pub row: Row,
    /// The survey method's part of `row.cov`.
    pub method_cov: Option<Cov6>,
}

/// What positioning the probe's stations needs besides the stations and
/// the depth log: the tie-on, the probe's own error model at the site and
/// where the bit is.
#[derive(Debug, Clone)]
pub struct SurveySetup {
    /// The tie-on, metres (MD `None`: the first station's).
    pub tie: TieOnInput,
    /// The probe's angle sigmas plus the depth log's scale and stretch
    /// terms (no magnetic terms: the probe has none).
    pub terms: Vec<ErrorTerm>,
    pub site: Site,
    /// From the survey sensors to the bit, m (> 0); `None`: no projection.
    pub sensor_to_bit_m: Option<f64>,
    /// The number of the first station expected ([`FIRST_STATION`]; a
    /// display that forgot its oldest stations: the oldest it holds).
    pub first_station: u16,
    /// The probe ran without a calibration of its parts' deterministic
    /// errors (turn-on bias, scale factor, misalignment): its station
    /// sigmas are the calibrated residual's and do not cover those
    /// errors, so every station is flagged ([`UNCALIBRATED_NOTE`]).
    pub uncalibrated: bool,
    /// A station whose MD the depth log interpolates across a longer
    /// interval, s, is flagged ([`DEPTH_GAP_FLAG`]).
    pub depth_gap_limit_s: f64,
}

/// What the outputs of a survey whose probe ran without a calibration say
/// on top: its stations' sigmas are the calibrated probe's.
pub const UNCALIBRATED_NOTE: &str = "UNCALIBRATED: the probe ran without a calibration of its \
parts; every station is flagged \"uncalibrated\": its sigmas do not cover the parts' uncalibrated \
errors (turn-on bias, scale factor, misalignment), and its angles and positions may be off by \
many sigmas";

/// The flag of each station of an uncalibrated survey (CSV, JSON, WITSML).
pub const UNCALIBRATED_FLAG: &str = "uncalibrated";

impl SurveySetup {
    /// The probe's survey at a site at `latitude_rad`, tied on at `tie`.
    pub fn probe(tie: TieOnInput, latitude_rad: f64) -> Result<Self> {
        Ok(Self {
            tie,
            terms: survey_terms()?,
            site: Site {
                gravity: 9.806_65,
                b_total: 0.0,
                dip: 0.0,
                declination: 0.0,
                vertical_limit: 0.0001_f64.to_radians(),
                latitude: latitude_rad,
                gyro_noise_reduction: 1.0,
            },
            sensor_to_bit_m: None,
            first_station: FIRST_STATION,
            uncalibrated: false,
            depth_gap_limit_s: DEPTH_GAP_LIMIT_S,
        })
    }

    /// The same, for a probe that ran without a calibration (`true`).
    pub fn with_uncalibrated(self, uncalibrated: bool) -> Self {
        Self {
            uncalibrated,
            ..self
        }
    }

    /// The same, with the bit `m` metres ahead of the sensors (`None`, 0:
    /// no projection).
    pub fn with_sensor_to_bit(self, m: Option<f64>) -> Self {
        Self {
            sensor_to_bit_m: m.filter(|m| *m > 0.0),
            ..self
        }
    }
}

/// The probe's tool model (docs/probe-tool-model.md): a capture survey's.
pub const MODEL_NAME: &str = "PROBE-SCC1300";

/// The survey's error sources other than the probe's angles, from the
/// probe's tool model (one place for their magnitudes): the depth log's
/// scale and stretch (DSFS, DSTG) and the minimum-curvature method's
/// long-course-length terms (XCLA, XCLH, SPE 187249): one arc per stand
/// cannot follow a path that changes its curvature inside the stand
/// (docs/drilling-survey.md).
pub fn survey_terms() -> Result<Vec<ErrorTerm>> {
    let model = super::model(MODEL_NAME)?;
    let wanted = ["DSF", "DST", "XCLA", "XCLH"];
    let terms: Vec<ErrorTerm> = super::terms(model)?
        .into_iter()
        .filter(|t| wanted.contains(&t.weighting.as_str()))
        .collect();
    if terms.len() != wanted.len() {
        bail!("the PROBE-SCC1300 table lacks one of the DSF, DST, XCLA and XCLH terms");
    }
    Ok(terms)
}

/// The azimuth 1-sigma the probe reported in its 20 Hz solutions, by
/// sample counter: the sigma each station's earth-rate updates started
/// from, for the stations' carried fraction
/// ([`crate::survey::iscwsa::probe_station`]). Empty when the solutions are
/// not at hand: the model then takes each station's start as the previous
/// station's sigma.
#[derive(Clone, Debug, Default)]
pub struct AzimuthSigmaTrack {
    /// (sample counter, azimuth, azimuth sigma; rad), counters increasing.
    points: Vec<(u32, f32, f32)>,
}

/// The solution a station starts from ([`AzimuthSigmaTrack::start_before`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StationStart {
    pub sample_counter: u32,
    /// Azimuth (rad), as the solution gave it.
    pub azimuth: f64,
    /// Its 1-sigma (rad): a finite number > 0.
    pub sigma: f64,
}

impl AzimuthSigmaTrack {
    /// Adds a solution; one out of order (a reboot, a repeated frame) ends
    /// what is known before it, as a new run would.
    pub fn push(&mut self, s: &NavSolution) {
        if self
            .points
            .last()
            .is_some_and(|&(last, _, _)| s.sample_counter <= last)
        {
            self.points.clear();
        }
        self.points
            .push((s.sample_counter, s.attitude[2], s.attitude_std[2]));
    }

    /// A station just taken from the stream: the solution it starts from
    /// ([`start_before`](Self::start_before) its `start_sample`), and the
    /// solutions before its end forgotten, so that a live stream or a long
    /// run keeps only what a station still to come can start from.
    pub fn station_start_solution(&mut self, station: &StationSurvey) -> Option<StationStart> {
        let start = self.start_before(station.start_sample);
        self.forget_before(station.end_sample);
        start
    }

    /// Forgets the solutions before `sample`.
    fn forget_before(&mut self, sample: u32) {
        let k = self.points.partition_point(|&(c, _, _)| c < sample);
        self.points.drain(..k);
    }

    /// The sigma of the last solution before `sample`, if it is a finite
    /// number > 0 and no more than a second (20 samples) before it.
    pub fn before(&self, sample: u32) -> Option<f64> {
        self.start_before(sample).map(|s| s.sigma)
    }

    /// The last solution before `sample`, under [`before`](Self::before)'s
    /// conditions.
    pub fn start_before(&self, sample: u32) -> Option<StationStart> {
        let k = self.points.partition_point(|&(c, _, _)| c < sample);
        let &(counter, azimuth, sigma) = self.points.get(k.checked_sub(1)?)?;
        let sigma = f64::from(sigma);
        (sample - counter <= 20 && sigma.is_finite() && sigma > 0.0).then_some(StationStart {
            sample_counter: counter,
            azimuth: f64::from(azimuth),
            sigma,
        })
    }
}

impl<'a> FromIterator<&'a NavSolution> for AzimuthSigmaTrack {
    fn from_iter<I: IntoIterator<Item = &'a NavSolution>>(iter: I) -> Self {
        let mut track = Self::default();
        for s in iter {
            track.push(s);
        }
        track
    }
}

/// The station's azimuth is a number with a finite sigma (the survey's
/// rule; `study lateral` counts with it too).
pub(crate) fn azimuth_determined(s: &StationSurvey) -> bool {
    s.flags & station_flags::AZIMUTH_UNDETERMINED == 0 && s.angles_std[1].is_finite()
}

/// The probe did not mark the station invalid (its tilt sigma held, the
/// covariance kept its meaning).
pub(crate) fn station_valid(s: &StationSurvey) -> bool {
    s.flags & station_flags::SOLUTION_INVALID == 0
}

/// A valid station with a determined azimuth: the stations whose azimuth
/// the survey and the studies use.
pub(crate) fn azimuth_usable(s: &StationSurvey) -> bool {
    station_valid(s) && azimuth_determined(s)
}

/// Why a station cannot be used at all, if so.
fn unusable(s: &StationSurvey) -> Option<&'static str> {
    if !station_valid(s) {
        return Some("the probe marked it invalid");
    }
    let inc_ok = s.angles[0].is_finite() && s.angles_std[0].is_finite();
    if !inc_ok || !s.angles[1].is_finite() {
        return Some("its angles or inclination sigma are not numbers");
    }
    None
}

/// A station the survey keeps: the survey, its time (s) and MD (m), the
/// azimuth sigma at its start and its link.
type Kept = (StationSurvey, f64, f64, Option<f64>, Option<StationLink>);

/// The survey of `stations` (in the order the probe sent them) with MD
/// from `depth`, positioned as `setup` says (the tie-on's position, and
/// its MD if given; the bit's projection); `azi_before`: each station's azimuth sigma at its start
/// ([`AzimuthSigmaTrack::before`] its `start_sample`), for the stations'
/// correlation; shorter than `stations` (empty) where not known; `links`:
/// each station's link from the probe (`Navigator::station_link`; empty
/// where not known: no frame carries them yet), for the chain in the
/// links' states (`survey_error::probe_station`). A station number from `setup.first_station` to the last received that
/// is not among `stations` is a lost station. The tie-on is the first
/// usable station: when a station before the first kept one was lost,
/// which station the tie-on belongs to is not known, and a tie-on given
/// (its MD or position) is refused rather than put on a later station
/// (every station would move).
pub fn survey(
    stations: &[StationSurvey],
    azi_before: &[Option<f64>],
    links: &[Option<StationLink>],
    depth: &DepthLog,
    setup: &SurveySetup,
) -> Result<DrillingSurvey> {
    let lost = lost_numbers(setup.first_station, stations);
    let SurveySetup {
        tie, terms, site, ..
    } = setup;
    let mut skipped = Vec::new();
    let mut kept: Vec<Kept> = Vec::new();
    let (first, last) = depth.span();
    // A station frame received twice (sent again) is one station.
    let mut received = std::collections::HashSet::new();
    for (k, s) in stations.iter().enumerate() {
        if !received.insert((s.station, s.time_us)) {
            continue;
        }
        if let Some(reason) = unusable(s) {
            skipped.push(Skipped {
                survey: *s,
                reason: reason.into(),
                superseded_by: None,
            });
            continue;
        }
        let time_s = s.time_us as f64 * 1e-6;
        let md = depth.md_at(time_s).ok_or_else(|| {
            anyhow!(
                "station {} at {time_s:.2} s is outside the depth log's time span \
                 ({first:.2} s to {last:.2} s): is it this run's log?",
                s.station
            )
        })?;
        if let Some((previous, ..)) = kept.last() {
            if time_s <= previous.time_us as f64 * 1e-6 {
                bail!(
                    "station {} is not later than station {}: the capture holds more than \
                     one run (split it at the boot event)",
                    s.station,
                    previous.station
                );
            }
        }
        // Not beyond the previous station: the string did not move in
        // between; the later station (more still time behind it, or the
        // last dwell of an indexed connection) stands, its link carried
        // back past the one it supersedes.
        let mut link = links.get(k).copied().flatten();
        while let Some((previous, _, prev_md, _, prev_link)) = kept.last() {
            if md > *prev_md {
                break;
            }
            link = prev_link
                .zip(link)
                .and_then(|(dropped, later)| iscwsa::through_superseded(&dropped, &later));
            skipped.push(Skipped {
                survey: *previous,
                reason: format!("superseded by station {} at the same MD", s.station),
                superseded_by: Some(s.station),
            });
            kept.pop();
        }
        kept.push((*s, time_s, md, azi_before.get(k).copied().flatten(), link));
    }
    let Some(&(first_kept, _, first_md, ..)) = kept.first() else {
        bail!("no usable station survey in the capture");
    };
    tie_on_station_known(&lost, first_kept.station, !tie.is_surface())?;
    let md_offset_m = tie.md.map_or(0.0, |md| md - first_md);
    let mut file = StationFile {
        unit: LengthUnit::Metre,
        stations: kept
            .iter()
            .map(|(s, time_s, md, ..)| InputStation {
                md: md + md_offset_m,
                inc_deg: f64::from(s.angles[0]).to_degrees(),
                azi_deg: f64::from(s.angles[1]).to_degrees(),
                toolface_deg: Some(f64::from(s.angles[2]).to_degrees()),
                time_s: Some(*time_s),
            })
            .collect(),
    };
    // The bit at the log's end: its last MD (the tie-on's shift applied)
    // plus the sensor-to-bit distance.
    let log_end_md = depth.md_at(last).map(|md| md + md_offset_m);
    let ahead = setup
        .sensor_to_bit_m
        .zip(log_end_md.zip(file.stations.last()))
        .map(|(d, (end, station))| (end - station.md).max(0.0) + d);
    if let (Some(d), Some(&last)) = (ahead, file.stations.last()) {
        file.stations.push(InputStation {
            md: last.md + d,
            toolface_deg: None,
            time_s: None,
            ..last
        });
    }
    let tie_position = TieOnInput { md: None, ..*tie };
    let (mut rows, _) = compute(&file, AzimuthReference::True, tie_position, None)?;
    let bit_row = ahead.and_then(|_| rows.pop());
    let numbered: Vec<_> = kept.iter().map(|k| (k.0.station, k.4)).collect();
    let sigmas: Vec<Option<AngleSigma>> = kept
        .iter()
        .zip(links_in_order(&numbered))
        .map(|((s, _, _, before, _), link)| {
            azimuth_determined(s).then_some(AngleSigma {
                inc: f64::from(s.angles_std[0]),
                azi: f64::from(s.angles_std[1]),
                corr_inc_azi: f64::from(s.correlations[0]),
                azi_before: *before,
                link,
            })
        })
        .collect();
    let mut covs = covariance(&rows, &sigmas, terms, site, ahead)?;
    with_tie_on(&mut covs, tie);
    let bit_cov = (covs.len() > rows.len()).then(|| covs.pop()).flatten();
    let bit =
        bit_row
            .zip(ahead.zip(setup.sensor_to_bit_m))
            .map(|(mut row, (d, sensor_to_bit_m))| {
                row.cov = bit_cov.map(|c| c.total);
                BitProjection {
                    sensor_to_bit_m,
                    projected_m: d,
                    row,
                    method_cov: bit_cov.map(|c| c.method),
                }
            });
    let rows = kept
        .iter()
        .zip(rows)
        .enumerate()
        .map(|(k, ((s, time_s, ..), mut row))| {
            row.cov = covs.get(k).map(|c| c.total);
            DrillingRow {
                survey: *s,
                time_s: *time_s,
                row,
                method_cov: covs.get(k).map(|c| c.method),
                azimuth_determined: sigmas[k].is_some(),
                position_determined: k < covs.len(),
                qc: None,
                depth_gap_s: depth
                    .interpolation_span(*time_s)
                    .filter(|gap| *gap > setup.depth_gap_limit_s),
            }
        })
        .collect();
    Ok(DrillingSurvey {
        rows,
        skipped,
        lost,
        md_offset_m,
        bit,
        tie_on_cov_m2: tie.covariance_m2(LengthUnit::Metre),
        qc_reference: None,
        uncalibrated: setup.uncalibrated,
        depth_gap_limit_s: setup.depth_gap_limit_s,
    })
}

/// The tie-on's covariance (metres: a drilling survey's unit) added to
/// every position's total (`listing::plus_tie_on`).
pub(super) fn with_tie_on(covs: &mut [PositionCovariance], tie: &TieOnInput) {
    let tie_m2 = tie.covariance_m2(LengthUnit::Metre);
    for c in covs.iter_mut() {
        c.total = super::plus_tie_on(c.total, tie_m2.as_ref());
    }
}

/// A position's NEV covariance, and the survey method's part of it.
#[derive(Clone, Copy, Debug)]
pub struct PositionCovariance {
    pub total: Cov6,
    /// From the method's terms alone (XCLA, XCLH): the part no sensor
    /// makes, which a Monte Carlo of one drilled path cannot sample.
    pub method: Cov6,
}

/// Whether a term is the survey method's (the long-course-length terms)
/// rather than the depth log's.
fn is_method_term(t: &ErrorTerm) -> bool {
    t.weighting.starts_with("XCL")
}

/// NEV covariance of the rows up to (not including) the first one without
/// a determined azimuth: the probe's angle errors plus `terms`
/// ([`survey_terms`]), the latter on MD counted from the tie-on (the log's
/// error at the tie-on is in the tie-on's MD, not in the positions: module
/// docs). With `ahead` (m) and every row determined, one more: the last
/// row projected that far straight ahead ([`BitProjection`]).
pub fn covariance(
    rows: &[Row],
    sigmas: &[Option<AngleSigma>],
    terms: &[ErrorTerm],
    site: &Site,
    ahead: Option<f64>,
) -> Result<Vec<PositionCovariance>> {
    let valid = sigmas.iter().take_while(|s| s.is_some()).count();
    if valid == 0 {
        return Ok(Vec::new());
    }
    let ahead = ahead.filter(|_| valid == rows.len());
    let md0 = rows[0].md_m;
    let mut stations: Vec<Station> = rows[..valid].iter().map(Row::iscwsa_station).collect();
    let sig: Vec<AngleSigma> = sigmas[..valid].iter().flatten().copied().collect();
    // The bit: the last station held straight ahead (its TVD too, for the
    // depth terms).
    if let (Some(d), Some(&last)) = (ahead, stations.last()) {
        stations.push(Station {
            md: last.md + d,
            toolface: None,
            ..last
        });
    }
    let angles = match ahead {
        Some(_) => angle_covariance_projected(&stations, &sig),
        None => angle_covariance(&stations, &sig),
    }
    .map_err(|e| anyhow!("{e}"))?;
    let valid = stations.len();
    let from_tie_on: Vec<Station> = stations
        .iter()
        .map(|s| Station {
            md: s.md - md0,
            ..*s
        })
        .collect();
    let mut others = vec![[0.0; 6]; valid];
    let mut method = vec![[0.0; 6]; valid];
    if valid > 1 {
        let result = iscwsa::run(terms, &from_tie_on, site);
        if !result.missing.is_empty() {
            bail!(
                "survey terms not implemented: {}",
                result.missing.join(", ")
            );
        }
        others = result.total;
        for t in terms.iter().filter(|t| is_method_term(t)) {
            let Some(covs) = result.per_source.get(&t.code) else {
                continue;
            };
            for (m, c) in method.iter_mut().zip(covs) {
                for j in 0..6 {
                    m[j] += c[j];
                }
            }
        }
    }
    Ok(angles
        .iter()
        .zip(others.iter().zip(&method))
        .map(|(a, (o, m))| PositionCovariance {
            total: std::array::from_fn(|j| a[j] + o[j]),
            method: *m,
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn solution(counter: u32, azimuth_std: f32) -> NavSolution {
        NavSolution {
            sample_counter: counter,
            attitude_std: [0.0, 0.0, azimuth_std],
            ..NavSolution::default()
        }
    }

    #[test]
    fn a_station_starts_from_the_last_solution_before_its_first_update() {
        let track: AzimuthSigmaTrack = [solution(10, 0.1), solution(11, 0.2), solution(12, 0.3)]
            .iter()
            .collect();
        assert_eq!(track.before(12), Some(f64::from(0.2f32)));
        assert_eq!(track.before(32), Some(f64::from(0.3f32)));
        // nothing before the first, nothing older than a second
        assert_eq!(track.before(10), None);
        assert_eq!(track.before(33), None);
    }

    #[test]
    fn an_invalid_sigma_or_a_restart_leaves_the_start_unknown() {
        let mut track = AzimuthSigmaTrack::default();
        track.push(&solution(5, f32::INFINITY));
        assert_eq!(track.before(6), None);
        track.push(&solution(6, f32::NAN));
        assert_eq!(track.before(7), None);
        track.push(&solution(7, 0.0));
        assert_eq!(track.before(8), None);
        // a counter that goes back is a new run: the old one is forgotten
        track.push(&solution(100, 0.5));
        track.push(&solution(3, 0.25));
        assert_eq!(track.before(101), None);
        assert_eq!(track.before(4), Some(0.25));
    }

    #[test]
    fn a_taken_station_keeps_only_what_a_later_station_can_start_from() {
        let mut track: AzimuthSigmaTrack = (0..50)
            .map(|k| solution(k, 0.5))
            .collect::<Vec<_>>()
            .iter()
            .collect();
        let station = StationSurvey {
            start_sample: 30,
            end_sample: 40,
            ..StationSurvey::default()
        };
        assert_eq!(
            track.station_start_solution(&station).map(|s| s.sigma),
            Some(0.5)
        );
        assert_eq!(track.points.len(), 10);
        assert_eq!(track.before(45), Some(0.5));
        assert_eq!(track.before(40), None);
    }
}
