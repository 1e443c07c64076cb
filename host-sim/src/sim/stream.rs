//! The probe's physical input stream (`simulate --sensor-stream FILE`):
//! each simulated sample, sensor errors applied, as each of the two
//! SCC1300 parts senses it in its own axes, in the binary format of
//! `hil_mock::stream` (header: magic, version, parts, rate, count; per
//! sample per part: rate, 3 specific forces, temperature, f32 LE). The
//! QEMU probe (feature `qemu-drilling`) feeds its simulated parts from it,
//! so the probe in QEMU and the host's `.bin` capture see the same physics.
use super::sensor::SimSample;
use crate::formats::files::OutputFile;
use anyhow::{Context, Result};
use hil_mock::stream::{encode_record, StreamHeader, StreamRecord};
use hil_mock::PhysicalSample;
use mwd_core::sensor_units::PART_MOUNTINGS;
use mwd_core::timing::SAMPLE_RATE_HZ;
use std::io::Write;
use std::path::{Path, PathBuf};

/// The temperature both parts read: the simulator has no thermal model,
/// and the `.bin` capture writes the same 25 degC.
pub const STREAM_TEMPERATURE_DEGC: f32 = 25.0;

/// What the two parts sense for one simulated sample: the body-frame
/// measurements through each part's mounting (`PART_MOUNTINGS`), in f32.
pub fn part_record(s: &SimSample) -> StreamRecord {
    // The probe has no body-y gyro (the simulator writes NaN there); no
    // part reads that axis, 0 keeps the record finite.
    let y = if s.gyro.y.is_finite() { s.gyro.y } else { 0.0 };
    let rate = [s.gyro.x as f32, y as f32, s.gyro.z as f32];
    let accel = [s.accel.x as f32, s.accel.y as f32, s.accel.z as f32];
    PART_MOUNTINGS.map(|m| PhysicalSample {
        rate_rad_s: m.gyro_rate_from_body(rate),
        accel_m_s2: m.body_to_sensor(accel),
        temperature_degc: STREAM_TEMPERATURE_DEGC,
    })
}

/// Writes a stream of a known number of samples.
pub struct SensorStreamWriter {
    out: OutputFile,
    path: PathBuf,
    expected: u32,
    written: u32,
}

impl SensorStreamWriter {
    /// Creates `path` for `count` samples (the header says so).
    pub fn create(path: &Path, count: usize) -> Result<Self> {
        let expected = u32::try_from(count)
            .ok()
            .filter(|&n| n > 0)
            .with_context(|| format!("a sensor stream holds 1 to 2^32-1 samples, not {count}"))?;
        let mut out = OutputFile::create(path)?;
        let header = StreamHeader {
            sample_rate_hz: SAMPLE_RATE_HZ as u32,
            sample_count: expected,
        };
        out.write_all(&header.encode())
            .with_context(|| format!("writing {}", path.display()))?;
        Ok(Self {
            out,
            path: path.to_owned(),
            expected,
            written: 0,
        })
    }

    pub fn push(&mut self, s: &SimSample) -> Result<()> {
        anyhow::ensure!(
            self.written < self.expected,
            "{}: more samples than the {} announced",
            self.path.display(),
            self.expected
        );
        let record = part_record(s);
        anyhow::ensure!(
            record
                .iter()
                .all(|p| p.rate_rad_s.is_finite() && p.accel_m_s2.iter().all(|a| a.is_finite())),
            "sample {} at {:.3} s is not finite: no stream record for it",
            self.written,
            s.time
        );
        self.out
            .write_all(&encode_record(&record))
            .with_context(|| format!("writing {}", self.path.display()))?;
        self.written += 1;
        Ok(())
    }

    /// Flushes; fails unless every announced sample was written.
    pub fn finish(self) -> Result<()> {
        anyhow::ensure!(
            self.written == self.expected,
            "{}: {} samples written of the {} announced",
            self.path.display(),
            self.written,
            self.expected
        );
        self.out.finish()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use hil_mock::StreamPlayer;
    use nalgebra::Vector3;

    #[test]
    fn a_written_stream_plays_back_each_part_in_its_axes() {
        let sample = |k: f64| SimSample {
            time: 0.05 * k,
            gyro: Vector3::new(0.01 * k, f64::NAN, -0.02),
            accel: Vector3::new(0.1, 0.2 * k, 9.8),
            true_rate: Vector3::zeros(),
            true_accel: Vector3::zeros(),
            truth: mwd_core::conventions::Euler::new(0.0, 0.0, 0.0),
            position_code: None,
        };
        let path = std::env::temp_dir().join(format!("stream-test-{}.bin", std::process::id()));
        let mut w = SensorStreamWriter::create(&path, 3).expect("create");
        for k in 0..3 {
            w.push(&sample(f64::from(k))).expect("push");
        }
        w.finish().expect("finish");
        let bytes = std::fs::read(&path).expect("read back");
        let _ = std::fs::remove_file(&path);
        let mut player = StreamPlayer::<_, 64>::open(&bytes[..]).expect("a good stream");
        assert_eq!(player.header().sample_count, 3);
        player.advance_to(2).expect("record 2");
        let s = sample(2.0);
        for (part, m) in PART_MOUNTINGS.iter().enumerate() {
            let got = player.part(part);
            assert_eq!(
                m.sensor_to_body(got.accel_m_s2),
                [0.1, 0.4, 9.8],
                "part {part}"
            );
            let body = [s.gyro.x as f32, 0.0, s.gyro.z as f32];
            assert_eq!(got.rate_rad_s, m.gyro_rate_from_body(body));
        }
        assert_ne!(player.part(0).rate_rad_s, player.part(1).rate_rad_s);
    }
}
