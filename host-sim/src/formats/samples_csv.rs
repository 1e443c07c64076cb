//! The probe-sample CSV: what `host-sim simulate` writes and `host-sim align`
//! reads until the binary UART capture takes over. One row per 20 Hz sample,
//! SI units named in the header; the truth columns are present in simulated
//! files only.
use crate::formats::text_records::{excerpt, for_each_record};
use anyhow::{bail, Context, Result};
use mwd_core::conventions::Euler;
use mwd_core::probe_sample::ProbeSample;
use nalgebra::Vector3;
use std::io::{Read, Write};

/// One output sample of the probe's sensors (body frame, SI), with the truth.
#[derive(Clone, Debug, PartialEq)]
pub struct SimSample {
    /// End of the sample interval (s).
    pub time: f64,
    /// Measured rates (rad/s); only x and z exist on the probe (y is NaN).
    pub gyro: Vector3<f64>,
    /// Measured specific force (m/s^2).
    pub accel: Vector3<f64>,
    /// True mean omega_ib^b over the interval (rad/s).
    pub true_rate: Vector3<f64>,
    /// True mean specific force over the interval (m/s^2).
    pub true_accel: Vector3<f64>,
    /// True attitude at `time`.
    pub truth: mwd_core::conventions::Euler,
    /// Six-position runs: the calibration position code (1-6).
    pub position_code: Option<u8>,
}

/// The measured columns, SI units in their names (also the columns a
/// capture's samples are read as).
pub const MEASURED_COLUMNS: [&str; 6] = [
    "time_s",
    "gyro_x_rad_s",
    "gyro_z_rad_s",
    "accel_x_m_s2",
    "accel_y_m_s2",
    "accel_z_m_s2",
];
const TRUTH: [&str; 3] = ["true_roll_rad", "true_pitch_rad", "true_heading_rad"];

/// One recorded sample.
#[derive(Clone, Debug, PartialEq)]
pub struct Record {
    pub time: f64,
    /// The x and z gyros and the specific force, body frame.
    pub sample: ProbeSample,
    pub truth: Option<Euler>,
}

impl From<&SimSample> for Record {
    fn from(s: &SimSample) -> Self {
        Self {
            time: s.time,
            sample: ProbeSample::new(s.gyro.x, s.gyro.z, s.accel),
            truth: Some(s.truth),
        }
    }
}

/// Writes the header and the samples; six-position runs get a `position`
/// column (the code `host-sim calibrate` reads).
pub fn write<W: Write>(mut out: W, samples: impl IntoIterator<Item = SimSample>) -> Result<()> {
    let mut samples = samples.into_iter().peekable();
    let with_position = samples.peek().is_some_and(|s| s.position_code.is_some());
    let position_header = if with_position { ",position" } else { "" };
    writeln!(
        out,
        "{},{}{position_header}",
        MEASURED_COLUMNS.join(","),
        TRUTH.join(",")
    )?;
    for s in samples {
        write!(
            out,
            "{:.3},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e}",
            s.time,
            s.gyro.x,
            s.gyro.z,
            s.accel.x,
            s.accel.y,
            s.accel.z,
            s.truth.roll,
            s.truth.pitch,
            s.truth.heading
        )?;
        if with_position {
            write!(out, ",{}", s.position_code.unwrap_or(0))?;
        }
        writeln!(out)?;
    }
    Ok(())
}

/// Reads a sample CSV as it streams in (separators, quoting, BOM and the
/// line-length limit of [`crate::formats::text_records`]), checking every
/// row; a bad value names its line and column.
pub fn read<R: Read>(input: R) -> Result<Vec<Record>> {
    let mut header: Option<Header> = None;
    let mut records = Vec::new();
    for_each_record(input, |line, fields| {
        let Some(Header {
            names,
            measured,
            truth,
        }) = &header
        else {
            header = Some(parse_header(fields)?);
            return Ok(());
        };
        let value = |col: usize| -> Result<f64> {
            let text = fields.get(col).with_context(|| {
                format!(
                    "line {line}: {} fields, expected {}",
                    fields.len(),
                    names.len()
                )
            })?;
            let v: f64 = text.parse().with_context(|| {
                format!(
                    "line {line}, column `{}`: `{}` is not a number",
                    names[col],
                    excerpt(text)
                )
            })?;
            if !v.is_finite() {
                bail!(
                    "line {line}, column `{}`: `{}` is not finite",
                    names[col],
                    excerpt(text)
                );
            }
            Ok(v)
        };
        let mut m = [0.0; 6];
        for (slot, &col) in m.iter_mut().zip(measured) {
            *slot = value(col)?;
        }
        let truth = match truth {
            Some([r, p, h]) => Some(Euler::new(value(*r)?, value(*p)?, value(*h)?)),
            None => None,
        };
        records.push(Record {
            time: m[0],
            sample: ProbeSample::new(m[1], m[2], Vector3::new(m[3], m[4], m[5])),
            truth,
        });
        Ok(())
    })?;
    if header.is_none() {
        bail!("empty file: expected a header starting with `time_s`");
    }
    if records.is_empty() {
        bail!("no samples after the header");
    }
    Ok(records)
}

/// The header's names and the columns of the measured and truth values.
struct Header {
    names: Vec<String>,
    measured: [usize; 6],
    truth: Option<[usize; 3]>,
}

fn parse_header(fields: &[&str]) -> Result<Header> {
    let find = |name: &str| fields.iter().position(|n| *n == name);
    let mut measured = [0usize; 6];
    for (slot, name) in measured.iter_mut().zip(MEASURED_COLUMNS) {
        *slot = find(name).with_context(|| {
            format!(
                "not a probe sample CSV: no `{name}` column in the header `{}`",
                excerpt(&fields.join(","))
            )
        })?;
    }
    let truth = match TRUTH.map(find) {
        [Some(r), Some(p), Some(h)] => Some([r, p, h]),
        _ => None,
    };
    let names = fields.iter().map(|f| f.to_string()).collect();
    Ok(Header {
        names,
        measured,
        truth,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::{SensorModel, SensorSimulator, Trajectory};
    use mwd_core::timing::SAMPLE_INTERVAL_S;

    #[test]
    fn round_trip_keeps_the_samples() {
        let traj = Trajectory::paper_static(Euler::new(0.1, 0.2, 0.3));
        let samples: Vec<_> =
            SensorSimulator::new(traj, SensorModel::scc1300(1), SAMPLE_INTERVAL_S)
                .take(10)
                .collect();
        let mut buf = Vec::new();
        write(&mut buf, samples.clone()).unwrap();
        let back = read(buf.as_slice()).unwrap();
        assert_eq!(back.len(), 10);
        for (r, s) in back.iter().zip(&samples) {
            assert!((r.sample.rate_x() - s.gyro.x).abs() <= 1e-5 * s.gyro.x.abs());
            let f = r.sample.specific_force;
            assert!((f.z - s.accel.z).abs() <= 1e-5 * s.accel.z.abs());
            assert!(r.truth.is_some());
        }
    }

    #[test]
    fn bad_files_get_clear_errors() {
        let err = |text: &str| read(text.as_bytes()).unwrap_err().to_string();
        assert!(err("").contains("empty file"));
        assert!(err("a,b,c\n1,2,3\n").contains("no `time_s` column"));
        let header = MEASURED_COLUMNS.join(",");
        assert!(err(&format!("{header}\n")).contains("no samples"));
        let bad = format!("{header}\n0.05,1,2,3,4,x\n");
        let e = err(&bad);
        assert!(e.contains("line 2") && e.contains("accel_z_m_s2"), "{e}");
        let nan = format!("{header}\n0.05,1,2,3,4,NaN\n");
        assert!(err(&nan).contains("not finite"));
        let short = format!("{header}\n0.05,1,2\n");
        assert!(err(&short).contains("fields"));
    }
}
