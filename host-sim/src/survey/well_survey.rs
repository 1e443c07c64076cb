//! A station file's survey as `host-sim survey` makes it: the stations
//! positioned by minimum curvature ([`listing::compute`]), given their
//! NEV covariance by an error model ([`listing::apply_model`]), and, with
//! an offset well, each station's separation from it (the ISCWSA
//! separation rule, Sawaryn et al. 2019, SPE-187073-PA). What the outputs
//! ([`crate::survey::outputs`]) need besides the rows is kept here too.
//!
//! The site an error model runs at comes from the caller, once the model
//! is known: a magnetic model needs the field, which the command line
//! gives (and refuses to go without).

use crate::survey::iscwsa::{Cov6, Site};
use crate::survey::job::WellNames;
use crate::survey::listing::separation as sep;
use crate::survey::listing::{
    self as listing, AzimuthReference, Invalid, KnownModel, LengthUnit, Row, StationFile,
    StationReading, TieOnInput,
};
use crate::survey::station_qc::StationQc;
use anyhow::{bail, Context, Result};
use std::path::Path;

/// The site a model runs at, given the model (see the module's doc).
pub type SiteFor<'a> = &'a dyn Fn(&KnownModel) -> Result<Site>;

/// Reads a station file (CSV), its path in the errors, as `reading` says
/// (an MD column without a unit, azimuths to wrap).
pub fn read_station_file(path: &Path, reading: StationReading) -> Result<StationFile> {
    let input = std::fs::File::open(path).with_context(|| format!("{}", path.display()))?;
    crate::formats::station_csv::read_stations_in(input, reading)
        .with_context(|| format!("{}", path.display()))
}

/// Which error model gives the stations their covariance.
#[derive(Clone, Copy, Debug)]
pub enum ModelChoice<'a> {
    /// None: positions only.
    None,
    /// A model the tool knows, by name ([`listing::model`]).
    Named(&'a str),
    /// A term table read from a file ([`listing::model_from_file`]).
    File(&'a Path),
}

/// How the reference well's stations are positioned.
#[derive(Clone, Copy, Debug)]
pub struct SurveyInputs<'a> {
    /// North reference of the file's azimuths.
    pub reference: AzimuthReference,
    /// The tie-on, in the file's unit.
    pub tie: TieOnInput,
    /// Vertical-section azimuth, rad (`None`: closure of the last station).
    pub vsec_azimuth: Option<f64>,
    pub model: ModelChoice<'a>,
    /// Probability held by the scaled horizontal ellipse (2-D normal).
    pub confidence: f64,
}

/// The offset well's inputs besides the separation rule's radii and
/// margins.
#[derive(Clone, Copy, Debug)]
pub struct OffsetInputs<'a> {
    /// The offset well's station file (same format and length unit).
    pub path: &'a Path,
    /// North reference of its azimuths (the reference well's).
    pub reference: AzimuthReference,
    /// Its tie-on, in the file's unit.
    pub tie: TieOnInput,
    /// Its error model by name; `None`: the reference well's.
    pub model_name: Option<&'a str>,
    /// How its file is read (`--units`, `--wrap-azimuth`).
    pub reading: StationReading,
    pub rule: sep::Rule,
}

/// The offset well's separation from the reference stations.
pub struct Offset {
    pub name: String,
    pub model: Option<&'static KnownModel>,
    pub rule: sep::Rule,
    pub seps: Vec<sep::Separation>,
    /// The offset's file name (figures' legend) and its rows.
    pub short_name: String,
    pub rows: Vec<Row>,
}

/// A survey: its rows and what the outputs need besides them.
pub struct WellSurvey {
    pub rows: Vec<Row>,
    pub vsec_azimuth_deg: f64,
    pub model: Option<&'static KnownModel>,
    /// First station the model is not valid at.
    pub invalid_from: Option<Invalid>,
    pub confidence: f64,
    /// Length unit of the station file (the figures use it).
    pub unit: LengthUnit,
    pub offset: Option<Offset>,
    /// The bit projected from the last station, where the survey has one
    /// (a capture survey with the sensor-to-bit distance).
    pub bit: Option<Row>,
    /// What a reader must know before the positions: how the stations
    /// are placed, what they are not (a capture survey without a
    /// tie-on); the listing, the JSON and the figures carry it.
    pub header_note: Option<String>,
    /// The well's and wellbore's names and uids (the WITSML trajectory
    /// carries them): the job's, else placeholders.
    pub well: WellNames,
    /// The tie-on's position covariance (m^2) in every station's; `None`:
    /// the tie-on is taken as exact.
    pub tie_on_cov_m2: Option<Cov6>,
    /// The length unit of the listing, CSV, JSON and WITSML (the rows are
    /// kept in metres; the writers convert): metres unless asked.
    pub output_unit: LengthUnit,
    /// Each row's quality checks, where the survey comes from a capture
    /// that had the stations' samples (else empty).
    pub station_qc: Vec<Option<StationQc>>,
    /// The probe ran without a calibration (a capture's survey,
    /// `DrillingSurvey::uncalibrated`): every output says so on top and
    /// flags every station.
    pub uncalibrated: bool,
    /// Each row's own flags besides "uncalibrated" (a capture's survey:
    /// `DrillingRow::flags`), where any (else empty).
    pub row_flags: Vec<Vec<&'static str>>,
}

impl WellSurvey {
    /// Row `k`'s flags: "uncalibrated" for a probe that ran without a
    /// calibration, then the row's own.
    pub fn station_flags(&self, k: usize) -> Vec<&'static str> {
        let mut flags = Vec::new();
        if self.uncalibrated {
            flags.push(listing::drilling::UNCALIBRATED_FLAG);
        }
        flags.extend(self.row_flags.get(k).into_iter().flatten());
        flags
    }

    /// The stations of `file` positioned and, with a model, given their
    /// covariance at the site `site_for` gives for it.
    pub fn compute(file: &StationFile, inputs: &SurveyInputs, site_for: SiteFor) -> Result<Self> {
        let (mut rows, direction) =
            listing::compute(file, inputs.reference, inputs.tie, inputs.vsec_azimuth)?;
        let model = match inputs.model {
            ModelChoice::File(path) => Some(listing::model_from_file(path)?),
            ModelChoice::Named(name) => Some(listing::model(name)?),
            ModelChoice::None => None,
        };
        let mut invalid_from = None;
        let tie_on_cov_m2 = inputs.tie.covariance_m2(file.unit);
        if let Some(m) = model {
            let terms = listing::terms(m)?;
            let site = site_for(m)?;
            invalid_from = listing::apply_model(&mut rows, m, &terms, &site)?;
            for row in rows.iter_mut() {
                row.cov = row
                    .cov
                    .map(|c| listing::plus_tie_on(c, tie_on_cov_m2.as_ref()));
            }
        }
        Ok(Self {
            rows,
            vsec_azimuth_deg: direction.to_degrees(),
            model,
            invalid_from,
            confidence: inputs.confidence,
            unit: file.unit,
            offset: None,
            bit: None,
            header_note: None,
            well: WellNames::default(),
            tie_on_cov_m2,
            output_unit: LengthUnit::Metre,
            station_qc: Vec::new(),
            uncalibrated: false,
            row_flags: Vec::new(),
        })
    }

    /// The offset well positioned and given its covariance, and its
    /// separation from every station of this survey.
    pub fn add_offset(&mut self, inputs: &OffsetInputs, site_for: SiteFor) -> Result<()> {
        let path = inputs.path;
        let file = read_station_file(path, inputs.reading).context("the offset well")?;
        if file.unit != self.unit {
            bail!(
                "{}: the offset well's length unit differs from the reference well's (give both in m or both in ft)",
                path.display()
            );
        }
        let (mut rows, _) = listing::compute(&file, inputs.reference, inputs.tie, None)
            .with_context(|| format!("offset well {}", path.display()))?;
        // default: the reference well's model (named or from a file)
        let model = match inputs.model_name {
            Some(name) => Some(listing::model(name)?),
            None => self.model,
        };
        if let Some(m) = model {
            let terms = listing::terms(m)?;
            listing::apply_model(&mut rows, m, &terms, &site_for(m)?)
                .with_context(|| format!("offset well {}", path.display()))?;
        }
        let seps = sep::separations(&self.rows, &rows, &inputs.rule)?;
        self.offset = Some(Offset {
            name: path.display().to_string(),
            model,
            rule: inputs.rule,
            seps,
            short_name: path
                .file_name()
                .map_or_else(|| "offset".into(), |n| n.to_string_lossy().into_owned()),
            rows,
        });
        Ok(())
    }

    /// Where the model stops being valid, as a sentence.
    pub fn validity_note(&self) -> Option<String> {
        let (m, inv) = (self.model?, self.invalid_from.as_ref()?);
        Some(validity_note(
            m,
            inv,
            self.rows[inv.station].md_m,
            self.output_unit,
        ))
    }

    /// The minimum SF and the violations, as lines of text.
    pub fn separation_summary(&self) -> Vec<String> {
        let Some(o) = &self.offset else {
            return Vec::new();
        };
        let u = self.output_unit;
        let (len, sym) = (|m: f64| u.from_m(m), u.symbol());
        let mut out = vec![format!(
            "offset {}: model {}; ISCWSA separation rule (Sawaryn et al. 2019, SPE-187073-PA): k {}, S_m {} m, sigma_pa {} m, hole radii {} m / {} m",
            o.name,
            o.model.map_or("none", |m| m.name),
            o.rule.k,
            o.rule.surface_margin_m,
            o.rule.sigma_pa_m,
            o.rule.ref_radius_m,
            o.rule.offset_radius_m
        )];
        match sep::minimum(&o.seps) {
            Some((i, f)) => out.push(format!(
                "minimum SF {:.3} at MD {:.2} {sym} (offset MD {:.2} {sym}, centre to centre {:.2} {sym} +- {:.2} {sym} 1-sigma)",
                f,
                len(self.rows[i].md_m),
                len(o.seps[i].closest.md_m),
                len(o.seps[i].ctc_m),
                // a minimum SF has its sigma (`sep::minimum`)
                o.seps[i].sigma_s_m.map_or(f64::NAN, len)
            )),
            None => {
                out.push("minimum SF undetermined: no station has both wells' covariance".into())
            }
        }
        let bad: Vec<usize> = (0..o.seps.len())
            .filter(|&i| sf_status(&o.seps[i]) == "violation")
            .collect();
        if let (Some(&a), Some(&b)) = (bad.first(), bad.last()) {
            out.push(format!(
                "VIOLATION of the separation rule (SF < 1) at {} stations, MD {:.2} to {:.2} {sym}",
                bad.len(),
                len(self.rows[a].md_m),
                len(self.rows[b].md_m)
            ));
        }
        let undetermined = o.seps.iter().filter(|x| x.sf.is_none()).count();
        if undetermined > 0 {
            out.push(format!(
                "SF undetermined at {undetermined} stations (a covariance missing: no model, or beyond its validity)"
            ));
        }
        out
    }
}

/// Where model `m` stops being valid (`invalid`, at MD `md_m`), as a
/// sentence in `unit`.
pub fn validity_note(m: &KnownModel, invalid: &Invalid, md_m: f64, unit: LengthUnit) -> String {
    format!(
        "{} {}: no uncertainty from MD {:.2} {} (station {}) on, not extrapolated",
        m.name,
        invalid.reason,
        unit.from_m(md_m),
        unit.symbol(),
        invalid.station
    )
}

/// A station's separation as one word: ok, violation (SF < 1) or
/// undetermined (no SF).
pub fn sf_status(x: &sep::Separation) -> &'static str {
    match x.sf {
        None => "undetermined",
        Some(f) if f < 1.0 => "violation",
        Some(_) => "ok",
    }
}
