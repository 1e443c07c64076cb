//! The industry's generic gyro survey tool models, OWSG GYRO-MWD and
//! GYRO-NS (SPE 90408 Tables 1 and 4, as transcribed in
//! `host-sim/data/owsg_gyro_*_terms.csv`), run by the ISCWSA engine
//! ([`crate::survey::iscwsa`]) on a study well, so that the lateral study
//! shows its figures side by side with the industry's models.
//!
//! Stations are those a drilling run surveys ([`study_stations`]): the
//! plan's tie-on, one per stand from it (the drilling simulator's
//! connections, `sim::drilling`) and TD, each with the plan's inclination
//! and azimuth there.
//!
//! Validity: both models' metadata (`owsg_gyro_*_metadata.json`) state
//! "Inclination Range Max 89 deg" and "Tool model fails at 90 deg
//! inclination": the XY-gyro terms GXY-B1, GXY-G4 and GXY-RN divide by
//! cos I. The engine does not refuse such stations: at exactly 90 deg
//! `cos` of the nearest double to pi/2 is 6.1e-17, so the weights are
//! ~1e16 times too large but finite (azimuth sigmas of ~1e17 deg), and
//! beyond 90 deg cos I changes sign and the numbers come back to a
//! plausible-looking size that means nothing. A prediction is therefore
//! valid only if every station lies in the stated range; otherwise it
//! carries `valid: false`, the reason, and no figures at all
//! ([`OwsgPrediction::figures`] is `None`), so no table can print one.
//!
//! A "capped" reference (the same stations with the inclination held at
//! the model's 89 deg limit) is computed but only given where the model's
//! own gyro terms leave a station's azimuth within the range a first-order
//! error model means anything (single-station azimuth 1-sigma at most
//! [`probe_weighting::MAX_FIRST_ORDER_AZIMUTH_SIGMA_DEG`], the project's
//! criterion from its Monte Carlo). At 89 deg the GXY-G4 term alone
//! (g-dependent error x tan I / Omega_h, 1 deg/h in GYRO-MWD) gives
//! hundreds of degrees: the reference is then withheld with that figure as
//! the note, never printed as a prediction.

use crate::sim::BuiltPlan;
use crate::survey::iscwsa::probe_weighting::MAX_FIRST_ORDER_AZIMUTH_SIGMA_DEG;
use crate::survey::iscwsa::{self, Cov6, ErrorTerm, Site, Station};
use crate::survey::listing::ellipse::{scale_2d, Ellipse};
use anyhow::{anyhow, bail, Context, Result};
use serde::Serialize;

/// Gravity and vertical limit of the study's [`Site`], as
/// `commands/study.rs` builds it for the drilling studies (no magnetic
/// field: the gyro models need none).
pub fn study_site(latitude: f64) -> Site {
    Site {
        gravity: 9.806_65,
        b_total: 0.0,
        dip: 0.0,
        declination: 0.0,
        vertical_limit: 0.0001_f64.to_radians(),
        latitude,
        gyro_noise_reduction: 1.0,
    }
}

/// The two OWSG gyro models.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OwsgModel {
    GyroMwd,
    GyroNs,
}

impl OwsgModel {
    pub const ALL: [Self; 2] = [Self::GyroMwd, Self::GyroNs];

    /// The name `survey_listing::model` knows it by.
    pub fn name(self) -> &'static str {
        match self {
            Self::GyroMwd => "GYRO-MWD",
            Self::GyroNs => "GYRO-NS",
        }
    }

    fn metadata(self) -> (&'static str, &'static str) {
        match self {
            Self::GyroMwd => (
                include_str!("../../data/owsg_gyro_mwd_metadata.json"),
                "owsg_gyro_mwd_metadata.json",
            ),
            Self::GyroNs => (
                include_str!("../../data/owsg_gyro_ns_metadata.json"),
                "owsg_gyro_ns_metadata.json",
            ),
        }
    }

    /// The embedded term table.
    pub fn terms(self) -> Result<Vec<ErrorTerm>> {
        crate::survey::listing::terms(crate::survey::listing::model(self.name())?)
    }

    /// The stated inclination range, read from the metadata file.
    pub fn range(self) -> Result<InclinationRange> {
        let (text, file) = self.metadata();
        InclinationRange::parse(text, file)
    }
}

/// Where a tool model is stated to hold.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct InclinationRange {
    pub min_deg: f64,
    pub max_deg: f64,
    /// The metadata's "Range Comment".
    pub comment: String,
}

impl InclinationRange {
    fn parse(text: &str, file: &str) -> Result<Self> {
        let meta: serde_json::Value =
            serde_json::from_str(text).with_context(|| format!("{file}: not JSON"))?;
        let deg = |key: &str| -> Result<f64> {
            let s = meta
                .get(key)
                .and_then(|v| v.as_str())
                .ok_or_else(|| anyhow!("{file}: no {key:?}"))?;
            let v = s
                .trim()
                .strip_suffix("deg")
                .ok_or_else(|| anyhow!("{file}: {key} {s:?} is not in deg"))?;
            v.trim()
                .parse::<f64>()
                .with_context(|| format!("{file}: {key} {s:?}"))
        };
        let range = Self {
            min_deg: deg("Inclination Range Min")?,
            max_deg: deg("Inclination Range Max")?,
            comment: meta
                .get("Range Comment")
                .and_then(|v| v.as_str())
                .unwrap_or("")
                .trim()
                .to_string(),
        };
        if !(range.min_deg >= 0.0 && range.min_deg < range.max_deg && range.max_deg <= 180.0) {
            bail!(
                "{file}: inclination range {}-{} deg is not a range",
                range.min_deg,
                range.max_deg
            );
        }
        Ok(range)
    }

    /// Inside the range, with 1e-9 deg of rounding (a plan's 89 deg comes
    /// back through radians as 89.00000000000001).
    fn holds(&self, inc_deg: f64) -> bool {
        inc_deg >= self.min_deg - 1e-9 && inc_deg <= self.max_deg + 1e-9
    }
}

/// The survey stations of a drilling run on `plan`: the tie-on, one every
/// `stand_length_m` of MD from it (the connections) and TD (not repeated
/// when the last stand ends there), with the plan's direction and TVD.
pub fn study_stations(plan: &BuiltPlan) -> Vec<Station> {
    let (start, end) = (plan.start_md(), plan.end_md());
    let stand = plan.drilling.stand_length_m;
    let mut mds = vec![start];
    // the drilling simulator's rule (sim::drilling): stands from the
    // tie-on, the last one shortened to end at TD
    let mut md = start;
    while end - md > 1e-9 {
        md = (md + stand).min(end);
        mds.push(md);
    }
    mds.into_iter()
        .map(|md| {
            let p = plan.at(md);
            Station {
                md,
                inc: p.inclination,
                azi: p.azimuth,
                tvd: p.nev.z,
                toolface: None,
            }
        })
        .collect()
}

/// The model's horizontal figures at one station.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct AlongMd {
    pub md_m: f64,
    /// sqrt(nn + ee), m.
    pub horizontal_sigma_m: f64,
    /// 1-sigma semi-major of the horizontal ellipse, m.
    pub semi_major_m: f64,
}

/// A model's prediction on stations where it holds.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Figures {
    /// MD from the tie-on to TD, m.
    pub lateral_m: f64,
    /// At TD: sqrt(trace of the NE covariance), m.
    pub td_horizontal_sigma_m: f64,
    /// At TD: the horizontal ellipse's 1-sigma semi-major, m.
    pub semi_major_1sigma_m: f64,
    /// The 95 % semi-major (1-sigma x sqrt(-2 ln 0.05) = 2.448), m.
    pub semi_major_95_m: f64,
    /// The same per 1000 m of lateral, m.
    pub semi_major_1sigma_per_1000m_m: f64,
    pub semi_major_95_per_1000m_m: f64,
    /// Share of the TD horizontal variance (nn + ee) from the XY-gyro
    /// terms (GXY-*, the gyrocompass's azimuth errors), 0..1.
    pub gyro_share: f64,
    /// Largest single-station azimuth 1-sigma from the gyro terms, deg.
    pub max_station_azimuth_sigma_deg: f64,
    pub along_md: Vec<AlongMd>,
}

/// The model on the stations with the inclination capped at its limit.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Reference {
    pub capped_at_deg: f64,
    pub figures: Figures,
}

/// One model's prediction on a well.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct OwsgPrediction {
    pub model: &'static str,
    pub range: InclinationRange,
    pub valid: bool,
    /// Why not valid (`None` when valid).
    pub reason: Option<String>,
    /// `Some` only when valid.
    pub figures: Option<Figures>,
    /// Clearly a reference, not a prediction for this well: the stations
    /// with the inclination capped at the model's limit, given only where
    /// the capped well needed it and the model's first-order azimuth
    /// errors stay meaningful there.
    pub reference: Option<Reference>,
    /// Why no reference is given, when the well needed one.
    pub reference_note: Option<String>,
}

impl OwsgPrediction {
    /// One cell of a table: the 1-sigma and 95 % semi-major per 1000 m,
    /// or "not valid (reason)".
    pub fn cell(&self) -> String {
        match (&self.figures, &self.reason) {
            (Some(f), _) => format!(
                "{:.2} m 1-sigma, {:.2} m 95 % per 1000 m",
                f.semi_major_1sigma_per_1000m_m, f.semi_major_95_per_1000m_m
            ),
            (None, Some(r)) => format!("not valid ({r})"),
            (None, None) => "not valid".to_string(),
        }
    }
}

/// Both models' predictions on `plan`.
pub fn predict_all(plan: &BuiltPlan, site: &Site) -> Result<Vec<OwsgPrediction>> {
    OwsgModel::ALL
        .iter()
        .map(|&m| predict(m, plan, site))
        .collect()
}

/// `model` on the study stations of `plan` (see the module's notes).
pub fn predict(model: OwsgModel, plan: &BuiltPlan, site: &Site) -> Result<OwsgPrediction> {
    predict_on(model, &study_stations(plan), site)
}

/// `model` on given stations (the first the tie-on).
pub fn predict_on(model: OwsgModel, stations: &[Station], site: &Site) -> Result<OwsgPrediction> {
    let terms = model.terms()?;
    let range = model.range()?;
    iscwsa::check_stations(stations).map_err(|e| anyhow!("{}: {e}", model.name()))?;
    ensure_two(stations, model)?;
    let outside: Vec<f64> = stations
        .iter()
        .map(|s| s.inc.to_degrees())
        .filter(|&d| !range.holds(d))
        .collect();
    if outside.is_empty() {
        let figures = figures(&terms, stations, site)?;
        return Ok(OwsgPrediction {
            model: model.name(),
            range,
            valid: true,
            reason: None,
            figures: Some(figures),
            reference: None,
            reference_note: None,
        });
    }
    let (lo, hi) = min_max(outside.iter().copied());
    let (well_lo, well_hi) = min_max(stations.iter().map(|s| s.inc.to_degrees()));
    let well = if outside.len() == stations.len() {
        String::new()
    } else {
        format!(" (the well {well_lo:.1}-{well_hi:.1} deg)")
    };
    let reason = format!(
        "{} of {} stations at inclination {lo:.1}-{hi:.1} deg{well}, model range {}-{} deg: \"{}\"",
        outside.len(),
        stations.len(),
        range.min_deg,
        range.max_deg,
        range.comment
    );
    let capped: Vec<Station> = stations
        .iter()
        .map(|s| Station {
            inc: s
                .inc
                .clamp(range.min_deg.to_radians(), range.max_deg.to_radians()),
            ..*s
        })
        .collect();
    let limit = MAX_FIRST_ORDER_AZIMUTH_SIGMA_DEG;
    let (reference, reference_note) = match figures(&terms, &capped, site) {
        Ok(f) if f.max_station_azimuth_sigma_deg <= limit => (
            Some(Reference {
                capped_at_deg: range.max_deg,
                figures: f,
            }),
            None,
        ),
        Ok(f) => (
            None,
            Some(format!(
                "no reference at the {} deg limit either: the model's gyro terms give a \
                 single-station azimuth 1-sigma of up to {:.0} deg there (a first-order error \
                 model means nothing above ~{limit} deg)",
                range.max_deg, f.max_station_azimuth_sigma_deg
            )),
        ),
        Err(e) => (
            None,
            Some(format!(
                "no reference at the {} deg limit: {e:#}",
                range.max_deg
            )),
        ),
    };
    Ok(OwsgPrediction {
        model: model.name(),
        range,
        valid: false,
        reason: Some(reason),
        figures: None,
        reference,
        reference_note,
    })
}

fn ensure_two(stations: &[Station], model: OwsgModel) -> Result<()> {
    if stations.len() < 2 {
        bail!(
            "{}: a well needs a tie-on and at least one station",
            model.name()
        );
    }
    Ok(())
}

fn min_max(v: impl Iterator<Item = f64>) -> (f64, f64) {
    v.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
        (a.min(x), b.max(x))
    })
}

fn is_gyro(t: &ErrorTerm) -> bool {
    t.weighting.starts_with("GXY-")
}

/// The engine's figures on `stations` (at least two).
fn figures(terms: &[ErrorTerm], stations: &[Station], site: &Site) -> Result<Figures> {
    let result = iscwsa::run(terms, stations, site);
    if !result.missing.is_empty() {
        bail!(
            "the engine does not implement the weighting of {}",
            result.missing.join(", ")
        );
    }
    let trace = |c: &Cov6| c[0] + c[1];
    let along_md: Vec<AlongMd> = stations
        .iter()
        .zip(&result.total)
        .map(|(s, c)| AlongMd {
            md_m: s.md,
            horizontal_sigma_m: trace(c).max(0.0).sqrt(),
            semi_major_m: Ellipse::from_cov(c).semi_major,
        })
        .collect();
    let last = result.total.len() - 1;
    let td = &result.total[last];
    let gyro: f64 = terms
        .iter()
        .filter(|t| is_gyro(t))
        .filter_map(|t| result.per_source.get(&t.code))
        .map(|covs| trace(&covs[last]))
        .sum();
    let lateral_m = stations[last].md - stations[0].md;
    let major = Ellipse::from_cov(td).semi_major;
    let k95 = scale_2d(0.95);
    let per_1000 = 1000.0 / lateral_m;
    let max_azi = stations[1..]
        .iter()
        .map(|s| station_azimuth_sigma(terms, s, site))
        .fold(0.0, f64::max);
    let f = Figures {
        lateral_m,
        td_horizontal_sigma_m: trace(td).max(0.0).sqrt(),
        semi_major_1sigma_m: major,
        semi_major_95_m: k95 * major,
        semi_major_1sigma_per_1000m_m: major * per_1000,
        semi_major_95_per_1000m_m: k95 * major * per_1000,
        gyro_share: if trace(td) > 0.0 {
            gyro / trace(td)
        } else {
            0.0
        },
        max_station_azimuth_sigma_deg: max_azi.to_degrees(),
        along_md,
    };
    if !(f.td_horizontal_sigma_m.is_finite() && f.max_station_azimuth_sigma_deg.is_finite()) {
        bail!("the engine gave no finite covariance at TD");
    }
    Ok(f)
}

/// The azimuth 1-sigma (rad) the model's gyro terms give one station at
/// `s`'s direction, from the engine itself: its GXY-* terms run on a
/// one-leg survey of length 1 m in that direction, where an azimuth error
/// dA moves the station across the hole by L sin(I) dA (the Rev 5 tie-on
/// convention gives the station the whole leg: `h_last` = L). NaN at a
/// vertical station (no azimuth).
fn station_azimuth_sigma(terms: &[ErrorTerm], s: &Station, site: &Site) -> f64 {
    let gyro: Vec<ErrorTerm> = terms.iter().filter(|t| is_gyro(t)).cloned().collect();
    let leg = [
        Station {
            md: 0.0,
            tvd: 0.0,
            ..*s
        },
        Station {
            md: 1.0,
            tvd: s.inc.cos(),
            ..*s
        },
    ];
    let r = iscwsa::run(&gyro, &leg, site);
    let c = r.total[1];
    let (sa, ca) = s.azi.sin_cos();
    // variance along the across-hole horizontal unit vector (-sin A, cos A)
    let across = sa * sa * c[0] + ca * ca * c[1] - 2.0 * sa * ca * c[3];
    let si = s.inc.sin();
    if si < 1e-6 {
        return f64::NAN;
    }
    across.max(0.0).sqrt() / si
}

#[cfg(test)]
mod tests;
