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
use anyhow::{bail, Context, Result};
use mwd_core::ar::ArModel;
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
        let text = std::fs::read_to_string(path)
            .with_context(|| format!("cannot read {}", path.display()))?;
        Self::parse(&text).with_context(|| format!("in {}", path.display()))
    }

    /// Parses and checks the JSON text of a model file.
    pub fn parse(text: &str) -> Result<Self> {
        let file: Self = serde_json::from_str(text)?;
        if file.format != FORMAT || file.version != VERSION {
            bail!(
                "not a {FORMAT} v{VERSION} file (format `{}`, version {})",
                file.format,
                file.version
            );
        }
        for m in &file.models {
            let finite = m.coefficients.iter().all(|c| c.is_finite());
            if m.coefficients.len() != m.order || !finite {
                bail!(
                    "sensor {}: {} finite coefficients expected",
                    m.sensor,
                    m.order
                );
            }
            if !(m.noise_variance.is_finite() && m.noise_variance >= 0.0) {
                bail!(
                    "sensor {}: noise variance {} is not a variance",
                    m.sensor,
                    m.noise_variance
                );
            }
            if !(m.sample_rate_hz.is_finite() && m.sample_rate_hz > 0.0) {
                bail!("sensor {}: bad sample rate {}", m.sensor, m.sample_rate_hz);
            }
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

    #[test]
    fn rejects_bad_files() {
        assert!(ArModelFile::parse("{}").is_err());
        let mut f = ArModelFile::new(vec![entry()]);
        f.models[0].noise_variance = -1.0;
        assert!(ArModelFile::parse(&serde_json::to_string(&f).unwrap()).is_err());
        let mut g = ArModelFile::new(vec![entry()]);
        g.models[0].coefficients = vec![1.5, 0.0, 0.0, 0.0];
        let g = ArModelFile::parse(&serde_json::to_string(&g).unwrap()).unwrap();
        assert!(
            g.models[0].to_core::<4>().is_err(),
            "|k| > 1 is not stationary"
        );
    }
}
