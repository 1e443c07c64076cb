//! The error models `host-sim survey` knows: the term tables embedded in
//! the tool (`host-sim/data/`) or read from a file, where each is valid
//! (an inclination limit, or the probe's gyrocompass rule), and the run of
//! a model over the positioned rows up to the first station it is not
//! valid at ([`crate::survey::iscwsa`]).

use super::positions::Row;
use crate::formats::text_records::excerpt;
use crate::survey::iscwsa::{self, ErrorTerm, Propagator, Site};
use anyhow::{anyhow, bail, Context, Result};

/// Where an error model may be applied.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Validity {
    /// Stated for inclinations up to this, deg (the OWSG gyro models'
    /// 89 deg: their weighting functions divide by cos I).
    MaxInclination(f64),
    /// This probe's gyrocompass (docs/probe-tool-model.md): every
    /// inclination, but only where (1) the azimuth sensitivity `S =
    /// sqrt(1 - sin^2 I sin^2 A)` is at least
    /// [`iscwsa::probe_weighting::MIN_AZIMUTH_SENSITIVITY`] (below
    /// it, a tool near horizontal heading near east or west, the azimuth is
    /// undetermined), and (2) the single-station first-order azimuth sigma
    /// from the model's own gyro terms (`PRB-GN`, `PRB-GXB`, `PRB-GZB`)
    /// is within [`iscwsa::probe_weighting::first_order_azimuth_limit`]
    /// (above it the first-order model understates the spread).
    AzimuthSensitivity,
}

/// The first station an error model is not valid at, and why.
#[derive(Clone, Debug, PartialEq)]
pub struct Invalid {
    pub station: usize,
    /// A clause after the model's name, e.g. "is stated for inclinations
    /// up to 89 deg".
    pub reason: String,
}

/// The gyro error magnitudes of a term table's `PRB-*` terms (rad/s,
/// root-sum-square over terms of the same weighting function).
fn probe_gyro_errors(terms: &[ErrorTerm]) -> iscwsa::probe_weighting::GyroErrors {
    let rss = |name: &str| {
        terms
            .iter()
            .filter(|t| t.weighting == name)
            .map(|t| t.magnitude_si * t.magnitude_si)
            .sum::<f64>()
            .sqrt()
    };
    iscwsa::probe_weighting::GyroErrors {
        noise: rss("PRB-GN"),
        bias_x: rss("PRB-GXB"),
        bias_z: rss("PRB-GZB"),
    }
}

impl Validity {
    /// Why the model (of these terms, at this site) is not valid at this
    /// row, or `None`.
    pub fn check(&self, row: &Row, terms: &[ErrorTerm], site: &Site) -> Option<String> {
        match *self {
            Self::MaxInclination(max) => {
                (row.inc_deg > max).then(|| format!("is stated for inclinations up to {max} deg"))
            }
            Self::AzimuthSensitivity => {
                use iscwsa::probe_weighting as pw;
                let (inc, azi) = (row.inc_deg.to_radians(), row.azi_deg.to_radians());
                let s = pw::azimuth_sensitivity(inc.sin(), azi.sin());
                if !pw::azimuth_determined(inc, azi) {
                    return Some(format!(
                        "cannot gyrocompass the azimuth at inclination {:.2} deg, azimuth {:.2} deg \
                         (azimuth sensitivity S = sqrt(1 - sin^2 I sin^2 A) = {s:.3} < {}: a tool near \
                         horizontal heading near east or west; azimuth undetermined)",
                        row.inc_deg,
                        row.azi_deg,
                        pw::MIN_AZIMUTH_SENSITIVITY
                    ));
                }
                let sigma = pw::single_station_azimuth_sigma(
                    inc,
                    azi,
                    row.input.toolface_deg.map(f64::to_radians),
                    site.latitude,
                    site.gyro_noise_reduction,
                    &probe_gyro_errors(terms),
                )?;
                let limit = pw::first_order_azimuth_limit(inc, azi);
                // NaN (a NaN magnitude) fails the test too: not valid
                (sigma.is_nan() || sigma > limit).then(|| {
                    format!(
                        "leaves the azimuth undetermined at inclination {:.2} deg, azimuth {:.2} deg \
                         (first-order model not valid: single-station azimuth sigma {:.1} deg > {:.2} deg, \
                         the limit there; at {:.1} deg latitude, from the model's gyro terms)",
                        row.inc_deg,
                        row.azi_deg,
                        sigma.to_degrees(),
                        limit.to_degrees(),
                        site.latitude.to_degrees()
                    )
                })
            }
        }
    }
}

/// An error model the tool knows: its term table (embedded) and where it
/// is valid.
#[derive(Clone, Copy, Debug)]
pub struct KnownModel {
    pub name: &'static str,
    pub table: &'static str,
    pub file: &'static str,
    pub validity: Validity,
    /// Needs the magnetic field (B total, dip, declination).
    pub magnetic: bool,
}

/// The embedded models (`host-sim/data/README.md`).
pub const MODELS: [KnownModel; 4] = [
    KnownModel {
        name: "ISCWSA MWD Rev5",
        table: include_str!("../../../data/mwd_rev5_model_terms.csv"),
        file: "mwd_rev5_model_terms.csv",
        validity: Validity::MaxInclination(180.0),
        magnetic: true,
    },
    KnownModel {
        name: "GYRO-MWD",
        table: include_str!("../../../data/owsg_gyro_mwd_terms.csv"),
        file: "owsg_gyro_mwd_terms.csv",
        validity: Validity::MaxInclination(89.0),
        magnetic: false,
    },
    KnownModel {
        name: "GYRO-NS",
        table: include_str!("../../../data/owsg_gyro_ns_terms.csv"),
        file: "owsg_gyro_ns_terms.csv",
        validity: Validity::MaxInclination(89.0),
        magnetic: false,
    },
    // this probe (docs/probe-tool-model.md): through 90 deg, but only
    // where one station's first-order azimuth sigma is within the limit
    // (never for the SCC1300 at 120 s stations)
    KnownModel {
        name: "PROBE-SCC1300",
        table: include_str!("../../../data/probe_scc1300_terms.csv"),
        file: "probe_scc1300_terms.csv",
        validity: Validity::AzimuthSensitivity,
        magnetic: false,
    },
];

/// The model of that name (case and spacing of the name ignored).
pub fn model(name: &str) -> Result<&'static KnownModel> {
    let key = |s: &str| {
        s.split_whitespace()
            .collect::<Vec<_>>()
            .join(" ")
            .to_ascii_uppercase()
    };
    MODELS
        .iter()
        .find(|m| key(m.name) == key(name))
        .ok_or_else(|| {
            let names: Vec<&str> = MODELS.iter().map(|m| m.name).collect();
            anyhow!(
                "unknown error model `{}` (known: {})",
                excerpt(name),
                names.join(", ")
            )
        })
}

/// The model's terms, parsed from the embedded table.
pub fn terms(model: &KnownModel) -> Result<Vec<ErrorTerm>> {
    iscwsa::parse_term_table(model.table, model.file).map_err(|e| anyhow!("{e}"))
}

/// Where a term table read from a file is valid, from its weighting
/// functions: the probe's rule ([`Validity::AzimuthSensitivity`]) if it
/// has the probe's gyro terms (`PRB-G*`), the OWSG gyro models' 89 deg if
/// it has XY gyrocompass terms (`GXY-*`, which divide by cos I), else no
/// limit.
pub fn file_validity(terms: &[ErrorTerm]) -> Validity {
    if terms.iter().any(|t| t.weighting.starts_with("PRB-G")) {
        Validity::AzimuthSensitivity
    } else if terms.iter().any(|t| t.weighting.starts_with("GXY-")) {
        Validity::MaxInclination(89.0)
    } else {
        Validity::MaxInclination(180.0)
    }
}

/// Reads an error model from a term table file (the CSV format of
/// `host-sim/data/`): its terms must parse, with finite magnitudes, and
/// every weighting function must be one the engine implements (checked on
/// a two-station survey). Its name is the file's path; it needs the
/// magnetic field if it has a weighting function that only the ISCWSA MWD
/// model uses. The model lives as long as the process (it is read once per
/// run, and the outputs refer to it as to the embedded ones).
pub fn model_from_file(path: &std::path::Path) -> Result<&'static KnownModel> {
    let name = path.display().to_string();
    let text = std::fs::read_to_string(path).with_context(|| format!("error model file {name}"))?;
    let terms = iscwsa::parse_term_table(&text, &name)
        .map_err(|e| anyhow!("error model file {name}: {e}"))?;
    if let Some(t) = terms.iter().find(|t| !t.magnitude_si.is_finite()) {
        bail!(
            "error model file {name}: term {} has magnitude {}, not a finite number",
            excerpt(&t.code),
            t.magnitude
        );
    }
    let probe = [
        iscwsa::Station {
            md: 0.0,
            inc: 0.5,
            azi: 0.5,
            tvd: 0.0,
            toolface: None,
        },
        iscwsa::Station {
            md: 30.0,
            inc: 0.5,
            azi: 0.5,
            tvd: 26.0,
            toolface: None,
        },
    ];
    let site = Site {
        gravity: 9.806_65,
        b_total: 50_000.0,
        dip: 1.2,
        declination: 0.0,
        vertical_limit: 1e-4_f64.to_radians(),
        latitude: 0.8,
        gyro_noise_reduction: 1.0,
    };
    let missing = iscwsa::run(&terms, &probe, &site).missing;
    if !missing.is_empty() {
        // `missing` names the terms; the file's reader wants the functions
        let which: Vec<String> = terms
            .iter()
            .filter(|t| missing.contains(&t.code))
            .map(|t| format!("{} (term {})", t.weighting, t.code))
            .collect();
        bail!(
            "error model file {name}: weighting functions not implemented: {}",
            excerpt(&which.join(", "))
        );
    }
    // weighting functions of the magnetic model that no gyro model uses
    let mut magnetic_only = std::collections::BTreeSet::new();
    for m in MODELS.iter().filter(|m| m.magnetic) {
        magnetic_only.extend(self::terms(m)?.into_iter().map(|t| t.weighting));
    }
    for m in MODELS.iter().filter(|m| !m.magnetic) {
        for t in self::terms(m)? {
            magnetic_only.remove(&t.weighting);
        }
    }
    let magnetic = terms.iter().any(|t| magnetic_only.contains(&t.weighting));
    let file: &'static str = Box::leak(name.clone().into_boxed_str());
    Ok(Box::leak(Box::new(KnownModel {
        name: file,
        table: Box::leak(text.into_boxed_str()),
        file,
        validity: file_validity(&terms),
        magnetic,
    })))
}

/// Runs the model over the rows (first = tie-on, taken as exact). From
/// the first station where the model is not valid on (an inclination
/// beyond its limit, an azimuth the probe cannot gyrocompass, or one whose
/// single-station first-order sigma is beyond the first-order limit) no station
/// gets a covariance: the model is not extrapolated, and a position error
/// without a bound at one station carries on to every later one. Returns
/// that first station and the reason, if any. The station's toolface, when
/// the file gives it, goes to the weighting functions that use it.
pub fn apply_model(
    rows: &mut [Row],
    model: &KnownModel,
    terms: &[ErrorTerm],
    site: &Site,
) -> Result<Option<Invalid>> {
    let stations: Vec<iscwsa::Station> = rows.iter().map(Row::iscwsa_station).collect();
    if !stations.is_empty() {
        iscwsa::check_stations(&stations).map_err(|e| anyhow!("{e}"))?;
    }
    let mut run = ModelRun::new(model, terms, *site);
    let mut done = Vec::with_capacity(rows.len());
    for r in rows.iter() {
        done.extend(run.push(*r)?);
    }
    done.extend(run.finish()?);
    rows.copy_from_slice(&done);
    Ok(run.invalid.map(|(invalid, _)| invalid))
}

/// A model run over rows one at a time: the stations before the first
/// where the model is not valid get covariances (the last of them as the
/// survey's last station), the rest none. [`apply_model`] runs it over a
/// survey in memory; `survey::streamed` over a file as it is read, holding
/// one row and the sources' sums ([`iscwsa::Propagator`]).
pub struct ModelRun<'t> {
    model: &'t KnownModel,
    terms: &'t [ErrorTerm],
    site: Site,
    propagator: Option<Propagator<'t>>,
    /// The row waiting for its covariance.
    pending: Option<Row>,
    /// Where the model stopped being valid, and that station's MD (m).
    pub invalid: Option<(Invalid, f64)>,
    /// Index of the next row.
    index: usize,
}

impl<'t> ModelRun<'t> {
    pub fn new(model: &'t KnownModel, terms: &'t [ErrorTerm], site: Site) -> Self {
        Self {
            model,
            terms,
            site,
            propagator: None,
            pending: None,
            invalid: None,
            index: 0,
        }
    }

    /// Takes the next row; returns the rows now complete, in order.
    pub fn push(&mut self, r: Row) -> Result<Vec<Row>> {
        let k = self.index;
        self.index += 1;
        if self.invalid.is_some() {
            return Ok(vec![r]);
        }
        if let Some(reason) = self.model.validity.check(&r, self.terms, &self.site) {
            self.invalid = Some((Invalid { station: k, reason }, r.md_m));
            let mut done = self.finish()?;
            done.push(r);
            return Ok(done);
        }
        let station = r.iscwsa_station();
        let cov = match self.propagator.as_mut() {
            Some(p) => p.push(station),
            None => {
                let p = Propagator::new(self.terms, station, &self.site, iscwsa::Options::REV5_10);
                if !p.missing().is_empty() {
                    bail!(
                        "error model {}: weighting functions not implemented for {}",
                        self.model.name,
                        p.missing().join(", ")
                    );
                }
                self.propagator = Some(p);
                None
            }
        };
        let done = self.pending.replace(r).map(|p| self.with(p, cov, k - 1));
        done.into_iter().collect()
    }

    /// The row still waiting, with its covariance as the last station's.
    pub fn finish(&mut self) -> Result<Vec<Row>> {
        let cov = self.propagator.as_mut().and_then(Propagator::finish);
        let k = self.index.saturating_sub(1);
        self.pending
            .take()
            .map(|p| self.with(p, cov, k))
            .into_iter()
            .collect()
    }

    /// Row `k` with its covariance (`None`: the survey's first station,
    /// which carries no error of its own).
    fn with(&self, mut r: Row, cov: Option<iscwsa::Cov6>, k: usize) -> Result<Row> {
        let cov = cov.unwrap_or([0.0; 6]);
        if !cov.iter().all(|x| x.is_finite()) {
            bail!(
                "error model {}: non-finite covariance at station {k} (MD {} m)",
                self.model.name,
                r.md_m
            );
        }
        r.cov = Some(cov);
        Ok(r)
    }
}

#[cfg(test)]
mod tests {
    use super::super::positions::{compute, AzimuthReference, TieOnInput};
    use super::*;
    use crate::formats::station_csv::{read_stations, StationFile};

    fn file(text: &str) -> StationFile {
        read_stations(text.as_bytes()).unwrap()
    }

    #[test]
    fn embedded_tables_parse() {
        // every model's every term has its weighting function: a short
        // survey at 45 deg runs with nothing missing and a finite result
        let f = file("md_m,inc_deg,azi_deg\n0,0,0\n300,45,30\n600,45,30\n");
        let tie = TieOnInput {
            md: None,
            tvd: 0.0,
            north: 0.0,
            east: 0.0,
            covariance: None,
        };
        let site = Site {
            gravity: 9.80665,
            b_total: 50_000.0,
            dip: 72f64.to_radians(),
            declination: 0.0,
            vertical_limit: 1e-4f64.to_radians(),
            latitude: 45f64.to_radians(),
            gyro_noise_reduction: 1.0,
        };
        for m in &MODELS {
            let mut terms = terms(m).unwrap();
            assert!(terms.len() >= 17, "{}", m.name);
            let (mut rows, _) = compute(&f, AzimuthReference::True, tie, None).unwrap();
            if m.validity == Validity::AzimuthSensitivity {
                // the SCC1300 at a 120 s station: beyond the first-order
                // limit from the tie-on on (docs/probe-tool-model.md)
                let inv = apply_model(&mut rows, m, &terms, &site).unwrap().unwrap();
                assert_eq!(inv.station, 0);
                assert!(inv.reason.contains("first-order model not valid"));
                assert!(rows.iter().all(|r| r.cov.is_none()));
                // a gyro 100 times better passes
                for t in terms
                    .iter_mut()
                    .filter(|t| t.weighting.starts_with("PRB-G"))
                {
                    t.magnitude_si *= 0.01;
                }
            }
            assert_eq!(apply_model(&mut rows, m, &terms, &site).unwrap(), None);
            let last = rows.last().unwrap().cov.unwrap();
            assert!(
                last.iter().all(|x| x.is_finite()) && last[0] > 0.0,
                "{}",
                m.name
            );
        }
        assert_eq!(model("probe-scc1300").unwrap().name, "PROBE-SCC1300");
        assert_eq!(model("iscwsa  mwd rev5").unwrap().name, "ISCWSA MWD Rev5");
        assert!(model("ISCWSA MWD Rev4").is_err());
    }
}
