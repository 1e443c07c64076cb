//! The AR model file `host-sim arfit` writes and the filter set-up loads:
//! JSON, one entry per sensor, coefficients in the paper's (`aryule`) sign
//! convention and the innovation variance in SI units squared
//! ((m/s^2)^2 for accelerometers, (rad/s)^2 for gyros).
//!
//! ```json
//! {"format": "mwd-ar-models", "version": 1, "models": [
//!   {"sensor": "ax", "quantity": "specific-force", "method": "yule-walker",
//!    "order": 4, "sample_rate_hz": 20.0, "coefficients": [0.33, ...],
//!    "noise_variance": 0.0034, "noise_variance_unit": "(m/s^2)^2",
//!    "std_errors": [...], "reflection": [...]}]}
//! ```

use super::arfit::{ArFit, ArMethod};
use super::units::Quantity;
use crate::formats::text_records::excerpt;
use anyhow::{bail, Context, Result};
use mwd_core::ar::{Ar4, ArModel};
use mwd_core::error_model::AugmentedModel;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Tag of the file format.
pub const FORMAT: &str = "mwd-ar-models";
/// Current version of the file format.
pub const VERSION: u32 = 1;

/// What a modelled channel measures.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ArQuantity {
    /// Accelerometer: variance in (m/s^2)^2.
    SpecificForce,
    /// Gyro (or a derived rate): variance in (rad/s)^2.
    AngularRate,
    /// Unknown unit: variance in the input unit squared.
    Other,
}

impl std::fmt::Display for ArQuantity {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Self::SpecificForce => "a specific force",
            Self::AngularRate => "an angular rate",
            Self::Other => "a quantity of unknown unit",
        })
    }
}

impl From<Quantity> for ArQuantity {
    fn from(quantity: Quantity) -> Self {
        match quantity {
            Quantity::AngularRate => Self::AngularRate,
            Quantity::SpecificForce => Self::SpecificForce,
            Quantity::Other => Self::Other,
        }
    }
}

impl ArQuantity {
    /// The variance unit written beside the number.
    pub fn variance_unit(self) -> &'static str {
        match self {
            Self::SpecificForce => "(m/s^2)^2",
            Self::AngularRate => "(rad/s)^2",
            Self::Other => "(u)^2",
        }
    }
}

/// One sensor's model.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ArModelEntry {
    /// Column / sensor name.
    pub sensor: String,
    /// What it measures.
    pub quantity: ArQuantity,
    /// How it was fitted.
    pub method: ArMethod,
    /// Model order p.
    pub order: usize,
    /// Sample rate of the data the model describes (Hz).
    pub sample_rate_hz: f64,
    /// `a_1 .. a_p`, `z_k = -sum a_i z_{k-i} + e_k`.
    pub coefficients: Vec<f64>,
    /// Innovation variance, SI units squared.
    pub noise_variance: f64,
    /// Unit of `noise_variance`, for people reading the file.
    pub noise_variance_unit: String,
    /// Standard errors of the coefficients (optional on input).
    #[serde(default)]
    pub std_errors: Vec<f64>,
    /// Reflection coefficients (optional on input).
    #[serde(default)]
    pub reflection: Vec<f64>,
}

impl ArModelEntry {
    /// Entry from a fit of SI data.
    pub fn from_fit(sensor: &str, quantity: ArQuantity, rate_hz: f64, fit: &ArFit) -> Self {
        Self {
            sensor: sensor.to_string(),
            quantity,
            method: fit.method,
            order: fit.coefficients.len(),
            sample_rate_hz: rate_hz,
            coefficients: fit.coefficients.clone(),
            noise_variance: fit.noise_variance,
            noise_variance_unit: quantity.variance_unit().to_string(),
            std_errors: fit.std_errors.clone(),
            reflection: fit.reflection.clone(),
        }
    }

    /// The probe's fixed-order model type; fails if the order differs or the
    /// model is not stationary (the filter would diverge).
    pub fn to_core<const P: usize>(&self) -> Result<ArModel<P>> {
        let coefficients: [f64; P] = self.coefficients.as_slice().try_into().map_err(|_| {
            anyhow::anyhow!(
                "sensor {}: order {} where the filter needs {P}",
                self.sensor,
                self.coefficients.len()
            )
        })?;
        let model = ArModel::new(coefficients, self.noise_variance);
        if model.reflection_coefficients().is_none() {
            bail!("sensor {}: the AR model is not stationary", self.sensor);
        }
        Ok(model)
    }
}

/// The physical range of every field (README, "Sensor-noise analysis and
/// calibration"), for the AR models of this file and of the sensor-model
/// file (`sim::model_file`).
pub mod limits {
    use crate::formats::ranges::Range;
    use mwd_core::conventions::DEG;
    use mwd_core::sensor_units::{
        ACCEL_LSB_PER_G, ACCEL_RANGE_G, GYRO_LSB_PER_DEG_S, GYRO_RANGE_DEG_S, STANDARD_GRAVITY,
    };

    /// Model orders a file may hold (the filter takes 4).
    pub const ORDER: std::ops::RangeInclusive<usize> = 1..=64;
    /// Sample rates of the data a model describes.
    pub const SAMPLE_RATE_HZ: Range = Range::new(1e-3, 1e4, "Hz");
    /// Largest modulus of a root of the AR polynomial: strictly inside the
    /// unit circle with a margin, so that the model is stationary and its
    /// correlation time, -1 / (rate ln r), at most ~1000 samples (50 s at
    /// 20 Hz; slower drifts belong to the bias states, not the AR ones).
    pub const MAX_ROOT_MODULUS: f64 = 0.999;

    /// Innovation variance of an accelerometer, (m/s^2)^2: from a
    /// thousandth of an LSB (1/650 g) squared, below which the output
    /// cannot show it, to the full scale (6 g) squared.
    pub fn specific_force_variance() -> Range {
        let lsb = STANDARD_GRAVITY / f64::from(ACCEL_LSB_PER_G);
        let full = f64::from(ACCEL_RANGE_G) * STANDARD_GRAVITY;
        Range::new((1e-3 * lsb).powi(2), full * full, "(m/s^2)^2")
    }

    /// Innovation variance of a gyro, (rad/s)^2: a thousandth of an LSB
    /// (1/18 deg/s) squared to the full scale (300 deg/s) squared.
    pub fn angular_rate_variance() -> Range {
        let lsb = DEG / f64::from(GYRO_LSB_PER_DEG_S);
        let full = f64::from(GYRO_RANGE_DEG_S) * DEG;
        Range::new((1e-3 * lsb).powi(2), full * full, "(rad/s)^2")
    }

    /// Innovation variance of a channel of unknown unit: positive, at most
    /// 1e12 (no SCC1300 output, raw counts included, comes near).
    pub const OTHER_VARIANCE: Range = Range::new(f64::MIN_POSITIVE, 1e12, "(u)^2");
}

/// Checks one AR model: order, finite coefficients, roots at most
/// [`limits::MAX_ROOT_MODULUS`], the innovation variance (SI) in the
/// range of `quantity`.
pub fn check_ar(coefficients: &[f64], noise_variance: f64, quantity: ArQuantity) -> Result<()> {
    if !limits::ORDER.contains(&coefficients.len()) {
        bail!(
            "order {} outside {} to {}",
            coefficients.len(),
            limits::ORDER.start(),
            limits::ORDER.end()
        );
    }
    for (i, &a) in coefficients.iter().enumerate() {
        if !a.is_finite() {
            bail!("`coefficients[{i}]` is {a}, not a finite number");
        }
    }
    let modulus = largest_root_modulus(coefficients);
    if modulus >= 1.0 {
        bail!(
            "the model is not stationary: a root of its AR polynomial has modulus >= 1 \
             (the limit is {})",
            limits::MAX_ROOT_MODULUS
        );
    }
    if modulus > limits::MAX_ROOT_MODULUS {
        bail!(
            "a root of the AR polynomial has modulus {modulus:.6}, beyond {}: too near the \
             unit circle (the model must be stationary with a margin)",
            limits::MAX_ROOT_MODULUS
        );
    }
    let range = match quantity {
        ArQuantity::SpecificForce => limits::specific_force_variance(),
        ArQuantity::AngularRate => limits::angular_rate_variance(),
        ArQuantity::Other => limits::OTHER_VARIANCE,
    };
    range.check("noise_variance", noise_variance)?;
    Ok(())
}

/// The largest modulus of the roots of z^p + a_1 z^(p-1) + ... + a_p, to
/// 1e-6, found by bisection on r: every root is inside the circle of radius
/// r exactly when the model with coefficients a_i / r^i is stationary
/// (all its reflection coefficients below 1 in magnitude, the step-down
/// test). At least 1 when the model is not stationary.
pub fn largest_root_modulus(a: &[f64]) -> f64 {
    let inside = |r: f64| {
        let scaled: Vec<f64> = a
            .iter()
            .enumerate()
            .map(|(i, v)| v / r.powi(i as i32 + 1))
            .collect();
        let k = super::arfit::reflection_from_coefficients(&scaled);
        k.iter().all(|k| k.is_finite() && k.abs() < 1.0)
    };
    if !inside(1.0) {
        return 1.0;
    }
    let (mut low, mut high) = (0.0, 1.0);
    while high - low > 1e-7 {
        let mid = 0.5 * (low + high);
        if mid > 0.0 && inside(mid) {
            high = mid;
        } else {
            low = mid;
        }
    }
    high
}

impl ArModelEntry {
    /// Checks the entry against [`limits`].
    pub fn check(&self) -> Result<()> {
        if self.coefficients.len() != self.order {
            bail!(
                "`order` is {} but there are {} coefficients",
                self.order,
                self.coefficients.len()
            );
        }
        limits::SAMPLE_RATE_HZ.check("sample_rate_hz", self.sample_rate_hz)?;
        check_ar(&self.coefficients, self.noise_variance, self.quantity)?;
        for (i, &e) in self.std_errors.iter().enumerate() {
            if !(e.is_finite() && e >= 0.0) {
                bail!("`std_errors[{i}]` is {e}, not a standard error");
            }
        }
        for (i, &k) in self.reflection.iter().enumerate() {
            if !(k.is_finite() && k.abs() < 1.0) {
                bail!("`reflection[{i}]` is {k}, outside -1 to 1");
            }
        }
        Ok(())
    }
}

/// The whole file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ArModelFile {
    /// Always [`FORMAT`].
    pub format: String,
    /// Format version, [`VERSION`].
    pub version: u32,
    /// One model per sensor.
    pub models: Vec<ArModelEntry>,
}

impl ArModelFile {
    /// A file holding `models`.
    pub fn new(models: Vec<ArModelEntry>) -> Self {
        Self {
            format: FORMAT.to_string(),
            version: VERSION,
            models,
        }
    }

    /// Loads and checks a model file.
    pub fn load(path: &Path) -> Result<Self> {
        let text = crate::formats::text_records::read_small_file(path)
            .with_context(|| format!("cannot read {}", path.display()))?;
        Self::parse(&text).with_context(|| format!("in {}", path.display()))
    }

    /// Parses and checks the JSON text of a model file.
    pub fn parse(text: &str) -> Result<Self> {
        /// The tag alone, so that another JSON file is named as such.
        #[derive(Deserialize)]
        struct Tag {
            format: Option<String>,
            version: Option<u32>,
        }
        let tag: Tag = serde_json::from_str(text)
            .with_context(|| format!("not a {FORMAT} file (not a JSON object)"))?;
        if tag.format.as_deref() != Some(FORMAT) || tag.version != Some(VERSION) {
            bail!(
                "not a {FORMAT} v{VERSION} file (format {}, version {})",
                tag.format.map_or("missing".into(), |f| format!("`{f}`")),
                tag.version.map_or("missing".into(), |v| v.to_string())
            );
        }
        let file: Self = serde_json::from_str(text)
            .with_context(|| format!("malformed {FORMAT} v{VERSION} file"))?;
        for (i, m) in file.models.iter().enumerate() {
            m.check()
                .with_context(|| format!("`models[{i}]` (sensor {})", excerpt(&m.sensor)))?;
        }
        Ok(file)
    }

    /// Writes the file as pretty JSON.
    pub fn save(&self, path: &Path) -> Result<()> {
        let text = serde_json::to_string_pretty(self)?;
        std::fs::write(path, text + "\n")
            .with_context(|| format!("cannot write {}", path.display()))
    }

    /// The model of a named sensor.
    pub fn get(&self, sensor: &str) -> Option<&ArModelEntry> {
        self.models
            .iter()
            .find(|m| m.sensor.eq_ignore_ascii_case(sensor))
    }
}

/// One of the six AR channels of the filter ([`AugmentedModel`]), with the
/// sensor names of a probe file that map onto it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FilterAxis {
    /// Readable name.
    pub label: &'static str,
    /// A file's sensor maps here when its name is this stem, or the stem
    /// followed by `_` and a unit (`accel_x_m_s2`, `gyro_z_rad_s`, ...).
    /// The paper's own labels (Table 5's "Y" is the body-x gyro) and short
    /// names such as `gy` are not accepted: they are ambiguous.
    pub stem: &'static str,
    /// What the sensor must measure.
    pub quantity: ArQuantity,
}

/// The filter's AR channels in [`AugmentedModel`] order: `accel[0..3]` then
/// `gyro[0..3]` (body x, y, z; gyro y is the tool-axis rate derived from
/// accelerometer roll, the probe has no tool-axis gyro).
pub const FILTER_AXES: [FilterAxis; 6] = [
    FilterAxis {
        label: "accel x",
        stem: "accel_x",
        quantity: ArQuantity::SpecificForce,
    },
    FilterAxis {
        label: "accel y",
        stem: "accel_y",
        quantity: ArQuantity::SpecificForce,
    },
    FilterAxis {
        label: "accel z",
        stem: "accel_z",
        quantity: ArQuantity::SpecificForce,
    },
    FilterAxis {
        label: "gyro x",
        stem: "gyro_x",
        quantity: ArQuantity::AngularRate,
    },
    FilterAxis {
        label: "gyro y (accelerometer-derived rate)",
        stem: "gyro_y",
        quantity: ArQuantity::AngularRate,
    },
    FilterAxis {
        label: "gyro z",
        stem: "gyro_z",
        quantity: ArQuantity::AngularRate,
    },
];

/// Index of the accelerometer-derived tool-axis rate in [`FILTER_AXES`].
pub const DERIVED_RATE: usize = 4;

/// Where one filter channel's model came from.
#[derive(Clone, Debug, PartialEq)]
pub struct AxisSource {
    /// The filter channel.
    pub axis: FilterAxis,
    /// The file's sensor name, or `None` when the caller's model was kept.
    pub sensor: Option<String>,
    /// The fitting method named in the file.
    pub method: Option<ArMethod>,
    /// The model the filter now has.
    pub model: Ar4,
}

impl FilterAxis {
    /// Whether a file's sensor name maps onto this channel.
    pub fn matches(&self, sensor: &str) -> bool {
        let name = sensor.to_ascii_lowercase();
        name == self.stem
            || name
                .strip_prefix(self.stem)
                .is_some_and(|rest| rest.starts_with('_'))
    }
}

impl ArModelFile {
    /// Replaces the accelerometer and rate AR models of `model` with this
    /// file's, sensor by sensor (see [`FILTER_AXES`]). Every channel must be
    /// in the file exactly once, measure the right quantity, be AR(4),
    /// stationary and fitted at the filter's rate 1 / `model.dt`; the one
    /// exception, with `keep_derived_rate`, is the accelerometer-derived
    /// tool-axis rate (gyro y), which then keeps `model`'s own (the probe has
    /// no tool-axis gyro, so a fit of its captures has no such sensor).
    /// Returns the sources in [`FILTER_AXES`] order and the names of the
    /// file's sensors that map onto no channel.
    pub fn apply_to(
        &self,
        model: &mut AugmentedModel,
        keep_derived_rate: bool,
    ) -> Result<([AxisSource; 6], Vec<String>)> {
        let rate = 1.0 / model.dt;
        let names: Vec<&str> = self.models.iter().map(|m| m.sensor.as_str()).collect();
        let mut sources = Vec::with_capacity(FILTER_AXES.len());
        for (i, axis) in FILTER_AXES.iter().enumerate() {
            let current = if i < 3 {
                model.accel[i]
            } else {
                model.gyro[i - 3]
            };
            let found: Vec<&ArModelEntry> = self
                .models
                .iter()
                .filter(|m| axis.matches(&m.sensor))
                .collect();
            let entry = match found.as_slice() {
                [one] => *one,
                [] if i == DERIVED_RATE && keep_derived_rate => {
                    sources.push(AxisSource {
                        axis: *axis,
                        sensor: None,
                        method: None,
                        model: current,
                    });
                    continue;
                }
                [] if i == DERIVED_RATE => bail!(
                    "no model for {} (sensor `{}` or `{}_<unit>`); the probe has no tool-axis gyro, \
                     so a fit of its files lacks it: fit that rate too, or pass \
                     --paper-derived-rate to keep the paper's Table 5 model for it \
                     (the file has: {})",
                    axis.label,
                    axis.stem,
                    axis.stem,
                    names.join(", ")
                ),
                [] => bail!(
                    "no model for {} (sensor `{}` or `{}_<unit>`, e.g. a `host-sim simulate` \
                     column); the file has: {}",
                    axis.label,
                    axis.stem,
                    axis.stem,
                    names.join(", ")
                ),
                many => bail!(
                    "{} models map onto {}: {}",
                    many.len(),
                    axis.label,
                    many.iter()
                        .map(|m| m.sensor.as_str())
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            };
            if entry.quantity != axis.quantity {
                bail!(
                    "sensor {}: the file has {} where {} needs {} (fit it with SI \
                     units, e.g. `--units auto` on `_m_s2` / `_rad_s` columns)",
                    entry.sensor,
                    entry.quantity,
                    axis.label,
                    axis.quantity
                );
            }
            if (entry.sample_rate_hz - rate).abs() > 1e-9 * rate {
                bail!(
                    "sensor {}: fitted at {} Hz, the filter runs at {rate} Hz (an AR model \
                     describes one sample interval)",
                    entry.sensor,
                    entry.sample_rate_hz
                );
            }
            let ar = entry.to_core::<4>()?;
            sources.push(AxisSource {
                axis: *axis,
                sensor: Some(entry.sensor.clone()),
                method: Some(entry.method),
                model: ar,
            });
        }
        let sources: [AxisSource; 6] = sources
            .try_into()
            .map_err(|_| anyhow::anyhow!("internal: six filter channels expected"))?;
        for (i, s) in sources.iter().enumerate() {
            if i < 3 {
                model.accel[i] = s.model;
            } else {
                model.gyro[i - 3] = s.model;
            }
        }
        let unused = names
            .iter()
            .filter(|n| !FILTER_AXES.iter().any(|a| a.matches(n)))
            .map(|n| n.to_string())
            .collect();
        Ok((sources, unused))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn entry() -> ArModelEntry {
        let a = mwd_core::ar::ACCEL_X;
        ArModelEntry {
            sensor: "ax".into(),
            quantity: ArQuantity::SpecificForce,
            method: ArMethod::YuleWalker,
            order: 4,
            sample_rate_hz: 20.0,
            coefficients: a.coefficients.to_vec(),
            noise_variance: a.noise_variance,
            noise_variance_unit: ArQuantity::SpecificForce.variance_unit().into(),
            std_errors: vec![],
            reflection: vec![],
        }
    }

    #[test]
    fn round_trip_into_the_core_type() {
        let file = ArModelFile::new(vec![entry()]);
        let text = serde_json::to_string(&file).unwrap();
        let back = ArModelFile::parse(&text).unwrap();
        assert_eq!(back, file);
        let core = back.get("AX").unwrap().to_core::<4>().unwrap();
        assert_eq!(core, mwd_core::ar::ACCEL_X);
        assert!(back.models[0].to_core::<3>().is_err());
    }

    /// A file like `arfit` writes for a `host-sim simulate` CSV: the five
    /// measured channels, in the CSV's column order (not the filter's).
    fn probe_file() -> ArModelFile {
        let names = [
            ("gyro_x_rad_s", ArQuantity::AngularRate),
            ("gyro_z_rad_s", ArQuantity::AngularRate),
            ("accel_x_m_s2", ArQuantity::SpecificForce),
            ("accel_y_m_s2", ArQuantity::SpecificForce),
            ("accel_z_m_s2", ArQuantity::SpecificForce),
            ("temperature_c", ArQuantity::Other),
        ];
        let models = names
            .iter()
            .enumerate()
            .map(|(i, (name, quantity))| ArModelEntry {
                sensor: name.to_string(),
                quantity: *quantity,
                coefficients: vec![0.1 * i as f64, 0.0, 0.0, 0.01],
                noise_variance: (i + 1) as f64,
                ..entry()
            })
            .collect();
        ArModelFile::new(models)
    }

    #[test]
    fn maps_sensors_onto_the_filter_axes_by_name() {
        let mut model = AugmentedModel::paper();
        let (sources, unused) = probe_file().apply_to(&mut model, true).unwrap();
        assert_eq!(model.gyro[0].noise_variance, 1.0);
        assert_eq!(model.gyro[2].noise_variance, 2.0);
        assert_eq!(model.accel[0].noise_variance, 3.0);
        assert_eq!(model.accel[2].noise_variance, 5.0);
        assert_eq!(model.accel[1].coefficients, [0.1 * 3.0, 0.0, 0.0, 0.01]);
        assert_eq!(model.gyro[1], mwd_core::ar::GYRO_Y, "kept");
        assert_eq!(sources[DERIVED_RATE].sensor, None);
        assert_eq!(sources[0].sensor.as_deref(), Some("accel_x_m_s2"));
        assert_eq!(unused, ["temperature_c"]);
        // A fitted derived rate is taken when present.
        let mut f = probe_file();
        f.models.push(ArModelEntry {
            sensor: "GYRO_Y_deg_s".into(),
            quantity: ArQuantity::AngularRate,
            ..entry()
        });
        let mut model = AugmentedModel::paper();
        f.apply_to(&mut model, false).unwrap();
        assert_eq!(model.gyro[1], mwd_core::ar::ACCEL_X);
    }

    #[test]
    fn refuses_files_the_filter_cannot_use() {
        let err = |f: &ArModelFile, keep: bool| {
            let mut model = AugmentedModel::paper();
            let e = f.apply_to(&mut model, keep).unwrap_err().to_string();
            assert_eq!(model, AugmentedModel::paper(), "untouched on error");
            e
        };
        assert!(err(&probe_file(), false).contains("--paper-derived-rate"));
        let mut f = probe_file();
        f.models.retain(|m| m.sensor != "accel_y_m_s2");
        assert!(err(&f, true).contains("no model for accel y"));
        let mut f = probe_file();
        f.models[2].sensor = "accel_xy".into();
        assert!(err(&f, true).contains("no model for accel x"));
        let mut f = probe_file();
        f.models.push(ArModelEntry {
            sensor: "accel_x".into(),
            ..entry()
        });
        assert!(err(&f, true).contains("2 models map onto accel x"));
        let mut f = probe_file();
        f.models[0].sample_rate_hz = 100.0;
        assert!(err(&f, true).contains("100 Hz"));
        let mut f = probe_file();
        f.models[3].coefficients = vec![0.1, 0.2, 0.3];
        f.models[3].order = 3;
        assert!(err(&f, true).contains("order 3"));
        let mut f = probe_file();
        f.models[4].coefficients = vec![0.0, 0.0, 0.0, -1.2];
        assert!(err(&f, true).contains("not stationary"));
        let mut f = probe_file();
        f.models[1].quantity = ArQuantity::Other;
        assert!(err(&f, true).contains("needs an angular rate"));
    }

    /// The audit's bad files.
    #[test]
    fn models_outside_the_physical_ranges_are_refused() {
        let refused = |edit: &dyn Fn(&mut ArModelEntry), needle: &str| {
            let mut e = entry();
            edit(&mut e);
            let text = serde_json::to_string(&ArModelFile::new(vec![e])).unwrap();
            let err = format!("{:#}", ArModelFile::parse(&text).unwrap_err());
            assert!(err.contains(needle), "{needle:?} not in {err}");
            assert!(err.contains("models[0]"), "{err}");
        };
        refused(
            &|e| e.noise_variance = 1e300,
            "`noise_variance` is 1e300 (m/s^2)^2, outside",
        );
        refused(
            &|e| e.noise_variance = 0.0,
            "`noise_variance` is 0 (m/s^2)^2, outside",
        );
        refused(
            &|e| {
                e.coefficients = vec![-0.9999999];
                e.order = 1;
            },
            "modulus 1.000000, beyond 0.999",
        );
        refused(&|e| e.coefficients[3] = -1.5, "not stationary");
        refused(&|e| e.sample_rate_hz = 0.0, "`sample_rate_hz` is 0 Hz");
        refused(
            &|e| e.order = 3,
            "`order` is 3 but there are 4 coefficients",
        );
        refused(&|e| e.reflection = vec![1.5], "`reflection[0]` is 1.5");
        // Every model the paper gives is inside the ranges.
        for m in mwd_core::ar::ACCEL_DEFAULTS.iter() {
            check_ar(&m.coefficients, m.noise_variance, ArQuantity::SpecificForce).unwrap();
        }
        for m in mwd_core::ar::GYRO_DEFAULTS.iter() {
            check_ar(&m.coefficients, m.noise_variance, ArQuantity::AngularRate).unwrap();
        }
    }

    #[test]
    fn the_largest_root_modulus() {
        // z^2 - 0.25 = (z - 0.5)(z + 0.5); z + 0.9; complex pair of modulus 0.8.
        assert!((largest_root_modulus(&[0.0, -0.25]) - 0.5).abs() < 1e-6);
        assert!((largest_root_modulus(&[0.9]) - 0.9).abs() < 1e-6);
        assert!((largest_root_modulus(&[0.0, 0.64]) - 0.8).abs() < 1e-6);
        assert_eq!(largest_root_modulus(&[-1.0]), 1.0);
    }

    #[test]
    fn rejects_bad_files() {
        assert!(ArModelFile::parse("{}").is_err());
        let mut f = ArModelFile::new(vec![entry()]);
        f.models[0].noise_variance = -1.0;
        assert!(ArModelFile::parse(&serde_json::to_string(&f).unwrap()).is_err());
        let mut g = ArModelFile::new(vec![entry()]);
        g.models[0].coefficients = vec![1.5, 0.0, 0.0, 0.0];
        assert!(
            ArModelFile::parse(&serde_json::to_string(&g).unwrap()).is_err(),
            "|k| > 1 is not stationary"
        );
        assert!(g.models[0].to_core::<4>().is_err());
    }
}
