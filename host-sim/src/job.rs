//! The job file: what one run needs on the probe, in one JSON file that
//! `host-sim probe configure` sends (and, later, `survey` and `replay`
//! read, so one file describes a run end to end).
//!
//! ```json
//! {
//!   "format": "mwd-job", "version": 1,
//!   "site": { "latitude_deg": 45.77755, "longitude_deg": 126.687898, "height_m": 124.0 },
//!   "tie_in": { "inclination_deg": 88.0, "azimuth_deg": 271.0, "toolface_deg": 15.0,
//!               "inclination_sigma_deg": 0.1, "azimuth_sigma_deg": 1.5,
//!               "toolface_sigma_deg": 0.3 },
//!   "calibration_file": "probe-cal.json"
//! }
//! ```
//! `tie_in` and `calibration_file` are optional (absent: the static
//! alignment, no correction); a relative calibration path is taken from
//! the job file's folder. Every number is checked when the file is read,
//! by the rules the probe applies (`probe::TieIn::new`, and the uplink's
//! own decoding of each command), so a job the host accepts the probe
//! does not refuse.

use crate::analysis::calibration_file::CalibrationFile;
use crate::analysis::text_records::read_small_file;
use anyhow::{bail, Context, Result};
use mwd_core::calibration::ProbeCalibration;
use mwd_core::conventions::{DrillingAngles, DEG};
use mwd_core::earth::Position;
use mwd_core::probe::TieIn;
use mwd_core::protocol::uplink::{
    decode_command, encode_command_body, Command, UplinkError, MAX_COMMAND_BODY_LEN,
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

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct JobEntry {
    format: String,
    version: u32,
    site: SiteEntry,
    tie_in: Option<TieInEntry>,
    calibration_file: Option<PathBuf>,
}

/// A checked job.
#[derive(Debug, Clone, PartialEq)]
pub struct Job {
    pub site: Position,
    pub tie_in: Option<TieIn>,
    /// With the file it came from, if any.
    pub calibration: Option<(PathBuf, ProbeCalibration)>,
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
        let job = Self {
            site,
            tie_in,
            calibration,
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
    }
}
