//! The calibration file `host-sim calibrate` writes: JSON holding, per
//! accelerometer triad, the probe's correction (bias and M = K^-1, SI
//! units) and, per gyro, its bias (rad/s). It loads into the correction
//! types of `mwd_core::calibration`, which the simulator and probe apply.

use anyhow::{bail, Context, Result};
use mwd_core::calibration::{GyroCalibration, ProbeCalibration, TriadCalibration};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Tag of the file format.
pub const FORMAT: &str = "mwd-calibration";
/// Current format version.
pub const VERSION: u32 = 1;

/// One triad's correction.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TriadEntry {
    /// Input columns, x y z.
    pub columns: [String; 3],
    /// Zero offsets (m/s^2).
    pub bias: [f64; 3],
    /// Row-major M = K^-1.
    pub correction: [[f64; 3]; 3],
}

/// One gyro's correction.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GyroEntry {
    /// Input column.
    pub column: String,
    /// Body axis sensed: "x", "y" or "z".
    pub axis: String,
    /// Bias (rad/s).
    pub bias: f64,
    /// Scale factor applied (1 unless set by hand).
    pub scale: f64,
}

/// The file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CalibrationFile {
    /// Always [`FORMAT`].
    pub format: String,
    /// [`VERSION`].
    pub version: u32,
    /// "ls" or "tls": how the triads were fitted.
    pub method: String,
    /// Latitude used for earth rate (deg).
    pub latitude_deg: f64,
    /// Gravity magnitude used for the references (m/s^2).
    pub gravity: f64,
    /// Accelerometer triads.
    pub accel: Vec<TriadEntry>,
    /// Gyros.
    pub gyro: Vec<GyroEntry>,
}

impl TriadEntry {
    /// The probe's correction type.
    pub fn to_core(&self) -> TriadCalibration {
        TriadCalibration {
            bias: self.bias,
            correction: self.correction,
        }
    }
}

impl GyroEntry {
    /// The probe's correction type.
    pub fn to_core(&self) -> GyroCalibration {
        GyroCalibration {
            bias: self.bias,
            scale: self.scale,
        }
    }
}

impl CalibrationFile {
    /// Parses and checks a calibration file's text.
    pub fn parse(text: &str) -> Result<Self> {
        let file: Self = serde_json::from_str(text)?;
        if file.format != FORMAT || file.version != VERSION {
            bail!(
                "not a {FORMAT} v{VERSION} file (format `{}`, version {})",
                file.format,
                file.version
            );
        }
        for t in &file.accel {
            let finite = t
                .bias
                .iter()
                .chain(t.correction.iter().flatten())
                .all(|v| v.is_finite());
            if !finite {
                bail!(
                    "triad {}: a calibration value is not a finite number",
                    t.columns.join(",")
                );
            }
        }
        for g in &file.gyro {
            if !(g.bias.is_finite() && g.scale.is_finite() && g.scale != 0.0) {
                bail!(
                    "gyro {}: bias {} / scale {} unusable",
                    g.column,
                    g.bias,
                    g.scale
                );
            }
        }
        Ok(file)
    }

    /// Loads a calibration file.
    pub fn load(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path)
            .with_context(|| format!("cannot read {}", path.display()))?;
        Self::parse(&text).with_context(|| format!("in {}", path.display()))
    }

    /// Writes the file as pretty JSON.
    pub fn save(&self, path: &Path) -> Result<()> {
        let text = serde_json::to_string_pretty(self)? + "\n";
        std::fs::write(path, text).with_context(|| format!("cannot write {}", path.display()))
    }

    /// The probe's whole correction: the first two triads (x-gyro part,
    /// z-gyro part) and the gyros on body x and z; identity where absent.
    /// A file of one triad was fitted on the body-frame force both parts
    /// share (the simulator's CSV and the host's tools carry one): it
    /// corrects both parts, so the probe's average of the two corrected
    /// triads is that triad corrected.
    pub fn to_probe(&self) -> ProbeCalibration {
        let mut p = ProbeCalibration::default();
        for (slot, t) in p.accel.iter_mut().zip(self.accel.iter().cycle()) {
            *slot = t.to_core();
        }
        for g in &self.gyro {
            match g.axis.as_str() {
                "x" => p.gyro[0] = g.to_core(),
                "z" => p.gyro[1] = g.to_core(),
                _ => {}
            }
        }
        p
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_checks() {
        let file = CalibrationFile {
            format: FORMAT.into(),
            version: VERSION,
            method: "tls".into(),
            latitude_deg: mwd_core::earth::Position::paper_site().lat.to_degrees(),
            gravity: 9.806,
            accel: vec![TriadEntry {
                columns: ["ax".into(), "ay".into(), "az".into()],
                bias: [0.01, -0.02, 0.003],
                correction: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            }],
            gyro: vec![GyroEntry {
                column: "gz".into(),
                axis: "z".into(),
                bias: 1e-5,
                scale: 1.0,
            }],
        };
        let text = serde_json::to_string(&file).unwrap();
        let back = CalibrationFile::parse(&text).unwrap();
        assert_eq!(back, file);
        let probe = back.to_probe();
        assert_eq!(probe.accel[0].bias, [0.01, -0.02, 0.003]);
        // One triad (the body frame's) corrects both parts.
        assert_eq!(probe.accel[1], probe.accel[0]);
        assert_eq!(probe.gyro[1].bias, 1e-5);
        assert_eq!(probe.gyro[0], GyroCalibration::IDENTITY);
        assert!(CalibrationFile::parse(&text.replace("\"scale\":1.0", "\"scale\":0.0")).is_err());
    }
}
