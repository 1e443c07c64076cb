//! The stations on the page: each as the probe sent it, with MD and
//! positions by minimum curvature from the job's tie-on when a depth log
//! pairs them with depth (the stations of `host-sim survey CAPTURE --depth
//! --job`, collected and positioned by [`crate::survey::stations`]), for the
//! plan view and the vertical section.

use mwd_core::protocol::StationSurvey;
use serde_json::{json, Value};

use super::well_view::{drawing, PlacedStation};
use crate::formats::depth_log::DepthLog;
use crate::formats::display;
use crate::survey::listing::drilling::{self, DrillingRow};
use crate::survey::listing::TieOnInput;
use crate::survey::stations::{StationCollector, SurveySetup};

/// "12.34 +- 0.56 m" from a value and a variance; "n/a" when the variance
/// is not a valid one (never a sigma of 0 for it).
fn metres(value: f64, variance: Option<f64>) -> String {
    match variance {
        Some(v) if v.is_finite() && v >= 0.0 && value.is_finite() => {
            format!("{value:.2} +- {:.2} m", v.sqrt())
        }
        _ => "n/a".into(),
    }
}

fn station_row(s: &StationSurvey) -> Value {
    let [inc, _, tf] = s.angles.map(f64::from);
    let [s_inc, _, s_tf] = s.angles_std.map(f64::from);
    let tf_deg = if tf.is_finite() {
        display::deg_0_360(tf)
    } else {
        f64::NAN
    };
    json!({
        "number": s.station,
        "time_s": s.time_us as f64 * 1e-6,
        "inclination": display::angle_with_sigma(inc.to_degrees(), s_inc),
        "azimuth": display::station_azimuth_text(s),
        "toolface": display::angle_with_sigma(tf_deg, s_tf),
        "invalid": !drilling::station_valid(s),
        "md": Value::Null,
        "position": "no depth log",
    })
}

fn positioned(row: &mut Value, d: &DrillingRow) {
    row["md"] = json!(format!("{:.2} m", d.row.md_m));
    row["position"] = if d.position_determined {
        let cov = d.row.cov;
        let part = |i: usize| cov.map(|c| c[i]);
        json!(format!(
            "N {}, E {}, TVD {}",
            metres(d.row.north_m, part(0)),
            metres(d.row.east_m, part(1)),
            metres(d.row.tvd_m, part(2)),
        ))
    } else {
        json!("undetermined (an azimuth up to here is undetermined)")
    };
}

/// The stations for the page: the list, the note on positions, and the
/// plan view (east, north) and vertical section (section, TVD) of the
/// stations whose position is determined, with their ellipses, against
/// `well_plan` ((north, east, TVD) along the job's plan) if given
/// ([`drawing`]).
pub fn stations_json(
    collected: &StationCollector,
    dropped: u64,
    depth: Option<&DepthLog>,
    setup: &SurveySetup,
    well_plan: Option<&[[f64; 3]]>,
) -> Value {
    let stations = collected.stations();
    let mut rows: Vec<Value> = stations.iter().map(station_row).collect();
    let mut placed = Vec::new();
    let note = match (depth, stations.is_empty()) {
        (None, _) => "No depth log: positions by minimum curvature need MD, so the stations \
                      are listed only (start with --depth DEPTH.csv)."
            .to_string(),
        (Some(_), true) => "No station yet.".to_string(),
        (Some(depth), false) => {
            // No station links: the page has the frames only, not their
            // replay (the survey then chains the stations' azimuths alone).
            match collected.survey(&[], setup, depth) {
                Ok(survey) => {
                    for d in &survey.rows {
                        // By number and time: a station's NaN correlations
                        // make `==` false even for itself.
                        let same = |s: &StationSurvey| {
                            (s.station, s.time_us) == (d.survey.station, d.survey.time_us)
                        };
                        if let Some(k) = stations.iter().position(same) {
                            positioned(&mut rows[k], d);
                        }
                        if d.position_determined {
                            placed.push(PlacedStation {
                                nev: [d.row.north_m, d.row.east_m, d.row.tvd_m],
                                cov: d.row.cov,
                            });
                        }
                    }
                    let skipped: Vec<String> = survey
                        .skipped
                        .iter()
                        .map(|s| format!("station {}: {}", s.survey.station, s.reason))
                        .collect();
                    let mut note = tie_on_note(&setup.tie);
                    note += " The position sigmas chain the stations' azimuths alone: the page \
                             has no replay of the capture for the stations' links, which \
                             `host-sim survey CAPTURE --job` adds, so they can be smaller than \
                             the survey's.";
                    if !skipped.is_empty() {
                        note += &format!(" Left out: {}.", skipped.join("; "));
                    }
                    if placed.is_empty() {
                        note += " No position is determined yet: the azimuth is undetermined.";
                    }
                    note
                }
                Err(e) => format!("Positions not computed: {e:#}"),
            }
        }
    };
    let note = if dropped > 0 {
        format!("{note} ({dropped} earlier stations no longer held.)")
    } else {
        note
    };
    let mut view = drawing(&placed, well_plan);
    view.insert("rows".into(), rows.into());
    view.insert("note".into(), note.into());
    Value::Object(view)
}

/// How the stations are placed: from the job's tie-on, or from the first
/// station at the surface when the job gives none.
fn tie_on_note(tie: &TieOnInput) -> String {
    let at = format!(
        "N {:.2} m, E {:.2} m, TVD {:.2} m",
        tie.north, tie.east, tie.tvd
    );
    match tie.md {
        Some(md) => format!(
            "Positions by minimum curvature from the job's tie-on (MD {md:.2} m, {at}), MD from \
             the depth log; 1 sigma."
        ),
        None if (tie.north, tie.east, tie.tvd) == (0.0, 0.0, 0.0) => {
            "Positions by minimum curvature from the first station (the tie-on, at N 0, E 0, \
             TVD 0), MD from the depth log; 1 sigma."
                .to_string()
        }
        None => format!(
            "Positions by minimum curvature from the first station (the tie-on, at {at}), MD \
             from the depth log; 1 sigma."
        ),
    }
}
