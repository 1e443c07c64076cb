//! The outputs of a station file's survey ([`WellSurvey`]): the listing
//! on the terminal, one CSV row per station, the survey as JSON, a WITSML
//! 1.4.1.1 trajectory, and the plan and section figures. Lengths in
//! metres, azimuths along true north, whatever the input.

use crate::formats::files::OutputSet;
use crate::survey::listing::drilling::{UNCALIBRATED_FLAG, UNCALIBRATED_NOTE};
use crate::survey::listing::separation as sep;
use crate::survey::listing::{plot, tie_on_note};
use crate::survey::well_survey::{sf_status, WellSurvey};
use anyhow::Result;
use std::path::{Path, PathBuf};

mod table;
mod witsml;
pub use table::{csv_head, csv_row, csv_text, listing_head, listing_row, listing_text, Head};
pub use witsml::witsml_text;

/// Where the outputs go (each one only when given).
#[derive(Clone, Copy, Debug, Default)]
pub struct OutputPaths<'a> {
    pub csv: Option<&'a Path>,
    pub json: Option<&'a Path>,
    pub witsml: Option<&'a Path>,
    /// Directory of the figures (prepared beforehand:
    /// [`crate::formats::figure::prepare_dir`]).
    pub plot: Option<&'a Path>,
}

/// Writes the outputs asked for, in the order CSV, JSON, WITSML, figures;
/// `well` names the well in the figures. Returns the figures' files.
pub fn write_outputs(s: &WellSurvey, paths: &OutputPaths, well: &str) -> Result<Vec<PathBuf>> {
    let mut set = OutputSet::default();
    let figures = stage_outputs(&mut set, s, paths, well)?;
    set.commit()?;
    Ok(figures)
}

/// [`write_outputs`] as part of a command's set of outputs: the CSV, JSON
/// and WITSML staged in `set` (named when the set is committed), the
/// figures written; the figures' paths.
pub fn stage_outputs(
    set: &mut OutputSet,
    s: &WellSurvey,
    paths: &OutputPaths,
    well: &str,
) -> Result<Vec<PathBuf>> {
    if let Some(p) = paths.csv {
        set.stage(p, &csv_text(s))?;
    }
    if let Some(p) = paths.json {
        set.stage(p, &json_text(s)?)?;
    }
    if let Some(p) = paths.witsml {
        set.stage(p, &witsml_text(s))?;
    }
    let Some(dir) = paths.plot else {
        return Ok(Vec::new());
    };
    let figures = plot::SurveyPlot {
        rows: &s.rows,
        unit: s.unit,
        vsec_azimuth: s.vsec_azimuth_deg.to_radians(),
        well,
        model: s.model.map(|m| m.name),
        offset: s
            .offset
            .as_ref()
            .map(|o| (o.short_name.as_str(), o.rows.as_slice())),
    };
    figures.write(dir)
}

/// One station of the JSON: position, and with a model its covariance and
/// ellipse at `s.confidence`; lengths in `s.output_unit`, each key named
/// with its unit.
fn json_station(s: &WellSurvey, r: &crate::survey::listing::Row) -> serde_json::Value {
    use serde_json::json;
    let u = s.output_unit;
    let sym = u.symbol();
    let len = |m: f64| u.from_m(m);
    let mut v = serde_json::Map::new();
    let mut put = |key: String, value: serde_json::Value| {
        v.insert(key, value);
    };
    put(format!("md_{sym}"), json!(len(r.md_m)));
    put("inc_deg".into(), json!(r.inc_deg));
    put("azi_deg".into(), json!(r.azi_deg));
    put(format!("tvd_{sym}"), json!(len(r.tvd_m)));
    put(format!("north_{sym}"), json!(len(r.north_m)));
    put(format!("east_{sym}"), json!(len(r.east_m)));
    put(
        format!("dls_deg_per_{}", u.dls_course().1),
        json!(u.dls_from_per_30m(r.dls_deg_per_30m)),
    );
    put(format!("vsec_{sym}"), json!(len(r.vsec_m)));
    put("toolface_deg".into(), json!(r.input.toolface_deg));
    put("time_s".into(), json!(r.input.time_s));
    if s.model.is_some() {
        let e = r.ellipse();
        let scaled = e.map(|e| e.scaled(s.confidence));
        put(
            format!("nev_covariance_{sym}2"),
            json!(r.cov.map(|c| c.map(|x| u.from_m2(x)))),
        );
        put(
            format!("sigma_north_{sym}"),
            json!(r.cov.map(|c| len(c[0].max(0.0).sqrt()))),
        );
        put(
            format!("sigma_east_{sym}"),
            json!(r.cov.map(|c| len(c[1].max(0.0).sqrt()))),
        );
        put(
            format!("sigma_vert_{sym}"),
            json!(e.map(|e| len(e.sigma_vert))),
        );
        put(
            format!("ellipse_semi_major_{sym}"),
            json!(scaled.map(|x| len(x.0))),
        );
        put(
            format!("ellipse_semi_minor_{sym}"),
            json!(scaled.map(|x| len(x.1))),
        );
        put(
            "ellipse_azimuth_deg".into(),
            json!(e.map(|e| e.azimuth_deg)),
        );
        put("error_model_valid".into(), json!(r.cov.is_some()));
    }
    if s.uncalibrated {
        put("flags".into(), json!([UNCALIBRATED_FLAG]));
    }
    serde_json::Value::Object(v)
}

pub fn json_text(s: &WellSurvey) -> Result<String> {
    let u = s.output_unit;
    let sym = u.symbol();
    let len = |m: f64| u.from_m(m);
    let stations: Vec<serde_json::Value> = s
        .rows
        .iter()
        .enumerate()
        .map(|(k, r)| {
            let mut v = json_station(s, r);
            let flags = s.station_flags(k);
            if !flags.is_empty() {
                v["flags"] = serde_json::json!(flags);
            }
            if let Some(q) = s.station_qc.get(k).copied().flatten() {
                let rate = q.earth_rate_deg_h();
                v["qc"] = serde_json::json!({
                    "result": q.word(),
                    "gravity_m_s2": q.gravity_m_s2,
                    "gravity_error_m_s2": q.gravity_error_m_s2,
                    "gravity_tolerance_m_s2": q.gravity_tolerance_m_s2,
                    "earth_rate_residual_deg_h": rate.map(|r| r.0),
                    "earth_rate_tolerance_deg_h": rate.map(|r| r.1),
                });
            }
            if let Some(x) = s.offset.as_ref().map(|o| &o.seps[k]) {
                let c = &x.closest;
                v[format!("offset_md_{sym}")] = serde_json::json!(len(c.md_m));
                v[format!("offset_nev_{sym}")] =
                    serde_json::json!([len(c.nev.x), len(c.nev.y), len(c.nev.z)]);
                v[format!("offset_nev_covariance_{sym}2")] =
                    serde_json::json!(c.cov.map(|c| c.map(|x| u.from_m2(x))));
                v[format!("ctc_{sym}")] = serde_json::json!(len(x.ctc_m));
                v[format!("sigma_s_{sym}")] = serde_json::json!(x.sigma_s_m.map(len));
                v["sf"] = serde_json::json!(x.sf);
                v["sf_status"] = serde_json::json!(sf_status(x));
            }
            v
        })
        .collect();
    let doc = serde_json::json!({
        "north_reference": "true",
        "length_unit": sym,
        "vsec_azimuth_deg": s.vsec_azimuth_deg,
        "error_model": s.model.map(|m| m.name),
        "confidence": s.model.map(|_| s.confidence),
        "ellipse_convention": s.model.map(|_| format!("semi-axes: 1-sigma of the NE covariance times sqrt(-2 ln(1 - confidence)); azimuth of the major axis in [0, 180) deg; covariance [nn, ee, vv, ne, nv, ev] {sym}^2")),
        "note": s.validity_note(),
        "stations": stations,
    });
    let mut doc = doc;
    if s.model.is_some() {
        doc[format!("tie_on_covariance_{sym}2")] =
            serde_json::json!(s.tie_on_cov_m2.map(|c| c.map(|x| u.from_m2(x))));
        doc["tie_on_note"] = serde_json::json!(tie_on_note(s.tie_on_cov_m2.as_ref(), u));
    }
    if s.uncalibrated {
        doc["uncalibrated_note"] = serde_json::json!(UNCALIBRATED_NOTE);
    }
    if let Some(note) = &s.header_note {
        doc["placement_note"] = serde_json::json!(note);
    }
    if let Some(bit) = &s.bit {
        // the last station's angles held straight ahead to the bit
        doc["bit_projection"] = json_station(s, bit);
    }
    if let Some(o) = &s.offset {
        let min = sep::minimum(&o.seps);
        doc["separation"] = serde_json::json!({
            "offset": o.name,
            "offset_error_model": o.model.map(|m| m.name),
            "rule": "ISCWSA separation rule, Sawaryn et al. 2019 (SPE-187073-PA): SF = (D - R_ref - R_off - S_m) / (k sqrt(sigma_S^2 + sigma_pa^2)); offset covariance interpolated linearly in MD at the closest point",
            "k": o.rule.k,
            "surface_margin_m": o.rule.surface_margin_m,
            "sigma_pa_m": o.rule.sigma_pa_m,
            "hole_radius_m": o.rule.ref_radius_m,
            "offset_hole_radius_m": o.rule.offset_radius_m,
            "min_sf": min.map(|m| m.1),
            "violation": o.seps.iter().any(|x| x.sf.is_some_and(|f| f < 1.0)),
            "summary": s.separation_summary(),
        });
        doc["separation"][format!("min_sf_md_{sym}")] =
            serde_json::json!(min.map(|m| len(s.rows[m.0].md_m)));
    }
    Ok(serde_json::to_string_pretty(&doc)? + "\n")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::survey::listing::{read_stations, AzimuthReference, KnownModel, TieOnInput};
    use crate::survey::well_survey::{ModelChoice, SurveyInputs};

    /// The `--csv` output is a station file: read back, it gives the same
    /// stations (MD in metres, whatever the input's unit).
    #[test]
    fn csv_output_reads_back_as_the_same_stations() {
        for (text, to_m) in [
            (
                "MD (m);Inc;Azi (deg);tf;Time (s)\n0;0;0;;\n30;1.5;10;20;5\n530.25;45.125;123.5;;9\n",
                1.0,
            ),
            (
                "md_ft,inc_deg,azi_deg\n0,0,0\n100,3,350\n1000,60,12.5\n",
                0.3048,
            ),
        ] {
            let file = read_stations(text.as_bytes()).unwrap();
            let inputs = SurveyInputs {
                reference: AzimuthReference::True,
                tie: TieOnInput {
                    md: None,
                    tvd: 0.0,
                    north: 0.0,
                    east: 0.0,
                    covariance: None,
                },
                vsec_azimuth: None,
                model: ModelChoice::None,
                confidence: 0.95,
            };
            let no_site = |_: &KnownModel| anyhow::bail!("no model, no site");
            let survey = WellSurvey::compute(&file, &inputs, &no_site).unwrap();
            let back = read_stations(csv_text(&survey).as_bytes()).unwrap();
            assert_eq!(back.unit, crate::survey::listing::LengthUnit::Metre);
            assert_eq!(back.stations.len(), file.stations.len());
            for (a, b) in file.stations.iter().zip(&back.stations) {
                // the survey keeps angles in radians: equal to rounding
                let close = |x: f64, y: f64| (x - y).abs() < 1e-9;
                assert!(close(a.md * to_m, b.md), "{a:?} {b:?}");
                assert!(close(a.inc_deg, b.inc_deg), "{a:?} {b:?}");
                assert!(close(a.azi_deg, b.azi_deg), "{a:?} {b:?}");
                assert_eq!((a.toolface_deg, a.time_s), (b.toolface_deg, b.time_s));
            }
        }
    }
}
