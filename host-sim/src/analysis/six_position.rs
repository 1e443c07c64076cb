//! A six-position calibration of a table of samples, as `host-sim
//! calibrate` runs it: which columns hold accelerometer triads and gyros,
//! their position means, the LS and TLS fits of every triad
//! ([`super::calibration`]), the gyro biases, and the calibration file
//! they make.

use super::calibration::{
    calibrate_gyro, calibrate_triad, earth_rate_up, position_means, GyroResult, PositionMean,
    TriadResult,
};
use super::calibration_file::{CalibrationFile, GyroEntry, TriadEntry, FORMAT, VERSION};
use super::csv_input::Columns;
use super::tls::FitMethod;
use anyhow::{bail, Context, Result};

/// Body axis names, by index.
const AXES: [&str; 3] = ["x", "y", "z"];

/// An accelerometer triad: the names of its x, y and z columns.
#[derive(Clone, Debug, PartialEq)]
pub struct TriadColumns(pub [String; 3]);

impl TriadColumns {
    /// `x,y,z` column names.
    pub fn parse(spec: &str) -> Result<Self> {
        let cols: Vec<&str> = spec.split(',').map(str::trim).collect();
        let [x, y, z] = cols.as_slice() else {
            bail!("--accel wants three column names x,y,z, got `{spec}`")
        };
        Ok(Self([x.to_string(), y.to_string(), z.to_string()]))
    }

    /// The names joined as they were given, `x,y,z`.
    pub fn joined(&self) -> String {
        self.0.join(",")
    }
}

/// A gyro: its column and the body axis it senses.
#[derive(Clone, Debug, PartialEq)]
pub struct GyroColumn {
    pub column: String,
    /// Body axis index (0 = x).
    pub axis: usize,
}

impl GyroColumn {
    /// `column:axis`, the axis one of x, y, z.
    pub fn parse(spec: &str) -> Result<Self> {
        let Some((name, axis)) = spec.split_once(':') else {
            bail!("--gyro wants column:axis, got `{spec}`")
        };
        let axis = match AXES.iter().position(|a| *a == axis.trim()) {
            Some(i) => i,
            None => bail!("--gyro {spec}: axis `{}` is not x, y or z", axis.trim()),
        };
        Ok(Self {
            column: name.trim().to_string(),
            axis,
        })
    }

    /// The axis' name, x, y or z.
    pub fn axis_name(&self) -> &'static str {
        AXES[self.axis]
    }
}

/// The position means of a table's sensor columns, in SI units.
pub struct PositionData {
    /// Per position, the means of the triads' columns, then the gyros'.
    pub means: Vec<PositionMean>,
    triads: Vec<(TriadColumns, [usize; 3])>,
    gyros: Vec<(GyroColumn, usize)>,
}

/// Averages the named columns of `table` (scaled to SI by `accel_si` and
/// `gyro_si`) over each position of its `position` column.
pub fn position_data(
    table: &Columns,
    triads: &[TriadColumns],
    gyros: &[GyroColumn],
    accel_si: f64,
    gyro_si: f64,
) -> Result<PositionData> {
    let positions = table.column("position")?;
    let mut data: Vec<Vec<f64>> = Vec::new();
    let mut col_of = |name: &str, scale: f64| -> Result<usize> {
        data.push(table.column(name)?.iter().map(|v| v * scale).collect());
        Ok(data.len() - 1)
    };
    let mut triad_cols = Vec::new();
    for triad in triads {
        let [x, y, z] = &triad.0;
        let cols = [
            col_of(x, accel_si)?,
            col_of(y, accel_si)?,
            col_of(z, accel_si)?,
        ];
        triad_cols.push((triad.clone(), cols));
    }
    let mut gyro_cols = Vec::new();
    for gyro in gyros {
        gyro_cols.push((gyro.clone(), col_of(&gyro.column, gyro_si)?));
    }
    let refs: Vec<&[f64]> = data.iter().map(Vec::as_slice).collect();
    Ok(PositionData {
        means: position_means(positions, &refs)?,
        triads: triad_cols,
        gyros: gyro_cols,
    })
}

/// One triad fitted both ways.
pub struct TriadFit {
    pub columns: TriadColumns,
    pub ls: TriadResult,
    pub tls: TriadResult,
}

impl TriadFit {
    /// The fit of `method`.
    pub fn by(&self, method: FitMethod) -> &TriadResult {
        match method {
            FitMethod::Ls => &self.ls,
            FitMethod::Tls => &self.tls,
        }
    }
}

/// Every triad and gyro of a six-position run, calibrated.
pub struct SixPositionFit {
    /// Gravity magnitude of the references (m/s^2).
    pub gravity: f64,
    /// Earth rate's up component at the site (rad/s).
    pub earth_rate_up: f64,
    pub triads: Vec<TriadFit>,
    pub gyros: Vec<(GyroColumn, GyroResult)>,
}

/// Fits every triad by LS and TLS against +-`gravity`, and every gyro's
/// bias with the earth rate at `latitude` (rad) cancelled.
pub fn fit(data: &PositionData, gravity: f64, latitude: f64) -> Result<SixPositionFit> {
    let earth_rate_up = earth_rate_up(latitude);
    let mut triads = Vec::new();
    for (columns, cols) in &data.triads {
        triads.push(TriadFit {
            columns: columns.clone(),
            ls: calibrate_triad(&data.means, *cols, gravity, FitMethod::Ls)?,
            tls: calibrate_triad(&data.means, *cols, gravity, FitMethod::Tls)?,
        });
    }
    let mut gyros = Vec::new();
    for (gyro, col) in &data.gyros {
        let result = calibrate_gyro(&data.means, *col, gyro.axis, earth_rate_up)?;
        gyros.push((gyro.clone(), result));
    }
    Ok(SixPositionFit {
        gravity,
        earth_rate_up,
        triads,
        gyros,
    })
}

impl SixPositionFit {
    /// The calibration file of the triads' `method` fits and the gyro
    /// biases, for a test at `latitude_deg`.
    pub fn calibration_file(
        &self,
        method: FitMethod,
        latitude_deg: f64,
    ) -> Result<CalibrationFile> {
        let mut accel = Vec::new();
        for triad in &self.triads {
            let cal = triad
                .by(method)
                .coupling
                .to_triad_calibration()
                .with_context(|| format!("triad {}", triad.columns.joined()))?;
            accel.push(TriadEntry {
                columns: triad.columns.0.clone(),
                bias: cal.bias,
                correction: cal.correction,
            });
        }
        let gyro = self
            .gyros
            .iter()
            .map(|(g, result)| GyroEntry {
                column: g.column.clone(),
                axis: g.axis_name().to_string(),
                bias: result.to_core().bias,
                scale: 1.0,
            })
            .collect();
        Ok(CalibrationFile {
            format: FORMAT.into(),
            version: VERSION,
            method: method.to_string(),
            latitude_deg,
            gravity: self.gravity,
            accel,
            gyro,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn column_specs_parse_or_say_what_they_want() {
        let triad = TriadColumns::parse(" ax, ay ,az").unwrap();
        assert_eq!(triad.joined(), "ax,ay,az");
        let err = TriadColumns::parse("ax,ay").unwrap_err().to_string();
        assert!(err.contains("three column names"), "{err}");
        let gyro = GyroColumn::parse("gz : z").unwrap();
        assert_eq!((gyro.column.as_str(), gyro.axis_name()), ("gz", "z"));
        assert!(GyroColumn::parse("gz").is_err());
        let err = GyroColumn::parse("gz:w").unwrap_err().to_string();
        assert!(err.contains("axis `w` is not x, y or z"), "{err}");
    }
}
