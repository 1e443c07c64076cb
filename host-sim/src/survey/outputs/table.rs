//! The survey's two tables, the listing on the terminal and the CSV, made
//! one station at a time: a survey held in memory ([`listing_text`],
//! [`csv_text`]) and one streamed from its file
//! ([`crate::survey::streamed`]) write the same bytes. Lengths in the
//! survey's output unit, each header naming it.

use crate::formats::fixed::push_fixed;
use crate::survey::iscwsa::Cov6;
use crate::survey::listing::drilling::{UNCALIBRATED_FLAG, UNCALIBRATED_NOTE};
use crate::survey::listing::ellipse::scale_2d;
use crate::survey::listing::separation::Separation;
use crate::survey::listing::{tie_on_note, KnownModel, LengthUnit, Row};
use crate::survey::well_survey::{sf_status, WellSurvey};
use std::fmt::Write as _;

/// What the tables' headers say: everything but the rows.
#[derive(Clone, Copy, Debug)]
pub struct Head {
    pub stations: usize,
    pub vsec_azimuth_deg: f64,
    pub model: Option<&'static KnownModel>,
    /// Probability held by the scaled horizontal ellipse.
    pub confidence: f64,
    pub tie_on_cov_m2: Option<Cov6>,
    pub unit: LengthUnit,
    /// Whether the rows carry an offset well's separation.
    pub offset: bool,
    /// The probe ran without a calibration (`WellSurvey::uncalibrated`):
    /// the note on top, every row flagged.
    pub uncalibrated: bool,
}

impl Head {
    pub fn of(s: &WellSurvey) -> Self {
        Self {
            stations: s.rows.len(),
            vsec_azimuth_deg: s.vsec_azimuth_deg,
            model: s.model,
            confidence: s.confidence,
            tie_on_cov_m2: s.tie_on_cov_m2,
            unit: s.output_unit,
            offset: s.offset.is_some(),
            uncalibrated: s.uncalibrated,
        }
    }
}

/// The listing: a header line, the model's and the ellipse's, a table of
/// the stations (with their sigmas and ellipse with a model, their
/// separation with an offset well), the model's validity note and the
/// separation summary.
pub fn listing_text(s: &WellSurvey) -> String {
    let head = Head::of(s);
    let mut text = listing_head(&head);
    for (k, r) in s.rows.iter().enumerate() {
        text += &listing_row(&head, r, s.offset.as_ref().map(|o| &o.seps[k]));
    }
    if let Some(note) = s.validity_note() {
        let _ = writeln!(text, "note: {note}");
    }
    for l in s.separation_summary() {
        let _ = writeln!(text, "{l}");
    }
    text
}

/// The listing's lines above the stations.
pub fn listing_head(h: &Head) -> String {
    let u = h.unit;
    let sym = u.symbol();
    let mut text = String::new();
    if h.uncalibrated {
        let _ = writeln!(text, "{UNCALIBRATED_NOTE}");
    }
    let _ = writeln!(
        text,
        "{} stations; lengths in {sym}, N/E along true north; DLS in deg/{}; vertical section along {:.2} deg",
        h.stations,
        u.dls_course().1,
        h.vsec_azimuth_deg
    );
    if let Some(m) = h.model {
        let _ = writeln!(
            text,
            "error model {}; ellipse at {:.1} % (2-D normal, k = {:.4} x 1-sigma)",
            m.name,
            100.0 * h.confidence,
            scale_2d(h.confidence)
        );
        let _ = writeln!(text, "{}", tie_on_note(h.tie_on_cov_m2.as_ref(), u));
    }
    let unit = |name: &str| format!("{name} {sym}");
    let mut columns = format!(
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
    if h.model.is_some() {
        columns += &format!(
            " {:>7} {:>7} {:>7} {:>8} {:>8} {:>6}",
            unit("sN"),
            unit("sE"),
            unit("sV"),
            unit("major"),
            unit("minor"),
            "az"
        );
    }
    if h.offset {
        columns += &format!(" {:>9} {:>7} {:>8}", unit("ctc"), unit("sS"), "SF");
    }
    let _ = writeln!(text, "{columns}");
    text
}

/// One station's line of the listing (with its newline).
pub fn listing_row(h: &Head, r: &Row, separation: Option<&Separation>) -> String {
    let u = h.unit;
    let len = |m: f64| u.from_m(m);
    let mut line = String::with_capacity(160);
    // (value, decimals, width), each after one space but the first
    let mut put = |cells: &[(f64, usize, usize)]| {
        for &(x, decimals, width) in cells {
            if !line.is_empty() {
                line.push(' ');
            }
            push_fixed(&mut line, x, decimals, width);
        }
    };
    put(&[
        (len(r.md_m), 2, 9),
        (r.inc_deg, 2, 7),
        (r.azi_deg, 2, 7),
        (len(r.tvd_m), 2, 9),
        (len(r.north_m), 2, 9),
        (len(r.east_m), 2, 9),
        (u.dls_from_per_30m(r.dls_deg_per_30m), 2, 6),
        (len(r.vsec_m), 2, 9),
    ]);
    if h.model.is_some() {
        match (r.cov, r.ellipse()) {
            (Some(c), Some(e)) => {
                let (a, b) = e.scaled(h.confidence);
                put(&[
                    (len(c[0].max(0.0).sqrt()), 2, 7),
                    (len(c[1].max(0.0).sqrt()), 2, 7),
                    (len(e.sigma_vert), 2, 7),
                    (len(a), 2, 8),
                    (len(b), 2, 8),
                    (e.azimuth_deg, 1, 6),
                ]);
            }
            _ => line += "  (outside the model's validity)",
        }
    }
    if let Some(x) = separation {
        let _ = write!(line, " {:>9.2}", len(x.ctc_m));
        match (x.sigma_s_m, x.sf) {
            (Some(sig), Some(f)) => {
                let flag = if f < 1.0 { " SF<1" } else { "" };
                let _ = write!(line, " {:>7.2} {f:>8.3}{flag}", len(sig));
            }
            _ => line += "  SF undetermined",
        }
    }
    if h.uncalibrated {
        let _ = write!(line, "  {UNCALIBRATED_FLAG}");
    }
    line + "\n"
}

fn opt(v: Option<f64>) -> String {
    v.map_or_else(String::new, |v| v.to_string())
}

/// One row per station (CSV): a station file the tool reads back.
pub fn csv_text(s: &WellSurvey) -> String {
    let head = Head::of(s);
    let mut out = csv_head(&head);
    for (k, r) in s.rows.iter().enumerate() {
        out += &csv_row(&head, r, s.offset.as_ref().map(|o| &o.seps[k]));
    }
    out
}

/// The CSV's header line (with its newline).
pub fn csv_head(h: &Head) -> String {
    let sym = h.unit.symbol();
    let mut out = format!(
        "md_{sym},inc_deg,azi_deg,tvd_{sym},north_{sym},east_{sym},dls_deg_per_{},vsec_{sym},toolface_deg,time_s",
        h.unit.dls_course().1
    );
    if h.model.is_some() {
        let _ = write!(
            out,
            ",sigma_north_{sym},sigma_east_{sym},sigma_vert_{sym},ellipse_semi_major_{sym},ellipse_semi_minor_{sym},ellipse_azimuth_deg,confidence,error_model_valid"
        );
    }
    if h.offset {
        let _ = write!(out, ",offset_md_{sym},ctc_{sym},sigma_s_{sym},sf,sf_status");
    }
    if h.uncalibrated {
        out += ",flag";
    }
    out + "\n"
}

/// One station's CSV row (with its newline).
pub fn csv_row(h: &Head, r: &Row, separation: Option<&Separation>) -> String {
    let u = h.unit;
    let len = |m: f64| u.from_m(m);
    let mut out = String::with_capacity(320);
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
    if h.model.is_some() {
        match (r.cov, r.ellipse()) {
            (Some(c), Some(e)) => {
                let (a, b) = e.scaled(h.confidence);
                let _ = write!(
                    out,
                    ",{},{},{},{},{},{},{},true",
                    len(c[0].max(0.0).sqrt()),
                    len(c[1].max(0.0).sqrt()),
                    len(e.sigma_vert),
                    len(a),
                    len(b),
                    e.azimuth_deg,
                    h.confidence
                );
            }
            _ => {
                let _ = write!(out, ",,,,,,,{},false", h.confidence);
            }
        }
    }
    if let Some(x) = separation {
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
    if h.uncalibrated {
        let _ = write!(out, ",{UNCALIBRATED_FLAG}");
    }
    out + "\n"
}
