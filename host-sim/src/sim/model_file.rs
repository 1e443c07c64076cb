//! The sensor model as a JSON file in datasheet units, so an engineer can
//! read, edit and keep the figures a simulation or an alignment used:
//! `host-sim simulate --print-sensor-model` writes the defaults, and
//! `--sensor-model FILE` (simulate, align) reads them back.
use super::sensor::{DeterministicErrors, SensorModel};
use crate::analysis::ar_file::{check_ar, ArQuantity};
use crate::analysis::calibration_file::limits as cal;
use anyhow::{Context, Result};
use mwd_core::ar::Ar4;
use mwd_core::conventions::DEG;
use mwd_core::sensor_noise::{
    arw_from_deg_per_sqrt_hour, rate_from_deg_per_hour, AxisNoise, ImuNoise,
};
use mwd_core::sensor_units::STANDARD_GRAVITY;
use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

/// An AR(4) model in the paper's sign convention (`z_k = -sum a_i z_{k-i} + e_k`).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Ar4File {
    pub a: [f64; 4],
    /// Variance of e_k: (deg/s)^2 for rates, (m/s^2)^2 for accelerometers.
    pub noise_variance: f64,
}

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct GyroFile {
    /// Angle random walk of the x and z gyros (deg/sqrt(h)).
    pub arw_deg_per_sqrt_h: f64,
    /// Gauss-Markov bias instability (deg/h) and its correlation time (s).
    pub bias_instability_deg_per_h: f64,
    pub correlation_time_s: f64,
    /// Bias left after calibration, 1 sigma (deg/h).
    pub residual_bias_deg_per_h: f64,
    /// Deterministic bias of the x and z gyros (deg/s), removed by calibration.
    pub bias_deg_per_s: [f64; 2],
    /// Scale-factor error of the x and z gyros (ppm).
    pub scale_factor_ppm: [f64; 2],
    /// Coloured noise of the x gyro, the derived tool-axis rate, the z gyro.
    pub ar4: [Option<Ar4File>; 3],
}

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct AccelFile {
    /// Velocity random walk (m/s/sqrt(h)).
    pub vrw_m_per_s_per_sqrt_h: f64,
    pub bias_instability_m_per_s2: f64,
    pub correlation_time_s: f64,
    /// Bias left after calibration, 1 sigma (mg).
    pub residual_bias_mg: f64,
    /// Deterministic bias (m/s^2), removed by calibration.
    pub bias_m_per_s2: [f64; 3],
    /// Scale factor and misalignment K, raw = K true + bias (row-major).
    pub scale_misalignment: [[f64; 3]; 3],
    pub ar4: [Option<Ar4File>; 3],
}

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct SensorModelFile {
    pub gyro: GyroFile,
    pub accel: AccelFile,
    /// Round outputs to the SCC1300's LSB.
    pub quantize: bool,
}

fn ar_to_file(ar: Option<Ar4>, unit: f64) -> Option<Ar4File> {
    ar.map(|m| Ar4File {
        a: m.coefficients,
        noise_variance: m.noise_variance / (unit * unit),
    })
}

/// An AR(4) model of the file in SI units, checked as the AR-model files
/// are ([`check_ar`]); `unit` converts the file's variance unit to SI.
fn ar_from_file(ar: &Option<Ar4File>, unit: f64, quantity: ArQuantity) -> Result<Option<Ar4>> {
    let Some(f) = ar else { return Ok(None) };
    let model = Ar4::new(f.a, f.noise_variance * unit * unit);
    check_ar(&model.coefficients, model.noise_variance, quantity)?;
    Ok(Some(model))
}

/// The physical range of every figure of the file (README, "The host
/// tool"): the SCC1300's datasheet figures (0.86 deg/sqrt(h), 2.1 deg/h,
/// 100 s) lie well inside; a value outside is a unit mistake.
pub mod limits {
    use crate::formats::ranges::Range;

    /// Gyro angle random walk.
    pub const ARW_DEG_PER_SQRT_H: Range = Range::new(0.0, 10.0, "deg/sqrt(h)");
    /// Gyro bias instability and residual bias.
    pub const GYRO_BIAS_DEG_PER_H: Range = Range::new(0.0, 1000.0, "deg/h");
    /// Gauss-Markov correlation time: more than 0 (0 is white noise, which
    /// the random walk figures describe), at most ~12 days.
    pub const CORRELATION_TIME_S: Range = Range::new(0.1, 1e6, "s");
    /// Deterministic gyro bias: 10 deg/s (the calibration file's limit).
    pub const GYRO_OFFSET_DEG_PER_S: Range = Range::within(10.0, "deg/s");
    /// Gyro scale-factor error: +-10 %.
    pub const SCALE_FACTOR_PPM: Range = Range::within(1e5, "ppm");
    /// Accelerometer velocity random walk.
    pub const VRW_M_PER_S_PER_SQRT_H: Range = Range::new(0.0, 10.0, "m/s/sqrt(h)");
    /// Accelerometer bias instability (0.1 g).
    pub const ACCEL_BIAS_INSTABILITY_M_PER_S2: Range = Range::new(0.0, 1.0, "m/s^2");
    /// Accelerometer residual bias after calibration.
    pub const RESIDUAL_BIAS_MG: Range = Range::new(0.0, 1000.0, "mg");
}

impl SensorModelFile {
    pub fn from_model(m: &SensorModel) -> Self {
        let (g, a) = (&m.noise.gyro, &m.noise.accel);
        let d = &m.deterministic;
        let k = d.accel_matrix;
        Self {
            gyro: GyroFile {
                arw_deg_per_sqrt_h: g[0].white_density / DEG * 60.0,
                bias_instability_deg_per_h: g[0].bias_instability / DEG * 3600.0,
                correlation_time_s: g[0].correlation_time,
                residual_bias_deg_per_h: g[0].residual_bias / DEG * 3600.0,
                bias_deg_per_s: [d.gyro_bias.x / DEG, d.gyro_bias.z / DEG],
                scale_factor_ppm: [d.gyro_scale.x * 1e6, d.gyro_scale.z * 1e6],
                ar4: [0, 1, 2].map(|i| ar_to_file(g[i].coloured, DEG)),
            },
            accel: AccelFile {
                vrw_m_per_s_per_sqrt_h: a[0].white_density * 60.0,
                bias_instability_m_per_s2: a[0].bias_instability,
                correlation_time_s: a[0].correlation_time,
                residual_bias_mg: a[0].residual_bias / STANDARD_GRAVITY * 1e3,
                bias_m_per_s2: [d.accel_bias.x, d.accel_bias.y, d.accel_bias.z],
                scale_misalignment: [0, 1, 2].map(|r| [k[(r, 0)], k[(r, 1)], k[(r, 2)]]),
                ar4: [0, 1, 2].map(|i| ar_to_file(a[i].coloured, 1.0)),
            },
            quantize: m.quantize,
        }
    }

    /// Checks every figure against [`limits`], the accelerometer matrix K
    /// as the calibration file's M = K^-1 is checked, and the AR models
    /// as AR-model files are.
    pub fn check(&self) -> Result<()> {
        use limits::*;
        // a figure against its range, named by its path in the file
        macro_rules! check {
            ($range:expr, $part:ident . $field:ident) => {
                $range.check(
                    concat!(stringify!($part), ".", stringify!($field)),
                    self.$part.$field,
                )?
            };
        }
        // the same for each element of an array
        macro_rules! check_each {
            ($range:expr, $part:ident . $field:ident) => {
                for (i, &value) in self.$part.$field.iter().enumerate() {
                    let name = concat!(stringify!($part), ".", stringify!($field));
                    $range.check(&format!("{name}[{i}]"), value)?;
                }
            };
        }
        check!(ARW_DEG_PER_SQRT_H, gyro.arw_deg_per_sqrt_h);
        check!(GYRO_BIAS_DEG_PER_H, gyro.bias_instability_deg_per_h);
        check!(CORRELATION_TIME_S, gyro.correlation_time_s);
        check!(GYRO_BIAS_DEG_PER_H, gyro.residual_bias_deg_per_h);
        check_each!(GYRO_OFFSET_DEG_PER_S, gyro.bias_deg_per_s);
        check_each!(SCALE_FACTOR_PPM, gyro.scale_factor_ppm);
        check!(VRW_M_PER_S_PER_SQRT_H, accel.vrw_m_per_s_per_sqrt_h);
        check!(
            ACCEL_BIAS_INSTABILITY_M_PER_S2,
            accel.bias_instability_m_per_s2
        );
        check!(CORRELATION_TIME_S, accel.correlation_time_s);
        check!(RESIDUAL_BIAS_MG, accel.residual_bias_mg);
        check_each!(cal::ACCEL_BIAS_M_S2, accel.bias_m_per_s2);
        let (g, a) = (&self.gyro, &self.accel);
        for (r, row) in a.scale_misalignment.iter().enumerate() {
            for (c, &k) in row.iter().enumerate() {
                let range = if r == c {
                    cal::CORRECTION_DIAGONAL
                } else {
                    cal::CORRECTION_OFF_DIAGONAL
                };
                range.check(&format!("accel.scale_misalignment[{r}][{c}]"), k)?;
            }
        }
        let k = Matrix3::from_fn(|r, c| a.scale_misalignment[r][c]);
        let sv = k.singular_values();
        cal::CORRECTION_CONDITION.check(
            "the condition number of accel.scale_misalignment",
            sv.max() / sv.min(),
        )?;
        for i in 0..3 {
            ar_from_file(&g.ar4[i], DEG, ArQuantity::AngularRate).with_context(|| {
                format!("gyro.ar4[{i}] (its noise_variance, in (deg/s)^2, checked in SI)")
            })?;
            ar_from_file(&a.ar4[i], 1.0, ArQuantity::SpecificForce)
                .with_context(|| format!("accel.ar4[{i}]"))?;
        }
        Ok(())
    }

    /// The model, checked ([`Self::check`]).
    pub fn to_model(&self, seed: u64) -> Result<SensorModel> {
        self.check()?;
        let g = &self.gyro;
        let a = &self.accel;
        let k = Matrix3::from_fn(|r, c| a.scale_misalignment[r][c]);
        let mut noise = ImuNoise::NONE;
        for (i, axis) in noise.gyro.iter_mut().enumerate() {
            *axis = AxisNoise {
                // The tool-axis rate is derived from accelerometers: no ARW.
                white_density: if i == 1 {
                    0.0
                } else {
                    arw_from_deg_per_sqrt_hour(g.arw_deg_per_sqrt_h)
                },
                coloured: ar_from_file(&g.ar4[i], DEG, ArQuantity::AngularRate)?,
                bias_instability: rate_from_deg_per_hour(g.bias_instability_deg_per_h),
                correlation_time: g.correlation_time_s,
                residual_bias: rate_from_deg_per_hour(g.residual_bias_deg_per_h),
            };
        }
        for (i, axis) in noise.accel.iter_mut().enumerate() {
            *axis = AxisNoise {
                white_density: a.vrw_m_per_s_per_sqrt_h / 60.0,
                coloured: ar_from_file(&a.ar4[i], 1.0, ArQuantity::SpecificForce)?,
                bias_instability: a.bias_instability_m_per_s2,
                correlation_time: a.correlation_time_s,
                residual_bias: a.residual_bias_mg * 1e-3 * STANDARD_GRAVITY,
            };
        }
        Ok(SensorModel {
            deterministic: DeterministicErrors {
                accel_bias: Vector3::from(a.bias_m_per_s2),
                accel_matrix: k,
                gyro_bias: Vector3::new(g.bias_deg_per_s[0], 0.0, g.bias_deg_per_s[1]) * DEG,
                gyro_scale: Vector3::new(g.scale_factor_ppm[0], 0.0, g.scale_factor_ppm[1]) * 1e-6,
            },
            noise,
            quantize: self.quantize,
            seed,
        })
    }

    pub fn load(path: &std::path::Path, seed: u64) -> Result<SensorModel> {
        let text = crate::formats::text_records::read_small_file(path)
            .with_context(|| format!("reading {}", path.display()))?;
        let file: SensorModelFile = serde_json::from_str(&text)
            .with_context(|| format!("{} is not a sensor model JSON", path.display()))?;
        file.to_model(seed)
            .with_context(|| format!("sensor model in {}", path.display()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_round_trip_through_json() {
        let model = SensorModel::scc1300(5);
        let json = serde_json::to_string_pretty(&SensorModelFile::from_model(&model)).unwrap();
        let file: SensorModelFile = serde_json::from_str(&json).unwrap();
        let back = file.to_model(5).unwrap();
        assert_eq!(back.quantize, model.quantize);
        assert!((back.deterministic.gyro_bias - model.deterministic.gyro_bias).norm() < 1e-18);
        for i in 0..3 {
            for (b, m) in [
                (&back.noise.gyro[i], &model.noise.gyro[i]),
                (&back.noise.accel[i], &model.noise.accel[i]),
            ] {
                assert!(
                    (b.white_density - m.white_density).abs() <= 1e-12 * m.white_density.max(1e-30)
                );
                assert!((b.residual_bias - m.residual_bias).abs() <= 1e-12 * m.residual_bias);
                let (bc, mc) = (b.coloured.unwrap(), m.coloured.unwrap());
                assert!((bc.noise_variance - mc.noise_variance).abs() <= 1e-12 * mc.noise_variance);
            }
        }
    }

    #[test]
    fn bad_models_are_refused() {
        let mut file = SensorModelFile::from_model(&SensorModel::scc1300(1));
        file.gyro.arw_deg_per_sqrt_h = -1.0;
        assert!(file.to_model(1).is_err());
        let mut file = SensorModelFile::from_model(&SensorModel::scc1300(1));
        file.accel.ar4[0] = Some(Ar4File {
            a: [-2.0, 1.0, 0.0, 0.0],
            noise_variance: 1.0,
        });
        assert!(format!("{:#}", file.to_model(1).unwrap_err()).contains("accel.ar4[0]"));
        let mut file = SensorModelFile::from_model(&SensorModel::scc1300(1));
        file.accel.scale_misalignment = [[0.0; 3]; 3];
        assert!(file.to_model(1).is_err());
    }

    /// The audit's bad files: refused, field and range named.
    #[test]
    fn figures_outside_the_physical_ranges_are_refused() {
        let refused = |edit: &dyn Fn(&mut SensorModelFile), needle: &str| {
            let mut file = SensorModelFile::from_model(&SensorModel::scc1300(1));
            edit(&mut file);
            let e = format!("{:#}", file.to_model(1).unwrap_err());
            assert!(e.contains(needle), "{needle:?} not in {e}");
        };
        refused(
            &|f| f.gyro.correlation_time_s = 0.0,
            "`gyro.correlation_time_s` is 0 s, outside its range 0.1 to 1e6 s",
        );
        refused(
            &|f| f.accel.correlation_time_s = 0.0,
            "`accel.correlation_time_s` is 0 s",
        );
        refused(
            &|f| f.gyro.arw_deg_per_sqrt_h = 1e300,
            "`gyro.arw_deg_per_sqrt_h` is 1e300 deg/sqrt(h), outside its range 0 to 10",
        );
        refused(
            &|f| f.accel.bias_m_per_s2[2] = 1e308,
            "`accel.bias_m_per_s2[2]` is 1e308",
        );
        refused(
            &|f| f.gyro.ar4[1].as_mut().unwrap().noise_variance = 1e300,
            "gyro.ar4[1] (its noise_variance, in (deg/s)^2, checked in SI): `noise_variance` is",
        );
        refused(
            &|f| f.accel.scale_misalignment[0][1] = 1e300,
            "`accel.scale_misalignment[0][1]` is 1e300",
        );
    }
}
