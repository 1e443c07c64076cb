//! The survey as a WITSML 1.4.1.1 trajectory (`trajectorys`, namespace
//! `http://www.witsml.org/schemas/1series`): the well's and wellbore's
//! names and uids from the job, one `trajectoryStation` per station with
//! its position and, where the error model gives one, its NEV covariance
//! (`matrixCov`), in the element order of the 1.4.1.1 schema
//! (`obj_trajectory`, `cs_trajectoryStation`, `cs_stnTrajMatrixCov`).
//! The output is not validated against the XSD: Energistics publishes it
//! on its site only, through no package registry.

use crate::survey::listing::drilling::UNCALIBRATED_NOTE;
use crate::survey::listing::{LengthUnit, Row};
use crate::survey::well_survey::WellSurvey;
use std::fmt::Write as _;

/// `text` with the five characters XML gives a meaning replaced by their
/// entities, safe in element text and in a double-quoted attribute.
fn escaped(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            c => out.push(c),
        }
    }
    out
}

/// The station's NEV covariance (`Row::cov`, m^2, [nn, ee, vv, ne, nv, ev])
/// in `cs_stnTrajMatrixCov`'s order: NN, NE, NVert, EE, EVert, VertVert.
/// Nothing for a station the model leaves undetermined.
fn matrix_cov(r: &Row, unit: LengthUnit) -> String {
    let Some([nn, ee, vv, ne, nv, ev]) = r.cov else {
        return String::new();
    };
    let sym = unit.symbol();
    let mut x = String::from("      <matrixCov>\n");
    for (name, value) in [
        ("varianceNN", nn),
        ("varianceNE", ne),
        ("varianceNVert", nv),
        ("varianceEE", ee),
        ("varianceEVert", ev),
        ("varianceVertVert", vv),
    ] {
        let _ = writeln!(
            x,
            "        <{name} uom=\"{sym}2\">{}</{name}>",
            unit.from_m2(value)
        );
    }
    x += "      </matrixCov>\n";
    x
}

pub fn witsml_text(s: &WellSurvey) -> String {
    let names = &s.well;
    let mut x = String::from(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n\
         <trajectorys xmlns=\"http://www.witsml.org/schemas/1series\" version=\"1.4.1.1\">\n",
    );
    let _ = write!(
        x,
        "  <trajectory uidWell=\"{}\" uidWellbore=\"{}\" uid=\"survey\">\n\
         \x20   <nameWell>{}</nameWell>\n\
         \x20   <nameWellbore>{}</nameWellbore>\n\
         \x20   <name>host-sim survey</name>\n",
        escaped(&names.well_uid),
        escaped(&names.wellbore_uid),
        escaped(&names.well),
        escaped(&names.wellbore),
    );
    let u = s.output_unit;
    let (sym, len) = (u.symbol(), |m: f64| u.from_m(m));
    if let (Some(first), Some(last)) = (s.rows.first(), s.rows.last()) {
        let _ = writeln!(x, "    <mdMn uom=\"{sym}\">{}</mdMn>", len(first.md_m));
        let _ = writeln!(x, "    <mdMx uom=\"{sym}\">{}</mdMx>", len(last.md_m));
    }
    let _ = writeln!(
        x,
        "    <aziVertSect uom=\"dega\">{}</aziVertSect>",
        s.vsec_azimuth_deg
    );
    x += "    <aziRef>true north</aziRef>\n";
    // The bit projection (`s.bit`) is left out: 1.4.1.1's TrajStationType
    // has no value for a projection to the bit, and a measured-looking
    // "unknown" station at the bit would mislead; the JSON carries it.
    for (k, r) in s.rows.iter().enumerate() {
        let kind = if k == 0 { "tie in point" } else { "unknown" };
        let _ = write!(
            x,
            "    <trajectoryStation uid=\"st{k}\">\n\
             \x20     <typeTrajStation>{kind}</typeTrajStation>\n\
             \x20     <md uom=\"{sym}\">{}</md>\n\
             \x20     <tvd uom=\"{sym}\">{}</tvd>\n\
             \x20     <incl uom=\"dega\">{}</incl>\n\
             \x20     <azi uom=\"dega\">{}</azi>\n\
             \x20     <dispNs uom=\"{sym}\">{}</dispNs>\n\
             \x20     <dispEw uom=\"{sym}\">{}</dispEw>\n\
             \x20     <vertSect uom=\"{sym}\">{}</vertSect>\n\
             \x20     <dls uom=\"dega/{}\">{}</dls>\n",
            len(r.md_m),
            len(r.tvd_m),
            r.inc_deg,
            r.azi_deg,
            len(r.north_m),
            len(r.east_m),
            len(r.vsec_m),
            u.dls_course().1,
            u.dls_from_per_30m(r.dls_deg_per_30m)
        );
        x += &matrix_cov(r, u);
        let flags = s.station_flags(k);
        if !flags.is_empty() {
            // TrajectoryStation's commonData comes after its matrixCov
            let _ = writeln!(
                x,
                "      <commonData><comments>{}</comments></commonData>",
                escaped(&flags.join("; "))
            );
        }
        x += "    </trajectoryStation>\n";
    }
    if s.uncalibrated {
        // the trajectory's commonData follows its stations
        let _ = writeln!(
            x,
            "    <commonData><comments>{}</comments></commonData>",
            escaped(UNCALIBRATED_NOTE)
        );
    }
    x += "  </trajectory>\n</trajectorys>\n";
    x
}

#[cfg(test)]
mod tests {
    use super::escaped;

    #[test]
    fn escapes_the_five_xml_characters() {
        assert_eq!(
            escaped(r#"A&B <C> "D" 'E'"#),
            "A&amp;B &lt;C&gt; &quot;D&quot; &apos;E&apos;"
        );
    }
}
