//! What `host-sim simulate` writes: the samples (a capture of the bytes
//! the probe would send, a sample CSV file, or the CSV on standard
//! output), and for a drilled lateral its truth trajectory, the surface
//! depth log and the probe's physical input stream, all written as the
//! samples are made (a lateral of a day is millions of samples: none is
//! kept).

use crate::formats::capture::ProbeSetup;
use crate::formats::files::{create_buffered, is_broken_pipe, OutputFile};
use crate::formats::{capture, samples_csv};
use crate::sim::stream::SensorStreamWriter;
use crate::sim::{Drilling, DrillingSimulator, SensorModel, SimSample, Truth};
use anyhow::{Context, Result};
use mwd_core::conventions::DEG;
use mwd_core::timing::SAMPLE_INTERVAL_S;
use std::io::Write;
use std::path::{Path, PathBuf};

/// Where the samples go.
#[derive(Clone, Copy, Debug)]
// One per run: the capture's probe configuration inline costs nothing.
#[allow(clippy::large_enum_variant)]
pub enum SampleSink<'a> {
    /// A capture (`.bin`) of a probe at `site` (tied in to `tie_in`): a
    /// boot event, then raw-sample and navigation frames.
    Capture { path: &'a Path, probe: ProbeSetup },
    /// A sample CSV file.
    Csv(&'a Path),
    /// The sample CSV on standard output; a reader that stopped (`| head`)
    /// ends the run quietly.
    Stdout,
}

/// Writes `samples` to `sink`; returns the capture's size in bytes (0 for
/// a CSV).
pub fn write_samples(sink: SampleSink, samples: impl Iterator<Item = SimSample>) -> Result<u64> {
    match sink {
        SampleSink::Capture { path, probe } => write_capture(path, samples, &probe),
        SampleSink::Csv(path) => {
            write_csv(path, samples)?;
            Ok(0)
        }
        SampleSink::Stdout => match samples_csv::write(std::io::stdout().lock(), samples) {
            Err(e) if is_broken_pipe(&e) => Ok(0),
            other => other.map(|()| 0),
        },
    }
}

/// Writes the capture of a probe at `site` (tied in to `tie_in`) of
/// `samples`; returns its size in bytes.
fn write_capture(
    path: &Path,
    samples: impl Iterator<Item = SimSample>,
    probe: &ProbeSetup,
) -> Result<u64> {
    let mut capture = capture::create_capture(path)?;
    capture::write_simulated_probe(&mut capture, samples, probe)?;
    let bytes = capture.bytes_written();
    capture
        .finish()
        .with_context(|| format!("writing {}", path.display()))?
        .finish()?;
    Ok(bytes)
}

/// Writes `samples` as a sample CSV file.
fn write_csv(path: &Path, samples: impl Iterator<Item = SimSample>) -> Result<()> {
    let mut out = create_buffered(path)?;
    samples_csv::write(&mut out, samples)?;
    out.finish()
}

/// Longest drilling run simulated: 7 days (a 1000 m lateral at 30 m/h
/// takes ~37 h).
pub const MAX_LATERAL_S: f64 = 7.0 * 86_400.0;

/// A drilled lateral's outputs besides the samples (each only when given).
#[derive(Clone, Copy, Debug)]
pub struct LateralOutputs<'a> {
    /// The truth trajectory (CSV).
    pub truth: Option<&'a Path>,
    /// One truth row every this many samples.
    pub truth_every: usize,
    /// The probe's physical input stream (`hil_mock::stream`).
    pub sensor_stream: Option<&'a Path>,
    /// The surface depth log (CSV: time_s, md_m).
    pub depth_log: Option<&'a Path>,
}

/// Samples with a sensor beyond its measurement range.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct OverRange {
    /// With an accelerometer axis beyond 6 g.
    pub accel: usize,
    /// With a gyro beyond 300 deg/s.
    pub gyro: usize,
}

/// Drills `drilling` with the sensors of `model`: the samples go to
/// `write_samples` as they are made (it is called once, after the truth
/// and sensor-stream files are created), the truth and the sensor stream
/// are written alongside, the depth log at the end. Refused beyond
/// [`MAX_LATERAL_S`]. Returns the samples beyond range.
pub fn drill(
    drilling: &Drilling,
    model: SensorModel,
    outputs: &LateralOutputs,
    write_samples: impl FnOnce(&mut dyn Iterator<Item = SimSample>) -> Result<()>,
) -> Result<OverRange> {
    anyhow::ensure!(
        drilling.duration() <= MAX_LATERAL_S,
        "the plan takes {:.1} h to drill; at most {:.0} h are simulated",
        drilling.duration() / 3600.0,
        MAX_LATERAL_S / 3600.0
    );
    let n = drilling.sample_count(SAMPLE_INTERVAL_S);
    let mut truth_out = match outputs.truth {
        Some(p) => {
            let mut w = TruthWriter::create(p)?;
            w.row(&drilling.truth(0.0))?;
            Some(w)
        }
        None => None,
    };
    let mut stream = match outputs.sensor_stream {
        Some(p) => Some(SensorStreamWriter::create(p, n)?),
        None => None,
    };
    // Created before the samples are written: a depth log that cannot be
    // created fails the run before any output is named.
    let depth_log = outputs.depth_log.map(create_buffered).transpose()?;
    let mut counts = OverRange::default();
    let mut failure: Option<anyhow::Error> = None;
    let every = outputs.truth_every;
    let mut samples = DrillingSimulator::new(drilling, model, SAMPLE_INTERVAL_S)
        .enumerate()
        .map(|(i, d)| {
            counts.accel += usize::from(d.accel_over_range);
            counts.gyro += usize::from(d.gyro_over_range);
            if let Some(w) = truth_out.as_mut() {
                if (i + 1) % every == 0 {
                    if let Err(e) = w.row(&d.truth) {
                        failure.get_or_insert(e);
                    }
                }
            }
            if let Some(w) = stream.as_mut() {
                if let Err(e) = w.push(&d.sample) {
                    failure.get_or_insert(e);
                }
            }
            d.sample
        });
    write_samples(&mut samples)?;
    drop(samples);
    if let Some(e) = failure {
        return Err(e);
    }
    if let Some(w) = truth_out {
        w.finish()?;
    }
    if let Some(w) = stream {
        w.finish()?;
    }
    if let Some(out) = depth_log {
        write_depth_log(out, drilling)?;
    }
    Ok(counts)
}

/// The truth trajectory CSV.
struct TruthWriter {
    out: OutputFile,
    path: PathBuf,
}

impl TruthWriter {
    fn create(path: &Path) -> Result<Self> {
        let mut out = create_buffered(path)?;
        writeln!(
            out,
            "time_s,md_m,tvd_m,north_m,east_m,inclination_deg,azimuth_deg,toolface_deg,\
             roll_deg,pitch_deg,heading_deg,state"
        )?;
        Ok(Self {
            out,
            path: path.to_owned(),
        })
    }

    fn row(&mut self, t: &Truth) -> Result<()> {
        let e = t.euler();
        let p = &t.point;
        writeln!(
            self.out,
            "{:.3},{:.6},{:.6},{:.6},{:.6},{:.9},{:.9},{:.9},{:.9},{:.9},{:.9},{}",
            t.time,
            t.md,
            p.nev.z,
            p.nev.x,
            p.nev.y,
            p.inclination / DEG,
            p.azimuth / DEG,
            mwd_core::conventions::wrap_two_pi(t.toolface) / DEG,
            e.roll / DEG,
            e.pitch / DEG,
            e.heading / DEG,
            t.state.name()
        )
        .with_context(|| format!("writing {}", self.path.display()))
    }

    fn finish(self) -> Result<()> {
        self.out.finish()
    }
}

/// The surface depth log: time_s, md_m (with the plan's depth errors).
fn write_depth_log(mut out: OutputFile, drilling: &Drilling) -> Result<()> {
    let mut rows = || -> std::io::Result<()> {
        writeln!(out, "time_s,md_m")?;
        for (t, md) in drilling.depth_log() {
            writeln!(out, "{t:.3},{md:.4}")?;
        }
        Ok(())
    };
    rows().with_context(|| format!("writing {}", out.path().display()))?;
    out.finish()
}
