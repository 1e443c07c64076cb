//! The calibration file `host-sim calibrate` writes: JSON holding, per
//! accelerometer triad, the probe's correction (bias and M = K^-1, SI
//! units) and, per gyro, its bias (rad/s). It loads into the correction
//! types of `mwd_core::calibration`, which the simulator and probe apply.

use crate::formats::text_records::excerpt;
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

/// The physical range of every field (README, "Sensor-noise analysis and
/// calibration"). A value outside is a unit mistake, a failed fit or a
/// failed part, never a calibration to load into a probe.
pub mod limits {
    use crate::formats::ranges::Range;
    // The probe's own bounds for an uplinked calibration: a file the host
    // accepts, the probe accepts (one place for the numbers).
    use mwd_core::protocol::uplink::fields as probe;

    /// Gyro scale factor applied: a +-50 % error is far beyond the part's
    /// (a few %); a negative or zero scale is not a gyro.
    pub const GYRO_SCALE: Range = Range::new(probe::GYRO_SCALE.0, probe::GYRO_SCALE.1, "");
    /// Gyro bias: 10 deg/s, far beyond the SCC1300's offset (its whole range
    /// is 300 deg/s); more is a unit mistake (deg/s written as rad/s).
    pub const GYRO_BIAS_RAD_S: Range = Range::within(probe::MAX_GYRO_BIAS_RAD_S, "rad/s");
    /// Accelerometer zero offset: 1 g, far beyond the part's (tens of mg).
    pub const ACCEL_BIAS_M_S2: Range = Range::within(probe::MAX_ACCEL_BIAS_M_S2, "m/s^2");
    /// Diagonal of M = K^-1: the inverse of a scale factor, as the gyro's.
    pub const CORRECTION_DIAGONAL: Range = Range::new(
        probe::ACCEL_CORRECTION_DIAGONAL.0,
        probe::ACCEL_CORRECTION_DIAGONAL.1,
        "",
    );
    /// Off-diagonal of M: cross-coupling up to 0.2 (11 deg of misalignment).
    pub const CORRECTION_OFF_DIAGONAL: Range =
        Range::within(probe::MAX_ACCEL_CORRECTION_OFF_DIAGONAL, "");
    /// Condition number of M (largest over smallest singular value): a
    /// nearly singular correction amplifies noise without bound.
    pub const CORRECTION_CONDITION: Range = Range::new(1.0, 10.0, "");
    /// Latitude of the calibration site.
    pub const LATITUDE_DEG: Range = Range::within(90.0, "deg");
    /// Gravity used as the reference: normal gravity is 9.780 (equator) to
    /// 9.832 (poles) m/s^2, a little less on a mountain.
    pub const GRAVITY_M_S2: Range = Range::new(9.7, 9.9, "m/s^2");
    /// Accelerometer triads: the probe has two parts; one triad (fitted on
    /// the body-frame force the parts share) corrects both.
    pub const TRIADS: std::ops::RangeInclusive<usize> = 1..=2;
    /// Gyro axes a file may name (each at most once).
    pub const GYRO_AXES: [&str; 3] = ["x", "y", "z"];
    /// Fitting methods.
    pub const METHODS: [&str; 2] = ["ls", "tls"];
}

impl CalibrationFile {
    /// Parses and checks a calibration file's text.
    pub fn parse(text: &str) -> Result<Self> {
        let file: Self = serde_json::from_str(text).map_err(|e| {
            anyhow::anyhow!(
                "not a {FORMAT} v{VERSION} JSON file: {}",
                excerpt(&e.to_string())
            )
        })?;
        if file.format != FORMAT || file.version != VERSION {
            bail!(
                "not a {FORMAT} v{VERSION} file (format `{}`, version {})",
                excerpt(&file.format),
                file.version
            );
        }
        file.check()?;
        Ok(file)
    }

    /// Checks every field against its range ([`limits`]).
    pub fn check(&self) -> Result<()> {
        use limits::*;
        if !METHODS.contains(&self.method.as_str()) {
            bail!(
                "`method` is `{}`, not one of {}",
                excerpt(&self.method),
                METHODS.join(", ")
            );
        }
        LATITUDE_DEG.check("latitude_deg", self.latitude_deg)?;
        GRAVITY_M_S2.check("gravity", self.gravity)?;
        if !TRIADS.contains(&self.accel.len()) {
            bail!(
                "{} accelerometer triads where the probe takes {} to {} (`accel`)",
                self.accel.len(),
                TRIADS.start(),
                TRIADS.end()
            );
        }
        for (i, t) in self.accel.iter().enumerate() {
            for (j, &b) in t.bias.iter().enumerate() {
                ACCEL_BIAS_M_S2.check(&format!("accel[{i}].bias[{j}]"), b)?;
            }
            for (r, row) in t.correction.iter().enumerate() {
                for (c, &m) in row.iter().enumerate() {
                    let range = if r == c {
                        CORRECTION_DIAGONAL
                    } else {
                        CORRECTION_OFF_DIAGONAL
                    };
                    range.check(&format!("accel[{i}].correction[{r}][{c}]"), m)?;
                }
            }
            let m = nalgebra::Matrix3::from_fn(|r, c| t.correction[r][c]);
            let sv = m.singular_values();
            let condition = sv.max() / sv.min();
            let condition = if condition.is_finite() {
                condition
            } else {
                f64::INFINITY
            };
            CORRECTION_CONDITION.check(
                &format!("the condition number of accel[{i}].correction"),
                condition,
            )?;
        }
        for (i, g) in self.gyro.iter().enumerate() {
            if !GYRO_AXES.contains(&g.axis.as_str()) {
                bail!(
                    "`gyro[{i}].axis` is `{}`, not one of x, y, z",
                    excerpt(&g.axis)
                );
            }
            if self.gyro[..i].iter().any(|h| h.axis == g.axis) {
                bail!("two gyros on axis {} (`gyro[{i}]`)", g.axis);
            }
            GYRO_BIAS_RAD_S.check(&format!("gyro[{i}].bias"), g.bias)?;
            GYRO_SCALE.check(&format!("gyro[{i}].scale"), g.scale)?;
        }
        Ok(())
    }

    /// Loads a calibration file.
    pub fn load(path: &Path) -> Result<Self> {
        let text = crate::formats::text_records::read_small_file(path)
            .with_context(|| format!("cannot read {}", path.display()))?;
        Self::parse(&text).with_context(|| format!("in {}", path.display()))
    }

    /// Writes the file as pretty JSON.
    /// Refuses, naming the field, a calibration outside the ranges a
    /// load accepts ([`limits`]).
    pub fn save(&self, path: &Path) -> Result<()> {
        self.check()
            .with_context(|| format!("not writing {}", path.display()))?;
        let text = serde_json::to_string_pretty(self)? + "\n";
        crate::formats::files::write_text(path, &text)
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

    fn good() -> CalibrationFile {
        CalibrationFile {
            format: FORMAT.into(),
            version: VERSION,
            method: "ls".into(),
            latitude_deg: 45.0,
            gravity: 9.806,
            accel: vec![TriadEntry {
                columns: ["ax".into(), "ay".into(), "az".into()],
                bias: [0.01, -0.02, 0.003],
                correction: [[1.01, 0.001, 0.0], [0.0, 0.99, 0.002], [0.0, 0.0, 1.0]],
            }],
            gyro: vec![GyroEntry {
                column: "gz".into(),
                axis: "z".into(),
                bias: 1e-5,
                scale: 1.0,
            }],
        }
    }

    /// The audit's bad files: each refused with the
    /// field and its range named.
    #[test]
    fn files_outside_the_physical_ranges_are_refused() {
        let refused = |edit: &dyn Fn(&mut CalibrationFile), needle: &str| {
            let mut f = good();
            edit(&mut f);
            let text = serde_json::to_string(&f).unwrap();
            let e = CalibrationFile::parse(&text).unwrap_err().to_string();
            assert!(e.contains(needle), "{needle:?} not in {e}");
        };
        assert!(CalibrationFile::parse(&serde_json::to_string(&good()).unwrap()).is_ok());
        refused(
            &|f| f.gyro[0].scale = -1.0,
            "`gyro[0].scale` is -1, outside its range 0.5 to 2",
        );
        refused(&|f| f.gyro[0].scale = 1e-300, "`gyro[0].scale` is 1e-300");
        refused(&|f| f.gyro[0].bias = 1e308, "`gyro[0].bias` is 1e308 rad/s");
        refused(&|f| f.gyro[0].axis = "q".into(), "`gyro[0].axis` is `q`");
        refused(&|f| f.gyro.push(f.gyro[0].clone()), "two gyros on axis z");
        refused(
            &|f| f.accel[0].bias[1] = 1e308,
            "`accel[0].bias[1]` is 1e308 m/s^2",
        );
        refused(
            &|f| f.accel[0].correction = [[1e300; 3]; 3],
            "`accel[0].correction[0][0]` is 1e300",
        );
        refused(
            &|f| f.accel[0].correction = [[1.0, 0.2, 0.2], [0.2, 1.0, 0.2], [1.0, 1.0, 1.0]],
            "`accel[0].correction[2][0]`",
        );
        // A singular matrix: the entry ranges make M strictly diagonally
        // dominant, hence invertible; the condition number bounds the rest.
        refused(
            &|f| f.accel[0].correction = [[1.0, 1.0, 0.0], [1.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            "`accel[0].correction[0][1]` is 1, outside its range -0.2 to 0.2",
        );
        refused(&|f| f.accel.clear(), "0 accelerometer triads");
        refused(
            &|f| f.accel = vec![f.accel[0].clone(); 3],
            "3 accelerometer triads where the probe takes 1 to 2",
        );
        refused(&|f| f.latitude_deg = 95.0, "`latitude_deg` is 95");
        refused(&|f| f.gravity = 1e300, "`gravity` is 1e300");
        refused(&|f| f.method = "magic".into(), "`method` is `magic`");
        let dir = std::env::temp_dir().join(format!("calfile-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let mut f = good();
        f.gyro[0].scale = -1.0;
        assert!(f.save(&dir.join("bad.cal.json")).is_err());
        assert!(!dir.join("bad.cal.json").exists(), "nothing written");
    }
}
