//! The filter's six AR channels ([`FILTER_AXES`]) and how the models of
//! a file map onto them by sensor name ([`ArModelFile::apply_to`]): each
//! channel once, of the right quantity, AR(4), stationary and fitted at
//! the filter's rate.

use super::file::{ArModelEntry, ArModelFile};
use super::model_check::ArQuantity;
use crate::analysis::arfit::ArMethod;
use anyhow::{bail, Result};
use mwd_core::ar::Ar4;
use mwd_core::error_model::AugmentedModel;

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
    use super::super::file::tests::entry;
    use super::*;

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
}
