//! Allan analysis of a record's columns, as `host-sim allan` runs it: per
//! column the overlapping Allan deviation with confidence intervals
//! ([`super::allan`]), the fitted noise coefficients ([`super::allan_fit`])
//! and the same in the units engineers quote; serialisable as the
//! command's JSON.

use super::allan::{allan_deviation, averaging_factors, AllanPoint, TauSet};
use super::allan_fit::{bias_instability_factor, fit_noise, NoiseCoefficients};
use super::csv_input::AnalysisInput;
use super::stats::power_of_two_scale;
use super::units::{report_noise, InputUnit, Quantity, Reported};
use anyhow::{bail, Result};
use serde::Serialize;

/// One column's analysis.
#[derive(Serialize)]
pub struct SensorAllan {
    pub name: String,
    pub input_unit: InputUnit,
    /// Unit of `tau` is s; of `oadev`, `adev` and the intervals this one.
    pub oadev_unit: &'static str,
    pub samples: usize,
    /// Allan deviations in SI units (rad/s or m/s^2) or the raw unit.
    pub points: Vec<AllanPoint>,
    /// Noise coefficients in SI units.
    pub fit: NoiseCoefficients,
    /// The same in report units: random walk, bias instability, rate random walk.
    pub report: [Reported; 3],
}

impl SensorAllan {
    /// What the column measures.
    pub fn quantity(&self) -> Quantity {
        self.input_unit.quantity()
    }
}

/// The whole analysis of a record.
#[derive(Serialize)]
pub struct AllanReport {
    pub file: String,
    pub rate_hz: f64,
    pub bias_instability_factor: f64,
    pub sensors: Vec<SensorAllan>,
}

/// The work of [`analyse_columns`] in sample visits, for a progress bar.
pub fn work(input: &AnalysisInput, set: TauSet) -> u64 {
    let n = input.table.rows();
    (input.selected.len() * averaging_factors(n, set).len()) as u64 * n as u64
}

/// Analyses every selected column of `input` (sampled at `rate_hz`) in SI
/// units at the taus of `set`. `on_column` hears each column's name as it
/// starts, `on_work` the work done (see [`work`]). Each column is analysed
/// scaled by a power of two ([`power_of_two_scale`], exact) so that no sum
/// of squares overflows; a column whose deviations are still not finite
/// numbers is an error, never a table of `inf`.
pub fn analyse_columns(
    input: &AnalysisInput,
    rate_hz: f64,
    set: TauSet,
    mut on_column: impl FnMut(&str),
    mut on_work: impl FnMut(u64),
) -> Result<Vec<SensorAllan>> {
    input
        .si_columns()
        .map(|(name, unit, y)| {
            on_column(name);
            let scale = power_of_two_scale(&y);
            let scaled: Vec<f64> = y.iter().map(|v| v * scale).collect();
            let mut points = allan_deviation(&scaled, rate_hz, set, &mut on_work);
            // Deviations and the noise coefficients go with the data's scale.
            let mut fit = fit_noise(&points);
            for p in &mut points {
                p.oadev /= scale;
                p.adev = p.adev.map(|d| d / scale);
                p.ci_low /= scale;
                p.ci_high /= scale;
            }
            for c in [
                &mut fit.quantization,
                &mut fit.random_walk,
                &mut fit.bias_instability,
                &mut fit.rate_random_walk,
            ] {
                *c /= scale;
            }
            let finite = points.iter().all(|p| {
                [p.oadev, p.ci_low, p.ci_high, p.adev.unwrap_or(0.0)]
                    .iter()
                    .all(|v| v.is_finite())
            });
            if !finite {
                bail!("column {name}: the Allan deviations are not finite numbers");
            }
            let quantity = unit.quantity();
            Ok(SensorAllan {
                name: name.to_string(),
                input_unit: unit,
                oadev_unit: match quantity {
                    Quantity::AngularRate => "rad/s",
                    Quantity::SpecificForce => "m/s^2",
                    Quantity::Other => "input unit",
                },
                samples: y.len(),
                report: report_noise(
                    quantity,
                    fit.random_walk,
                    fit.bias_instability,
                    fit.rate_random_walk,
                ),
                points,
                fit,
            })
        })
        .collect()
}

impl AllanReport {
    /// The report of `sensors`, analysed from `file` at `rate_hz`.
    pub fn new(file: String, rate_hz: f64, sensors: Vec<SensorAllan>) -> Self {
        Self {
            file,
            rate_hz,
            bias_instability_factor: bias_instability_factor(),
            sensors,
        }
    }
}
