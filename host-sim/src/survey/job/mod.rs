//! The job file: what one run needs, in one JSON file that
//! `host-sim probe configure` sends to the probe and that `host-sim survey`,
//! `host-sim replay` and `host-sim drill` read (`--job`), so one file
//! describes a run end to end. `examples/lateral-100m/job.json` is one
//! that runs as it is.
//!
//! ```json
//! {
//!   "format": "mwd-job", "version": 1,
//!   "site": { "latitude_deg": 45.77755, "longitude_deg": 126.687898, "height_m": 124.0 },
//!   "well": { "name": "Parent 1", "uid": "parent-1",
//!             "wellbore": "Parent 1 lateral A", "wellbore_uid": "parent-1-la" },
//!   "plan": "plan.json",
//!   "tie_in": { "inclination_deg": 88.0, "azimuth_deg": 271.0, "toolface_deg": 15.0,
//!               "inclination_sigma_deg": 0.1, "azimuth_sigma_deg": 1.5,
//!               "toolface_sigma_deg": 0.3 },
//!   "calibration_file": "probe-cal.json",
//!   "still": { "z_enter": 3.09, "z_stay": 5.199, "enter_epochs": 20,
//!              "max_station_samples": 6000, "zupt_velocity_sigma": 0.01 },
//!   "survey": { "length_unit": "ft", "error_model": "PROBE-SCC1300",
//!               "tie_on": { "md": 1500.0, "tvd": 1480.0, "north": 12.0, "east": -3.5,
//!                           "sigma": { "north": 1.5, "east": 1.5, "tvd": 0.8 } },
//!               "sensor_to_bit": 40.0 }
//! }
//! ```
//! Only `format`, `version` and `site` are required. Without `tie_in`,
//! `calibration_file` or `still`: the static alignment, no correction, the
//! probe's still settings left as they are. Paths (`calibration_file`,
//! `plan`) are taken from the job file's folder, so a job runs from any
//! directory. `still` is the still detector's and the station's settings
//! (uplink command 0x44, `protocol::uplink::StillSettings`, all five
//! fields, with its ranges; the defaults are the values above). `well`
//! names the well and wellbore (the WITSML trajectory's names and uids;
//! all four keys). `plan` is the well plan a simulated run drills
//! (`host-sim drill`, `sim::plan`). `survey` only the host reads: the
//! tie-on (the well's position where the survey starts, in `length_unit`,
//! "m" or "ft", default "m"; every part optional, as the `--tie-on-*`
//! flags; its position uncertainty, the parent well's where the lateral
//! leaves it, as `sigma` (1-sigma north, east, tvd, uncorrelated) or as
//! `covariance` (nn, ne, nv, ee, ev, vv in the unit squared, as the parent
//! well's survey lists it at the tie-on), added to every station's), the
//! tool's error model (a name `survey --error-model` takes) and
//! the distance from the survey sensors to the bit (in `length_unit`),
//! for the projection to the bit.
//!
//! Who reads what: `probe configure` sends the site, tie-in, calibration
//! and still settings; `survey` takes the site's latitude, the tie-on and
//! the error model (a capture survey, `--depth`, has the probe's own model
//! and refuses another), and to replay a capture for its station links
//! the site, calibration, still settings and tie-in; `replay` takes the
//! site, the calibration, the still settings and the tie-in (taken after
//! the first navigating cycle, as the probe takes it; a job's settings
//! are compared as post-processing: the capture's probe may not have had
//! them). Command-line flags override the job. A station
//! survey's first MD must equal the tie-on MD exactly: give the job's
//! tie-on in the station file's unit (converted from the other unit, an MD
//! may miss it by a rounding).
//!
//! Every number is checked when the file is read, by the rules the probe
//! applies (`probe::TieIn::new`, and the uplink's own decoding of each
//! command, and `survey`'s ranges), so a job the host accepts the probe
//! does not refuse.

use crate::analysis::calibration_file::CalibrationFile;
use crate::formats::text_records::read_small_file;
use crate::survey::iscwsa::Cov6;
use crate::survey::listing::{self, LengthUnit};
use anyhow::{bail, Context, Result};
use mwd_core::calibration::ProbeCalibration;
use mwd_core::conventions::{DrillingAngles, DEG};
use mwd_core::earth::Position;
use mwd_core::probe::TieIn;
use mwd_core::protocol::uplink::{
    decode_command, encode_command_body, Command, StillSettings, UplinkError, MAX_COMMAND_BODY_LEN,
};
use serde::Deserialize;
use std::path::{Path, PathBuf};

pub const FORMAT: &str = "mwd-job";
pub const VERSION: u32 = 1;

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct SiteEntry {
    latitude_deg: f64,
    longitude_deg: f64,
    height_m: f64,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct TieInEntry {
    inclination_deg: f64,
    azimuth_deg: f64,
    toolface_deg: f64,
    inclination_sigma_deg: f64,
    azimuth_sigma_deg: f64,
    toolface_sigma_deg: f64,
}

/// The uplink's still settings. Read wide and narrowed to the wire's
/// types (f32, u16, u32; saturating, far beyond every range) so that the
/// probe's own range check (`probe_accepts`) names a field out of range
/// whatever its size; the host sends and replays the narrowed values, what
/// the probe keeps.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct StillEntry {
    z_enter: f64,
    z_stay: f64,
    enter_epochs: i64,
    max_station_samples: i64,
    zupt_velocity_sigma: f64,
}

impl StillEntry {
    fn narrowed(&self) -> StillSettings {
        let saturated = |v: i64, max: u32| u32::try_from(v.clamp(0, i64::from(max))).unwrap_or(max);
        StillSettings {
            z_enter: self.z_enter as f32,
            z_stay: self.z_stay as f32,
            enter_epochs: saturated(self.enter_epochs, u32::from(u16::MAX)) as u16,
            max_station_samples: saturated(self.max_station_samples, u32::MAX),
            zupt_velocity_sigma: self.zupt_velocity_sigma as f32,
        }
    }
}

#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct TieOnEntry {
    md: Option<f64>,
    tvd: Option<f64>,
    north: Option<f64>,
    east: Option<f64>,
    /// 1-sigma of the tie-on's position, uncorrelated (length unit).
    sigma: Option<TieOnSigmaEntry>,
    /// The tie-on's NEV position covariance (length unit squared), as a
    /// parent well's survey gives it at the tie-on.
    covariance: Option<TieOnCovarianceEntry>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct TieOnSigmaEntry {
    north: f64,
    east: f64,
    tvd: f64,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct TieOnCovarianceEntry {
    nn: f64,
    ne: f64,
    nv: f64,
    ee: f64,
    ev: f64,
    vv: f64,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct SurveyEntry {
    length_unit: Option<String>,
    tie_on: Option<TieOnEntry>,
    error_model: Option<String>,
    sensor_to_bit: Option<f64>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct WellEntry {
    name: String,
    uid: String,
    wellbore: String,
    wellbore_uid: String,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct JobEntry {
    format: String,
    version: u32,
    site: SiteEntry,
    tie_in: Option<TieInEntry>,
    calibration_file: Option<PathBuf>,
    still: Option<StillEntry>,
    survey: Option<SurveyEntry>,
    well: Option<WellEntry>,
    plan: Option<PathBuf>,
}

/// The survey's tie-on from a job, in the job's length unit (true north);
/// each part as optional as its `--tie-on-*` flag.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JobTieOn {
    pub unit: LengthUnit,
    pub md: Option<f64>,
    pub tvd: Option<f64>,
    pub north: Option<f64>,
    pub east: Option<f64>,
    /// The tie-on's NEV position covariance in `unit` squared (`Cov6`:
    /// nn, ee, vv, ne, nv, ev): the parent well's uncertainty where the lateral
    /// leaves it, common to every station of the lateral.
    pub covariance: Option<Cov6>,
}

impl Default for JobTieOn {
    fn default() -> Self {
        Self {
            unit: LengthUnit::Metre,
            md: None,
            tvd: None,
            north: None,
            east: None,
            covariance: None,
        }
    }
}

impl JobTieOn {
    /// The tie-on in `unit`; the same unit keeps the numbers to the bit
    /// (a station file's first MD must equal the tie-on MD exactly).
    pub fn in_unit(&self, unit: LengthUnit) -> Self {
        let convert = |v: Option<f64>| {
            v.map(|v| {
                if unit == self.unit {
                    v
                } else {
                    v * self.unit.to_m() / unit.to_m()
                }
            })
        };
        Self {
            unit,
            md: convert(self.md),
            tvd: convert(self.tvd),
            north: convert(self.north),
            east: convert(self.east),
            covariance: self.covariance.map(|c| {
                let k = if unit == self.unit {
                    1.0
                } else {
                    (self.unit.to_m() / unit.to_m()).powi(2)
                };
                c.map(|v| v * k)
            }),
        }
    }
}

/// What `host-sim survey` takes from a job.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SurveyJob {
    pub tie_on: JobTieOn,
    /// A name `survey_listing::model` knows (checked when read).
    pub error_model: Option<String>,
    /// From the survey sensors to the bit along the hole, in the tie-on's
    /// length unit: the survey projects its last station this far ahead.
    pub sensor_to_bit: Option<f64>,
}

/// The names and uids of the well and the wellbore the survey belongs to,
/// as the WITSML trajectory and the figures carry them.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct WellNames {
    pub well: String,
    pub well_uid: String,
    pub wellbore: String,
    pub wellbore_uid: String,
}

impl Default for WellNames {
    /// Placeholders a reader sees as such.
    fn default() -> Self {
        Self {
            well: "unnamed well".into(),
            well_uid: "well".into(),
            wellbore: "unnamed wellbore".into(),
            wellbore_uid: "wellbore".into(),
        }
    }
}

impl WellEntry {
    fn checked(self) -> Result<WellNames> {
        for (key, value) in [
            ("name", &self.name),
            ("uid", &self.uid),
            ("wellbore", &self.wellbore),
            ("wellbore_uid", &self.wellbore_uid),
        ] {
            let trimmed = value.trim();
            if trimmed.is_empty() || trimmed.len() != value.len() || value.len() > 64 {
                bail!("well.{key} {value:?}: expected 1 to 64 characters, no spaces at either end");
            }
            if value.chars().any(char::is_control) {
                bail!("well.{key} {value:?}: control characters are not allowed");
            }
        }
        Ok(WellNames {
            well: self.name,
            well_uid: self.uid,
            wellbore: self.wellbore,
            wellbore_uid: self.wellbore_uid,
        })
    }
}

/// A checked job.
#[derive(Debug, Clone, PartialEq)]
pub struct Job {
    pub site: Position,
    pub tie_in: Option<TieIn>,
    /// With the file it came from, if any.
    pub calibration: Option<(PathBuf, ProbeCalibration)>,
    /// `None`: the probe's are left as they are (the replay takes the
    /// defaults); its ranges are checked by the probe's decoding.
    pub still: Option<StillSettings>,
    pub survey: SurveyJob,
    pub well: WellNames,
    /// The well plan (`sim::plan`) a simulated run drills, resolved
    /// against the job file's folder; checked to exist when read.
    pub plan: Option<PathBuf>,
}

/// The range `survey --tie-on-*` takes, in the length unit given.
const TIE_ON_LIMIT: f64 = 1e6;

/// The longest sensor-to-bit distance taken, m: a bottom-hole assembly
/// places its survey sensors a few metres to a few tens of metres behind
/// the bit.
const SENSOR_TO_BIT_LIMIT_M: f64 = 100.0;

impl SurveyEntry {
    fn checked(self) -> Result<SurveyJob> {
        let unit = match self.length_unit.as_deref() {
            None | Some("m") => LengthUnit::Metre,
            Some("ft") => LengthUnit::Foot,
            Some(other) => bail!("survey.length_unit {other:?}: expected \"m\" or \"ft\""),
        };
        let t = self.tie_on.unwrap_or_default();
        let checked = |name: &str, v: Option<f64>| -> Result<Option<f64>> {
            match v {
                Some(v) if !(v.is_finite() && v.abs() <= TIE_ON_LIMIT) => bail!(
                    "survey.tie_on.{name} = {v}: expected a finite number within +-{TIE_ON_LIMIT}"
                ),
                v => Ok(v),
            }
        };
        let tie_on = JobTieOn {
            unit,
            md: checked("md", t.md)?,
            tvd: checked("tvd", t.tvd)?,
            north: checked("north", t.north)?,
            east: checked("east", t.east)?,
            covariance: tie_on_covariance(t.sigma, t.covariance)?,
        };
        if let Some(name) = &self.error_model {
            listing::model(name).context("survey.error_model")?;
        }
        let limit = SENSOR_TO_BIT_LIMIT_M / unit.to_m();
        if let Some(d) = self.sensor_to_bit {
            if !(d.is_finite() && (0.0..=limit).contains(&d)) {
                bail!("survey.sensor_to_bit = {d}: expected 0 to {limit:.0} (the survey's length unit)");
            }
        }
        Ok(SurveyJob {
            tie_on,
            error_model: self.error_model,
            sensor_to_bit: self.sensor_to_bit,
        })
    }
}

/// The largest tie-on position sigma taken (length unit): a parent well's
/// position is known to metres or tens of metres, not kilometres.
const TIE_ON_SIGMA_LIMIT: f64 = 1e3;

/// The tie-on's covariance from `sigma` (uncorrelated) or `covariance`
/// (one of them), checked: finite, variances within the limit, and
/// positive semi-definite (no direction with a negative variance).
fn tie_on_covariance(
    sigma: Option<TieOnSigmaEntry>,
    covariance: Option<TieOnCovarianceEntry>,
) -> Result<Option<Cov6>> {
    let cov = match (sigma, covariance) {
        (Some(_), Some(_)) => {
            bail!("survey.tie_on: give sigma or covariance, not both")
        }
        (None, None) => return Ok(None),
        (Some(s), None) => {
            for (name, v) in [("north", s.north), ("east", s.east), ("tvd", s.tvd)] {
                if !(v.is_finite() && (0.0..=TIE_ON_SIGMA_LIMIT).contains(&v)) {
                    bail!(
                        "survey.tie_on.sigma.{name} = {v}: expected 0 to {TIE_ON_SIGMA_LIMIT} \
                         (the survey's length unit)"
                    );
                }
            }
            [
                s.north.powi(2),
                s.east.powi(2),
                s.tvd.powi(2),
                0.0,
                0.0,
                0.0,
            ]
        }
        (None, Some(c)) => {
            let cov = [c.nn, c.ee, c.vv, c.ne, c.nv, c.ev];
            let limit = TIE_ON_SIGMA_LIMIT.powi(2);
            for (name, v) in ["nn", "ee", "vv", "ne", "nv", "ev"].iter().zip(cov) {
                if !(v.is_finite() && v.abs() <= limit) {
                    bail!(
                        "survey.tie_on.covariance.{name} = {v}: expected a finite number within \
                         +-{limit} (the survey's length unit squared)"
                    );
                }
            }
            let m = crate::survey::iscwsa::cov_matrix(&cov);
            let least = m.symmetric_eigenvalues().min();
            // a rounding below the matrix's own scale is not a negative
            // variance
            if least < -1e-9 * m.trace().max(f64::MIN_POSITIVE) {
                bail!(
                    "survey.tie_on.covariance is not a covariance: it has a direction with \
                     variance {least:.3e} (negative)"
                );
            }
            cov
        }
    };
    Ok(Some(cov))
}

/// Longitude in (-180, 180] deg, as the uplink carries it (the host also
/// takes 0..360 east). Past 360 it is left as it is, for the site's check
/// to refuse: a longitude of 400 is a typing error, not 40 deg east.
fn wrapped_longitude(deg: f64) -> f64 {
    if deg > 180.0 && deg <= 360.0 {
        deg - 360.0
    } else {
        deg
    }
}

impl Job {
    pub fn load(path: &Path) -> Result<Self> {
        let text =
            read_small_file(path).with_context(|| format!("cannot read {}", path.display()))?;
        let folder = path.parent().unwrap_or(Path::new("."));
        Self::parse(&text, folder).with_context(|| format!("in job file {}", path.display()))
    }

    /// Reads a job's text; calibration paths are relative to `folder`.
    pub fn parse(text: &str, folder: &Path) -> Result<Self> {
        let entry: JobEntry = serde_json::from_str(text)
            .map_err(|e| anyhow::anyhow!("not a {FORMAT} v{VERSION} JSON file: {e}"))?;
        if entry.format != FORMAT || entry.version != VERSION {
            bail!(
                "format {:?} version {}: this tool reads {FORMAT:?} version {VERSION}",
                entry.format,
                entry.version
            );
        }
        let s = &entry.site;
        let site = Position::from_degrees(
            s.latitude_deg,
            wrapped_longitude(s.longitude_deg),
            s.height_m,
        );
        let tie_in = entry
            .tie_in
            .map(|t| {
                let rad = |i: f64, a: f64, tf: f64| DrillingAngles {
                    inclination: i * DEG,
                    azimuth: a * DEG,
                    toolface: tf * DEG,
                };
                TieIn::new(
                    rad(t.inclination_deg, t.azimuth_deg, t.toolface_deg),
                    rad(
                        t.inclination_sigma_deg,
                        t.azimuth_sigma_deg,
                        t.toolface_sigma_deg,
                    ),
                )
                .map_err(|e| anyhow::anyhow!("tie_in: {e}"))
            })
            .transpose()?;
        let calibration = entry
            .calibration_file
            .map(|file| {
                let path = folder.join(file);
                CalibrationFile::load(&path).map(|c| (path, c.to_probe()))
            })
            .transpose()?;
        let still = entry.still.as_ref().map(StillEntry::narrowed);
        let well = entry
            .well
            .map(WellEntry::checked)
            .transpose()?
            .unwrap_or_default();
        let plan = entry
            .plan
            .map(|file| {
                let path = folder.join(&file);
                if path.is_file() {
                    Ok(path)
                } else {
                    Err(anyhow::anyhow!("plan: {} is not a file", path.display()))
                }
            })
            .transpose()?;
        let survey = entry
            .survey
            .map(SurveyEntry::checked)
            .transpose()?
            .unwrap_or_default();
        let job = Self {
            site,
            tie_in,
            calibration,
            still,
            survey,
            well,
            plan,
        };
        for (label, command) in job.commands() {
            probe_accepts(&command).with_context(|| format!("the probe would refuse: {label}"))?;
        }
        Ok(job)
    }

    /// The commands that put this job on the probe, each with what a
    /// person reads about it.
    pub fn commands(&self) -> Vec<(String, Command)> {
        let s = &self.site;
        let mut out = vec![(
            format!(
                "set site {:.6} deg, {:.6} deg, {:.1} m",
                s.lat.to_degrees(),
                s.lon.to_degrees(),
                s.height
            ),
            Command::SetSite(*s),
        )];
        out.push(match &self.tie_in {
            Some(t) => {
                let (a, sd) = (t.angles(), t.sigma());
                (
                    format!(
                        "set tie-in inclination {:.3} +- {:.3} deg, azimuth {:.3} +- {:.3} deg, \
                         toolface {:.3} +- {:.3} deg",
                        a.inclination / DEG,
                        sd.inclination / DEG,
                        a.azimuth / DEG,
                        sd.azimuth / DEG,
                        a.toolface / DEG,
                        sd.toolface / DEG
                    ),
                    Command::SetTieIn {
                        angles: a,
                        sigma: sd,
                    },
                )
            }
            None => (
                "clear tie-in (static alignment)".to_string(),
                Command::ClearTieIn,
            ),
        });
        let (label, calibration) = match &self.calibration {
            Some((path, c)) => (path.display().to_string(), *c),
            None => (
                "none: no correction".to_string(),
                ProbeCalibration::default(),
            ),
        };
        for part in 0..2u8 {
            let i = usize::from(part);
            out.push((
                format!("set part {part} calibration ({label})"),
                Command::SetCalibration {
                    part,
                    accel: calibration.accel[i],
                    gyro: calibration.gyro[i],
                },
            ));
        }
        if let Some(s) = &self.still {
            out.push((
                format!(
                    "set still settings z_enter {}, z_stay {}, enter_epochs {}, \
                     max_station_samples {}, zupt_velocity_sigma {} m/s",
                    s.z_enter,
                    s.z_stay,
                    s.enter_epochs,
                    s.max_station_samples,
                    s.zupt_velocity_sigma
                ),
                Command::SetStillSettings(*s),
            ));
        }
        out
    }
}

/// The probe's own decoding of `command` (its ranges, one place): what it
/// would NAK as out of range is refused here, before anything is sent.
fn probe_accepts(command: &Command) -> Result<()> {
    let mut body = [0u8; MAX_COMMAND_BODY_LEN];
    let n = encode_command_body(0, command, &mut body)?;
    match decode_command(&body[..n]) {
        Ok(_) => Ok(()),
        Err(UplinkError::OutOfRange { field, .. }) => {
            bail!("the {} is out of its range", field.name())
        }
        Err(e) => bail!("{e}"),
    }
}

#[cfg(test)]
mod tests;
