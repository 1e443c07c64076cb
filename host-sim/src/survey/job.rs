//! The job file: what one run needs, in one JSON file that
//! `host-sim probe configure` sends to the probe and that `host-sim survey`
//! and `host-sim replay` read (`--job`), so one file describes a run end to
//! end.
//!
//! ```json
//! {
//!   "format": "mwd-job", "version": 1,
//!   "site": { "latitude_deg": 45.77755, "longitude_deg": 126.687898, "height_m": 124.0 },
//!   "tie_in": { "inclination_deg": 88.0, "azimuth_deg": 271.0, "toolface_deg": 15.0,
//!               "inclination_sigma_deg": 0.1, "azimuth_sigma_deg": 1.5,
//!               "toolface_sigma_deg": 0.3 },
//!   "calibration_file": "probe-cal.json",
//!   "still": { "z_enter": 3.09, "z_stay": 5.199, "enter_epochs": 20,
//!              "max_station_samples": 6000, "zupt_velocity_sigma": 0.01 },
//!   "survey": { "length_unit": "ft", "error_model": "PROBE-SCC1300",
//!               "tie_on": { "md": 1500.0, "tvd": 1480.0, "north": 12.0, "east": -3.5 } }
//! }
//! ```
//! `tie_in`, `calibration_file` and `still` are optional (absent: the
//! static alignment, no correction, the probe's still settings left as
//! they are); a relative calibration path is taken from the job file's
//! folder. `still` is the still detector's and the station's settings
//! (uplink command 0x44, `protocol::uplink::StillSettings`, all five
//! fields, with its ranges; the defaults are the values above). `survey` is optional and only the host reads it:
//! the tie-on (the well's position where the survey starts, in
//! `length_unit`, "m" or "ft", default "m"; every part optional, as the
//! `--tie-on-*` flags) and the tool's error model (a name `survey
//! --error-model` takes).
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
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct SurveyEntry {
    length_unit: Option<String>,
    tie_on: Option<TieOnEntry>,
    error_model: Option<String>,
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
}

impl Default for JobTieOn {
    fn default() -> Self {
        Self {
            unit: LengthUnit::Metre,
            md: None,
            tvd: None,
            north: None,
            east: None,
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
        }
    }
}

/// What `host-sim survey` takes from a job.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SurveyJob {
    pub tie_on: JobTieOn,
    /// A name `survey_listing::model` knows (checked when read).
    pub error_model: Option<String>,
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
}

/// The range `survey --tie-on-*` takes, in the length unit given.
const TIE_ON_LIMIT: f64 = 1e6;

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
        };
        if let Some(name) = &self.error_model {
            listing::model(name).context("survey.error_model")?;
        }
        Ok(SurveyJob {
            tie_on,
            error_model: self.error_model,
        })
    }
}

/// Longitude in (-180, 180] deg, as the uplink carries it (the host also
/// takes 0..360 east).
fn wrapped_longitude(deg: f64) -> f64 {
    if deg > 180.0 {
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
mod tests {
    use super::*;

    const JOB: &str = r#"{"format": "mwd-job", "version": 1,
        "site": {"latitude_deg": 30.0, "longitude_deg": 270.0, "height_m": 12.5},
        "tie_in": {"inclination_deg": 88.0, "azimuth_deg": 271.0, "toolface_deg": 15.0,
                   "inclination_sigma_deg": 0.1, "azimuth_sigma_deg": 1.5,
                   "toolface_sigma_deg": 0.3}}"#;

    #[test]
    fn a_job_becomes_the_commands_that_configure_the_probe() {
        let job = Job::parse(JOB, Path::new(".")).unwrap();
        assert_eq!(job.site, Position::from_degrees(30.0, -90.0, 12.5));
        let commands = job.commands();
        assert_eq!(commands.len(), 4);
        assert!(matches!(commands[1].1, Command::SetTieIn { .. }));
        assert!(
            commands[1].0.contains("271.000 +- 1.500 deg"),
            "{}",
            commands[1].0
        );
        assert_eq!(
            commands[3].1,
            Command::SetCalibration {
                part: 1,
                accel: Default::default(),
                gyro: Default::default()
            }
        );
    }

    #[test]
    fn bad_jobs_are_refused_with_the_reason() {
        let refused = |text: &str, needle: &str| {
            let e = format!("{:#}", Job::parse(text, Path::new(".")).unwrap_err());
            assert!(e.contains(needle), "{e}");
        };
        refused(&JOB.replace("88.0", "0.5"), "vertical");
        refused(
            &JOB.replace("\"height_m\": 12.5", "\"height_m\": 1e9"),
            "height",
        );
        refused(&JOB.replace("mwd-job", "other"), "version 1");
        refused(&JOB.replace("\"site\"", "\"sight\""), "mwd-job v1");
        refused(
            &JOB.replace("}}", "}, \"calibration_file\": \"/nonexistent/cal.json\"}"),
            "cal.json",
        );
        let with_survey = |survey: &str| JOB.replace("}}", &format!("}}, \"survey\": {survey}}}"));
        refused(&with_survey(r#"{"length_unit": "yd"}"#), "\"yd\"");
        refused(&with_survey(r#"{"tie_on": {"md": 1e7}}"#), "tie_on.md");
        refused(
            &with_survey(r#"{"error_model": "NOPE"}"#),
            "unknown error model",
        );
        refused(&with_survey(r#"{"tie_on": {"mdd": 1}}"#), "mdd");
    }

    const STILL: &str = r#"{"z_enter": 3.5, "z_stay": 6.0, "enter_epochs": 40,
        "max_station_samples": 1200, "zupt_velocity_sigma": 0.02}"#;

    fn with_still(still: &str) -> String {
        JOB.replace("}}", &format!("}}, \"still\": {still}}}"))
    }

    #[test]
    fn a_jobs_still_settings_are_sent_last_and_only_if_given() {
        let job = Job::parse(&with_still(STILL), Path::new(".")).unwrap();
        let expected = StillSettings {
            z_enter: 3.5,
            z_stay: 6.0,
            enter_epochs: 40,
            max_station_samples: 1200,
            zupt_velocity_sigma: 0.02,
        };
        assert_eq!(job.still, Some(expected));
        let commands = job.commands();
        assert_eq!(commands.len(), 5);
        let (label, command) = &commands[4];
        assert_eq!(*command, Command::SetStillSettings(expected));
        assert!(label.contains("enter_epochs 40"), "{label}");
        let plain = Job::parse(JOB, Path::new(".")).unwrap();
        assert_eq!(plain.still, None);
        assert!(plain
            .commands()
            .iter()
            .all(|(_, c)| !matches!(c, Command::SetStillSettings(_))));
    }

    #[test]
    fn still_settings_out_of_the_probes_ranges_are_refused_by_name() {
        let refused = |from: &str, to: &str, needle: &str| {
            let text = with_still(&STILL.replace(from, to));
            let e = format!("{:#}", Job::parse(&text, Path::new(".")).unwrap_err());
            assert!(e.contains(needle), "{from} -> {to}: {e}");
        };
        refused(
            "\"z_enter\": 3.5",
            "\"z_enter\": 1.5",
            "still entering quantile",
        );
        // Staying must be easier than entering.
        refused(
            "\"z_stay\": 6.0",
            "\"z_stay\": 3.0",
            "still staying quantile",
        );
        refused(
            "\"enter_epochs\": 40",
            "\"enter_epochs\": 0",
            "still entering epochs",
        );
        refused(
            "\"enter_epochs\": 40",
            "\"enter_epochs\": 70000",
            "still entering epochs",
        );
        refused("1200", "-5", "longest station");
        refused("1200", "5000000000", "longest station");
        refused("1200", "100", "longest station");
        refused("0.02", "2.0", "station ZUPT velocity sigma");
        refused("0.02", "-0.02", "station ZUPT velocity sigma");
        refused(", \"zupt_velocity_sigma\": 0.02", "", "zupt_velocity_sigma");
        refused("\"z_enter\"", "\"z_entre\"", "z_entre");
        refused("3.5", "\"3.5\"", "expected f64");
    }

    #[test]
    fn the_survey_part_is_read_in_its_unit_and_converted() {
        let job = Job::parse(
            &JOB.replace(
                "}}",
                r#"}, "survey": {"length_unit": "ft", "error_model": "gyro-mwd",
                      "tie_on": {"md": 1000.0, "north": -10.0}}}"#,
            ),
            Path::new("."),
        )
        .unwrap();
        let t = job.survey.tie_on;
        assert_eq!(
            (t.unit, t.md, t.north),
            (LengthUnit::Foot, Some(1000.0), Some(-10.0))
        );
        assert_eq!((t.tvd, t.east), (None, None));
        let m = t.in_unit(LengthUnit::Metre);
        assert!((m.md.unwrap() - 304.8).abs() < 1e-12, "{m:?}");
        assert!((m.north.unwrap() + 3.048).abs() < 1e-12, "{m:?}");
        assert_eq!(t.in_unit(LengthUnit::Foot), t);
        assert_eq!(job.survey.error_model.as_deref(), Some("gyro-mwd"));
        let plain = Job::parse(JOB, Path::new(".")).unwrap();
        assert_eq!(plain.survey, SurveyJob::default());
    }
}
