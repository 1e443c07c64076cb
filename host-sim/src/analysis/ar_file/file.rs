//! The file itself: its entries ([`ArModelEntry`], one sensor's model,
//! with its check and its conversion to the probe's fixed-order type) and
//! the whole file ([`ArModelFile`]: read, checked, written, looked up by
//! sensor). How a file's models map onto the filter's channels is in
//! `filter_axes`.

use super::limits;
use super::model_check::{check_ar, ArQuantity};
use crate::analysis::arfit::{ArFit, ArMethod};
use crate::formats::text_records::excerpt;
use anyhow::{bail, Context, Result};
use mwd_core::ar::ArModel;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Tag of the file format.
pub const FORMAT: &str = "mwd-ar-models";
/// Current version of the file format.
pub const VERSION: u32 = 1;

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
        crate::formats::files::write_text(path, &(text + "\n"))
    }

    /// The model of a named sensor.
    pub fn get(&self, sensor: &str) -> Option<&ArModelEntry> {
        self.models
            .iter()
            .find(|m| m.sensor.eq_ignore_ascii_case(sensor))
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;

    /// An accelerometer entry holding the paper's AR(4) model.
    pub(crate) fn entry() -> ArModelEntry {
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
