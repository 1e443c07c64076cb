//! The outputs of a station file's survey ([`WellSurvey`]): the listing
//! on the terminal, one CSV row per station, the survey as JSON, a WITSML
//! 1.4.1.1 trajectory, and the plan and section figures. Lengths in
//! metres, azimuths along true north, whatever the input.

use crate::survey::listing::ellipse::scale_2d;
use crate::survey::listing::separation as sep;
use crate::survey::listing::{plot, tie_on_note};
use crate::survey::well_survey::{sf_status, WellSurvey};
use anyhow::Result;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

mod witsml;
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
    use crate::formats::files::write_text;
    if let Some(p) = paths.csv {
        write_text(p, &csv_text(s))?;
    }
    if let Some(p) = paths.json {
        write_text(p, &json_text(s)?)?;
    }
    if let Some(p) = paths.witsml {
        write_text(p, &witsml_text(s))?;
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

/// The listing: a header line, the model's and the ellipse's, a table of
/// the stations (with their sigmas and ellipse with a model, their
/// separation with an offset well), the model's validity note and the
/// separation summary.
pub fn listing_text(s: &WellSurvey) -> String {
    let u = s.output_unit;
    let sym = u.symbol();
    let mut text = String::new();
    let _ = writeln!(
        text,
        "{} stations; lengths in {sym}, N/E along true north; DLS in deg/{}; vertical section along {:.2} deg",
        s.rows.len(),
        u.dls_course().1,
        s.vsec_azimuth_deg
    );
    if let Some(m) = s.model {
        let _ = writeln!(
            text,
            "error model {}; ellipse at {:.1} % (2-D normal, k = {:.4} x 1-sigma)",
            m.name,
            100.0 * s.confidence,
            scale_2d(s.confidence)
        );
        let _ = writeln!(text, "{}", tie_on_note(s.tie_on_cov_m2.as_ref(), u));
    }
    let unit = |name: &str| format!("{name} {sym}");
    let mut head = format!(
        "{:>9} {:>7} {:>7} {:>9} {:>9} {:>9} {:>6} {:>9}",
        unit("MD"),
        "inc",
        "azi",
        unit("TVD"),
        unit("N"),
        unit("E"),
        "DLS",
        unit("VS")
    );
    if s.model.is_some() {
        head += &format!(
            " {:>7} {:>7} {:>7} {:>8} {:>8} {:>6}",
            unit("sN"),
            unit("sE"),
            unit("sV"),
            unit("major"),
            unit("minor"),
            "az"
        );
    }
    if s.offset.is_some() {
        head += &format!(" {:>9} {:>7} {:>8}", unit("ctc"), unit("sS"), "SF");
    }
    let _ = writeln!(text, "{head}");
    let len = |m: f64| u.from_m(m);
    for (k, r) in s.rows.iter().enumerate() {
        let mut line = format!(
            "{:>9.2} {:>7.2} {:>7.2} {:>9.2} {:>9.2} {:>9.2} {:>6.2} {:>9.2}",
            len(r.md_m),
            r.inc_deg,
            r.azi_deg,
            len(r.tvd_m),
            len(r.north_m),
            len(r.east_m),
            u.dls_from_per_30m(r.dls_deg_per_30m),
            len(r.vsec_m)
        );
        if s.model.is_some() {
            match (r.cov, r.ellipse()) {
                (Some(c), Some(e)) => {
                    let (a, b) = e.scaled(s.confidence);
                    let _ = write!(
                        line,
                        " {:>7.2} {:>7.2} {:>7.2} {:>8.2} {:>8.2} {:>6.1}",
                        len(c[0].max(0.0).sqrt()),
                        len(c[1].max(0.0).sqrt()),
                        len(e.sigma_vert),
                        len(a),
                        len(b),
                        e.azimuth_deg
                    );
                }
                _ => line += "  (outside the model's validity)",
            }
        }
        if let Some(x) = s.offset.as_ref().map(|o| &o.seps[k]) {
            let _ = write!(line, " {:>9.2}", len(x.ctc_m));
            match (x.sigma_s_m, x.sf) {
                (Some(sig), Some(f)) => {
                    let flag = if f < 1.0 { " SF<1" } else { "" };
                    let _ = write!(line, " {:>7.2} {f:>8.3}{flag}", len(sig));
                }
                _ => line += "  SF undetermined",
            }
        }
        let _ = writeln!(text, "{line}");
    }
    if let Some(note) = s.validity_note() {
        let _ = writeln!(text, "note: {note}");
    }
    for l in s.separation_summary() {
        let _ = writeln!(text, "{l}");
    }
    text
}

fn opt(v: Option<f64>) -> String {
    v.map_or_else(String::new, |v| v.to_string())
}

pub fn csv_text(s: &WellSurvey) -> String {
    let u = s.output_unit;
    let sym = u.symbol();
    let len = |m: f64| u.from_m(m);
    let mut out = format!(
        "md_{sym},inc_deg,azi_deg,tvd_{sym},north_{sym},east_{sym},dls_deg_per_{},vsec_{sym},toolface_deg,time_s",
        u.dls_course().1
    );
    if s.model.is_some() {
        let _ = write!(
            out,
            ",sigma_north_{sym},sigma_east_{sym},sigma_vert_{sym},ellipse_semi_major_{sym},ellipse_semi_minor_{sym},ellipse_azimuth_deg,confidence,error_model_valid"
        );
    }
    if s.offset.is_some() {
        let _ = write!(out, ",offset_md_{sym},ctc_{sym},sigma_s_{sym},sf,sf_status");
    }
    out += "\n";
    for (k, r) in s.rows.iter().enumerate() {
        let _ = write!(
            out,
            "{},{},{},{},{},{},{},{},{},{}",
            len(r.md_m),
            r.inc_deg,
            r.azi_deg,
            len(r.tvd_m),
            len(r.north_m),
            len(r.east_m),
            u.dls_from_per_30m(r.dls_deg_per_30m),
            len(r.vsec_m),
            opt(r.input.toolface_deg),
            opt(r.input.time_s)
        );
        if s.model.is_some() {
            match (r.cov, r.ellipse()) {
                (Some(c), Some(e)) => {
                    let (a, b) = e.scaled(s.confidence);
                    let _ = write!(
                        out,
                        ",{},{},{},{},{},{},{},true",
                        len(c[0].max(0.0).sqrt()),
                        len(c[1].max(0.0).sqrt()),
                        len(e.sigma_vert),
                        len(a),
                        len(b),
                        e.azimuth_deg,
                        s.confidence
                    );
                }
                _ => {
                    let _ = write!(out, ",,,,,,,{},false", s.confidence);
                }
            }
        }
        if let Some(x) = s.offset.as_ref().map(|o| &o.seps[k]) {
            let _ = write!(
                out,
                ",{},{},{},{},{}",
                len(x.closest.md_m),
                len(x.ctc_m),
                opt(x.sigma_s_m.map(len)),
                opt(x.sf),
                sf_status(x)
            );
        }
        out += "\n";
    }
    out
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
