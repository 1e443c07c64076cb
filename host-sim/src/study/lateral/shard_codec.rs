//! A job's outcome as bytes for a shard file ([`super::shard`]): every
//! number by its bit pattern, so that a merge rebuilds each run exactly
//! (JSON numbers would lose the NaN and infinite sigmas the probe reports
//! and may round a digit on reading). Little-endian, fields in their
//! declaration order; the structs are taken apart whole, so that a new
//! field fails to compile here until the format carries it.

use super::covariance::CovariancePrediction;
use super::run::JobOutcome;
use crate::study::drilling_run::{PositionCheck, RunOutcome, StationCheck, TdCheck};
use anyhow::{bail, Context, Result};
use mwd_core::probe::StationLink;
use mwd_core::protocol::StationSurvey;

const RUN: u8 = 1;
const PREDICTION: u8 = 2;

/// The bytes of `outcome`.
pub fn encode(outcome: &JobOutcome) -> Vec<u8> {
    let mut e = Encoder(Vec::new());
    match outcome {
        JobOutcome::Run(r) => {
            e.u8(RUN);
            e.result(r, Encoder::run);
        }
        JobOutcome::Prediction(p) => {
            e.u8(PREDICTION);
            e.result(p, Encoder::prediction);
        }
    }
    e.0
}

/// The outcome of `bytes`, all of them.
pub fn decode(bytes: &[u8]) -> Result<JobOutcome> {
    let mut d = Decoder { bytes, at: 0 };
    let outcome = match d.u8()? {
        RUN => JobOutcome::Run(d.result(Decoder::run)?),
        PREDICTION => JobOutcome::Prediction(d.result(Decoder::prediction)?),
        kind => bail!("unknown outcome kind {kind}"),
    };
    if d.at != bytes.len() {
        bail!("{} bytes left after the outcome", bytes.len() - d.at);
    }
    Ok(outcome)
}

/// The bytes of one Monte Carlo run's outcome alone (the
/// drilling-coverage study's job, `crate::study::coverage_shard`).
pub(crate) fn encode_run(run: &Result<RunOutcome, String>) -> Vec<u8> {
    let mut e = Encoder(Vec::new());
    e.result(run, Encoder::run);
    e.0
}

/// The run of `bytes`, all of them.
pub(crate) fn decode_run(bytes: &[u8]) -> Result<Result<RunOutcome, String>> {
    let mut d = Decoder { bytes, at: 0 };
    let run = d.result(Decoder::run)?;
    if d.at != bytes.len() {
        bail!("{} bytes left after the run", bytes.len() - d.at);
    }
    Ok(run)
}

struct Encoder(Vec<u8>);

impl Encoder {
    fn u8(&mut self, v: u8) {
        self.0.push(v);
    }
    fn u16(&mut self, v: u16) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    fn u32(&mut self, v: u32) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    fn u64(&mut self, v: u64) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    fn len(&mut self, n: usize) {
        self.u64(n as u64);
    }
    fn f32(&mut self, v: f32) {
        self.u32(v.to_bits());
    }
    fn f64(&mut self, v: f64) {
        self.u64(v.to_bits());
    }
    fn bool(&mut self, v: bool) {
        self.u8(u8::from(v));
    }
    fn text(&mut self, v: &str) {
        self.len(v.len());
        self.0.extend_from_slice(v.as_bytes());
    }
    fn option<T>(&mut self, v: &Option<T>, some: impl FnOnce(&mut Self, &T)) {
        match v {
            Some(v) => {
                self.u8(1);
                some(self, v);
            }
            None => self.u8(0),
        }
    }
    fn opt_f64(&mut self, v: &Option<f64>) {
        self.option(v, |e, v| e.f64(*v));
    }
    fn opt_text(&mut self, v: &Option<String>) {
        self.option(v, |e, v| e.text(v));
    }
    fn f64s(&mut self, v: &[f64]) {
        v.iter().for_each(|&x| self.f64(x));
    }
    fn f32s(&mut self, v: &[f32]) {
        v.iter().for_each(|&x| self.f32(x));
    }
    fn result<T>(&mut self, v: &Result<T, String>, ok: impl FnOnce(&mut Self, &T)) {
        match v {
            Ok(v) => {
                self.u8(1);
                ok(self, v);
            }
            Err(e) => {
                self.u8(0);
                self.text(e);
            }
        }
    }

    fn run(&mut self, o: &RunOutcome) {
        let RunOutcome {
            seed,
            stations,
            td,
            td_note,
            method_td_error_ne,
            samples,
            elapsed_s,
            cpu_s,
            uncalibrated,
        } = o;
        self.u64(*seed);
        self.len(stations.len());
        stations.iter().for_each(|s| self.station(s));
        self.option(td, Self::td);
        self.opt_text(td_note);
        self.option(method_td_error_ne, |e, v| e.f64s(v));
        self.len(*samples);
        self.f64(*elapsed_s);
        self.opt_f64(cpu_s);
        self.bool(*uncalibrated);
    }

    fn station(&mut self, s: &StationCheck) {
        let StationCheck {
            survey,
            error,
            truth_md,
            azimuth_sigma_before,
            azimuth_error_before,
            link,
            position,
        } = s;
        let StationSurvey {
            time_us,
            station,
            flags,
            start_sample,
            end_sample,
            angles,
            angles_std,
            correlations,
            still_quality,
        } = survey;
        self.u64(*time_us);
        self.u16(*station);
        self.u16(*flags);
        self.u32(*start_sample);
        self.u32(*end_sample);
        self.f32s(angles);
        self.f32s(angles_std);
        self.f32s(correlations);
        self.f32(*still_quality);
        self.f64s(error);
        self.f64(*truth_md);
        self.opt_f64(azimuth_sigma_before);
        self.opt_f64(azimuth_error_before);
        self.option(link, Self::link);
        self.option(position, |e, p| {
            let PositionCheck { error_ne, cov_ne } = p;
            e.f64s(error_ne);
            e.f64s(cov_ne);
        });
    }

    fn link(&mut self, l: &StationLink) {
        let StationLink {
            station,
            previous,
            covariance,
            cross_previous,
        } = l;
        self.u16(*station);
        self.u16(*previous);
        covariance.iter().for_each(|row| self.f32s(row));
        self.option(cross_previous, |e, m| m.iter().for_each(|row| e.f32s(row)));
    }

    fn td(&mut self, t: &TdCheck) {
        let TdCheck {
            error_ne,
            d2,
            cov_ne,
            method_cov_ne,
        } = t;
        self.f64s(error_ne);
        self.f64(*d2);
        self.f64s(cov_ne);
        self.f64s(method_cov_ne);
    }

    fn prediction(&mut self, p: &CovariancePrediction) {
        let CovariancePrediction {
            grade,
            well,
            lateral_length_m,
            td_horizontal_1_sigma_m,
            td_semi_major_1_sigma_m,
            td_semi_major_1_sigma_per_1000_m,
            rms_station_azimuth_sigma_deg,
            rms_station_inclination_sigma_deg,
            azimuth_undetermined_stations,
            along_md,
            method_td_error_m,
            td_method_1_sigma_m,
            td_without_method_1_sigma_m,
            td_note,
            cpu_s,
            wall_s,
        } = p;
        self.text(grade);
        self.text(well);
        self.f64(*lateral_length_m);
        self.opt_f64(td_horizontal_1_sigma_m);
        self.opt_f64(td_semi_major_1_sigma_m);
        self.opt_f64(td_semi_major_1_sigma_per_1000_m);
        self.opt_f64(rms_station_azimuth_sigma_deg);
        self.opt_f64(rms_station_inclination_sigma_deg);
        self.len(*azimuth_undetermined_stations);
        self.len(along_md.len());
        for (md, azimuth, horizontal) in along_md {
            self.f64(*md);
            self.opt_f64(azimuth);
            self.opt_f64(horizontal);
        }
        self.opt_f64(method_td_error_m);
        self.opt_f64(td_method_1_sigma_m);
        self.opt_f64(td_without_method_1_sigma_m);
        self.opt_text(td_note);
        self.opt_f64(cpu_s);
        self.f64(*wall_s);
    }
}

struct Decoder<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl Decoder<'_> {
    fn take<const N: usize>(&mut self) -> Result<[u8; N]> {
        let end = self.at.checked_add(N).filter(|&e| e <= self.bytes.len());
        let Some(end) = end else {
            bail!("the outcome ends early (byte {})", self.at);
        };
        let mut out = [0u8; N];
        out.copy_from_slice(&self.bytes[self.at..end]);
        self.at = end;
        Ok(out)
    }
    fn u8(&mut self) -> Result<u8> {
        Ok(self.take::<1>()?[0])
    }
    fn u16(&mut self) -> Result<u16> {
        Ok(u16::from_le_bytes(self.take()?))
    }
    fn u32(&mut self) -> Result<u32> {
        Ok(u32::from_le_bytes(self.take()?))
    }
    fn u64(&mut self) -> Result<u64> {
        Ok(u64::from_le_bytes(self.take()?))
    }
    /// A count, no larger than the bytes left (each item takes one at
    /// least): a corrupt count cannot ask for a huge allocation.
    fn len(&mut self) -> Result<usize> {
        let n = self.u64()?;
        let left = (self.bytes.len() - self.at) as u64;
        if n > left {
            bail!("a count of {n} with {left} bytes left");
        }
        Ok(n as usize)
    }
    fn f32(&mut self) -> Result<f32> {
        Ok(f32::from_bits(self.u32()?))
    }
    fn f64(&mut self) -> Result<f64> {
        Ok(f64::from_bits(self.u64()?))
    }
    fn bool(&mut self) -> Result<bool> {
        match self.u8()? {
            0 => Ok(false),
            1 => Ok(true),
            b => bail!("{b} is no flag"),
        }
    }
    fn text(&mut self) -> Result<String> {
        let n = self.len()?;
        let bytes = self.bytes[self.at..self.at + n].to_vec();
        self.at += n;
        String::from_utf8(bytes).context("a text that is not UTF-8")
    }
    fn option<T>(&mut self, some: impl FnOnce(&mut Self) -> Result<T>) -> Result<Option<T>> {
        Ok(if self.bool()? {
            Some(some(self)?)
        } else {
            None
        })
    }
    fn opt_f64(&mut self) -> Result<Option<f64>> {
        self.option(Self::f64)
    }
    fn opt_text(&mut self) -> Result<Option<String>> {
        self.option(Self::text)
    }
    fn f64s<const N: usize>(&mut self) -> Result<[f64; N]> {
        let mut out = [0.0; N];
        for v in &mut out {
            *v = self.f64()?;
        }
        Ok(out)
    }
    fn f32s<const N: usize>(&mut self) -> Result<[f32; N]> {
        let mut out = [0.0; N];
        for v in &mut out {
            *v = self.f32()?;
        }
        Ok(out)
    }
    fn matrix<const N: usize>(&mut self) -> Result<[[f32; N]; N]> {
        let mut out = [[0.0; N]; N];
        for row in &mut out {
            *row = self.f32s()?;
        }
        Ok(out)
    }
    fn result<T>(&mut self, ok: impl FnOnce(&mut Self) -> Result<T>) -> Result<Result<T, String>> {
        Ok(if self.bool()? {
            Ok(ok(self)?)
        } else {
            Err(self.text()?)
        })
    }

    fn run(&mut self) -> Result<RunOutcome> {
        let seed = self.u64()?;
        let n = self.len()?;
        let stations = (0..n).map(|_| self.station()).collect::<Result<_>>()?;
        Ok(RunOutcome {
            seed,
            stations,
            td: self.option(Self::td)?,
            td_note: self.opt_text()?,
            method_td_error_ne: self.option(Self::f64s)?,
            samples: self.u64()? as usize,
            elapsed_s: self.f64()?,
            cpu_s: self.opt_f64()?,
            uncalibrated: self.bool()?,
        })
    }

    fn station(&mut self) -> Result<StationCheck> {
        let survey = StationSurvey {
            time_us: self.u64()?,
            station: self.u16()?,
            flags: self.u16()?,
            start_sample: self.u32()?,
            end_sample: self.u32()?,
            angles: self.f32s()?,
            angles_std: self.f32s()?,
            correlations: self.f32s()?,
            still_quality: self.f32()?,
        };
        Ok(StationCheck {
            survey,
            error: self.f64s()?,
            truth_md: self.f64()?,
            azimuth_sigma_before: self.opt_f64()?,
            azimuth_error_before: self.opt_f64()?,
            link: self.option(Self::link)?,
            position: self.option(|d| {
                Ok(PositionCheck {
                    error_ne: d.f64s()?,
                    cov_ne: d.f64s()?,
                })
            })?,
        })
    }

    fn link(&mut self) -> Result<StationLink> {
        Ok(StationLink {
            station: self.u16()?,
            previous: self.u16()?,
            covariance: self.matrix()?,
            cross_previous: self.option(Self::matrix)?,
        })
    }

    fn td(&mut self) -> Result<TdCheck> {
        Ok(TdCheck {
            error_ne: self.f64s()?,
            d2: self.f64()?,
            cov_ne: self.f64s()?,
            method_cov_ne: self.f64s()?,
        })
    }

    fn prediction(&mut self) -> Result<CovariancePrediction> {
        let (grade, well, lateral_length_m) = (self.text()?, self.text()?, self.f64()?);
        let td_horizontal_1_sigma_m = self.opt_f64()?;
        let td_semi_major_1_sigma_m = self.opt_f64()?;
        let td_semi_major_1_sigma_per_1000_m = self.opt_f64()?;
        let rms_station_azimuth_sigma_deg = self.opt_f64()?;
        let rms_station_inclination_sigma_deg = self.opt_f64()?;
        let azimuth_undetermined_stations = self.u64()? as usize;
        let n = self.len()?;
        let along_md = (0..n)
            .map(|_| Ok((self.f64()?, self.opt_f64()?, self.opt_f64()?)))
            .collect::<Result<_>>()?;
        Ok(CovariancePrediction {
            grade,
            well,
            lateral_length_m,
            td_horizontal_1_sigma_m,
            td_semi_major_1_sigma_m,
            td_semi_major_1_sigma_per_1000_m,
            rms_station_azimuth_sigma_deg,
            rms_station_inclination_sigma_deg,
            azimuth_undetermined_stations,
            along_md,
            method_td_error_m: self.opt_f64()?,
            td_method_1_sigma_m: self.opt_f64()?,
            td_without_method_1_sigma_m: self.opt_f64()?,
            td_note: self.opt_text()?,
            cpu_s: self.opt_f64()?,
            wall_s: self.f64()?,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::study::shard::{from_hex, to_hex};
    use mwd_core::protocol::frame::station_flags;

    fn station(number: u16) -> StationCheck {
        StationCheck {
            survey: StationSurvey {
                time_us: 123_456_789,
                station: number,
                flags: station_flags::AZIMUTH_UNDETERMINED,
                start_sample: 10,
                end_sample: 40,
                angles: [1.5, 0.1, 6.2],
                // an undetermined azimuth's sigma is infinite, an invalid
                // covariance's NaN: both must come back as they were
                angles_std: [0.001, f32::INFINITY, f32::NAN],
                correlations: [0.1, -0.2, 0.3],
                still_quality: 1.25,
            },
            error: [1e-300, -0.05, -0.0],
            truth_md: 3000.0 + f64::from(number),
            azimuth_sigma_before: Some(0.12),
            azimuth_error_before: None,
            link: Some(StationLink {
                station: number,
                previous: number - 1,
                covariance: [
                    [1.0, 2.0, 3.0],
                    [4.0, 5.0, 6.0],
                    [7.0, 8.0, f32::MIN_POSITIVE],
                ],
                cross_previous: Some([[0.5; 3]; 3]),
            }),
            position: Some(PositionCheck {
                error_ne: [0.1, 0.2],
                cov_ne: [1.0, 2.0, f64::NAN],
            }),
        }
    }

    #[test]
    fn outcomes_come_back_bit_for_bit() {
        let mut run = RunOutcome::of_stations(7, vec![station(1), station(2)]);
        run.td = Some(TdCheck {
            error_ne: [0.3, -0.4],
            d2: 1.0 / 3.0,
            cov_ne: [1.0, 2.0, 0.5],
            method_cov_ne: [0.1, 0.2, 0.05],
        });
        run.td_note = Some("a note, with \"quotes\" and ü".into());
        run.method_td_error_ne = Some([0.01, f64::NEG_INFINITY]);
        run.cpu_s = Some(0.1 + 0.2);
        let prediction = CovariancePrediction {
            grade: "scc1300".into(),
            well: "100m".into(),
            along_md: vec![(3000.0, Some(0.1), None)],
            td_note: Some("no TD".into()),
            ..CovariancePrediction::default()
        };
        for outcome in [
            JobOutcome::Run(Ok(run)),
            JobOutcome::Run(Err("seed 3: failed".into())),
            JobOutcome::Prediction(Ok(prediction)),
            JobOutcome::Prediction(Err("x".into())),
        ] {
            let bytes = encode(&outcome);
            let text = to_hex(&bytes);
            let back = decode(&from_hex(&text).expect("hex")).expect("decodes");
            assert_eq!(encode(&back), bytes);
            if let JobOutcome::Run(run) = &back {
                let alone = encode_run(run);
                let again = decode_run(&alone).expect("a run alone decodes");
                assert_eq!(encode_run(&again), alone);
                assert!(decode_run(&alone[..alone.len() - 1]).is_err());
            }
        }
    }

    #[test]
    fn corrupt_bytes_are_an_error_never_a_panic() {
        let bytes = encode(&JobOutcome::Run(Ok(RunOutcome::of_stations(
            1,
            vec![station(1)],
        ))));
        for cut in 0..bytes.len() {
            assert!(decode(&bytes[..cut]).is_err(), "cut at {cut}");
        }
        let mut longer = bytes.clone();
        longer.push(0);
        assert!(decode(&longer).is_err());
        let mut kind = bytes;
        kind[0] = 9;
        assert!(decode(&kind).is_err());
    }
}
