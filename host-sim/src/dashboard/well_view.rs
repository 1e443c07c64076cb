//! What a driller watches of the well: the stations' positions in a plan
//! view (east, north) and a vertical section (section distance, TVD down),
//! each with its error ellipse, against the job's well plan when it has
//! one. The geometry is the survey figures' (`survey::listing::plot`):
//! [`SIGMA`]-sigma ellipses of the north-east block and of the section
//! plane.

use serde_json::{json, Map, Value};

use crate::survey::iscwsa::Cov6;
use crate::survey::listing::plot::{ellipse_axes, plan_block, section_block, SIGMA};

/// A station whose position is determined: north, east, TVD (m) and its
/// NEV covariance where valid.
#[derive(Debug, Clone, Copy)]
pub struct PlacedStation {
    pub nev: [f64; 3],
    pub cov: Option<Cov6>,
}

/// The azimuth (rad, true north) the vertical section is taken along: to
/// the plan's end (its target) when there is a plan, else to the last
/// station placed (as `host-sim survey` takes it without
/// `--vsec-azimuth`); 0 (north) when that is the origin.
pub fn section_azimuth(stations: &[PlacedStation], well_plan: Option<&[[f64; 3]]>) -> f64 {
    let end = match well_plan.and_then(|p| p.last()) {
        Some(p) => Some(*p),
        None => stations.last().map(|s| s.nev),
    };
    match end {
        Some([n, e, _]) if n.hypot(e) > 0.0 => e.atan2(n),
        _ => 0.0,
    }
}

/// The section distance of (north, east) along `azimuth` (rad).
fn section_distance(n: f64, e: f64, azimuth: f64) -> f64 {
    let (s, c) = azimuth.sin_cos();
    n * c + e * s
}

/// `[x, y, semi-major, semi-minor, angle of the major axis from +x
/// towards +y in deg]` of the ellipse of the block (sxx, syy, sxy) around
/// (x, y), or `None` if the block is not a covariance.
fn ellipse(x: f64, y: f64, (sxx, syy, sxy): (f64, f64, f64)) -> Option<Value> {
    let (a, b, theta) = ellipse_axes(sxx, syy, sxy, SIGMA);
    let valid = [x, y, a, b, theta].iter().all(|v| v.is_finite());
    valid.then(|| json!([x, y, a, b, theta.to_degrees()]))
}

/// The drawing's fields of the stations' JSON: `plan` and `section` (the
/// stations' points), `plan_ellipses` and `section_ellipses`,
/// `well_plan` (`{"plan", "section"}` or null), `section_azimuth_deg`,
/// `ellipse_sigma`.
pub fn drawing(stations: &[PlacedStation], well_plan: Option<&[[f64; 3]]>) -> Map<String, Value> {
    let azimuth = section_azimuth(stations, well_plan);
    let mut plan = Vec::new();
    let mut section = Vec::new();
    let mut plan_ellipses = Vec::new();
    let mut section_ellipses = Vec::new();
    for s in stations {
        let [n, e, tvd] = s.nev;
        let vs = section_distance(n, e, azimuth);
        plan.push(json!([e, n]));
        section.push(json!([vs, tvd]));
        if let Some(cov) = &s.cov {
            plan_ellipses.extend(ellipse(e, n, plan_block(cov)));
            section_ellipses.extend(ellipse(vs, tvd, section_block(cov, azimuth)));
        }
    }
    let well_plan = well_plan.map(|points| {
        let plan: Vec<Value> = points.iter().map(|[n, e, _]| json!([e, n])).collect();
        let section: Vec<Value> = points
            .iter()
            .map(|[n, e, tvd]| json!([section_distance(*n, *e, azimuth), tvd]))
            .collect();
        json!({"plan": plan, "section": section})
    });
    let mut fields = Map::new();
    fields.insert("plan".into(), plan.into());
    fields.insert("section".into(), section.into());
    fields.insert("plan_ellipses".into(), plan_ellipses.into());
    fields.insert("section_ellipses".into(), section_ellipses.into());
    fields.insert("well_plan".into(), well_plan.unwrap_or(Value::Null));
    fields.insert("section_azimuth_deg".into(), json!(azimuth.to_degrees()));
    fields.insert("ellipse_sigma".into(), json!(SIGMA));
    fields
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64) {
        assert!((a - b).abs() < 1e-9, "{a} vs {b}");
    }

    #[test]
    fn the_section_runs_to_the_plans_target_else_to_the_last_station() {
        let placed = |n, e| PlacedStation {
            nev: [n, e, 100.0],
            cov: None,
        };
        let stations = [placed(0.0, 0.0), placed(-10.0, 10.0)];
        close(section_azimuth(&stations, None), 135f64.to_radians());
        let plan = [[0.0, 0.0, 0.0], [0.0, 50.0, 10.0]];
        close(section_azimuth(&stations, Some(&plan)), 90f64.to_radians());
        close(section_azimuth(&[placed(0.0, 0.0)], None), 0.0);
        close(section_azimuth(&[], None), 0.0);
    }

    #[test]
    fn stations_ellipses_and_the_plan_are_drawn_in_both_views() {
        // Semi-axes 3 and 1 m (1 sigma) with the major axis north-east,
        // 4 m^2 vertical; the section due east.
        let (s, c) = 45f64.to_radians().sin_cos();
        let cov = [
            9.0 * c * c + s * s,
            9.0 * s * s + c * c,
            4.0,
            8.0 * c * s,
            0.0,
            0.0,
        ];
        let stations = [
            PlacedStation {
                nev: [0.0, 0.0, 1000.0],
                cov: None,
            },
            PlacedStation {
                nev: [0.0, 30.0, 1005.0],
                cov: Some(cov),
            },
        ];
        let plan = [[0.0, 0.0, 1000.0], [0.0, 15.0, 1002.0], [0.0, 40.0, 1004.0]];
        let d = drawing(&stations, Some(&plan));
        close(d["section_azimuth_deg"].as_f64().unwrap(), 90.0);
        assert_eq!(d["plan"], json!([[0.0, 0.0], [30.0, 0.0]]));
        let section = d["section"].as_array().unwrap();
        close(section[1][0].as_f64().unwrap(), 30.0);
        close(section[1][1].as_f64().unwrap(), 1005.0);
        // One ellipse per station with a covariance; x east, y north:
        // the major axis north-east is 45 deg from +x towards +y.
        let plan_ellipses = d["plan_ellipses"].as_array().unwrap();
        assert_eq!(plan_ellipses.len(), 1);
        let p: Vec<f64> = plan_ellipses[0]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        close(p[0], 30.0);
        close(p[1], 0.0);
        close(p[2], SIGMA * 3.0);
        close(p[3], SIGMA * 1.0);
        close(p[4], 45.0);
        // In the section due east: var(east) = 5, var(TVD) = 4, no
        // correlation: the major axis along the section.
        let q = d["section_ellipses"][0].as_array().unwrap();
        close(q[2].as_f64().unwrap(), SIGMA * 5f64.sqrt());
        close(q[3].as_f64().unwrap(), SIGMA * 2.0);
        close(q[4].as_f64().unwrap(), 0.0);
        // The plan in both views.
        assert_eq!(d["well_plan"]["plan"][2], json!([40.0, 0.0]));
        close(d["well_plan"]["section"][2][0].as_f64().unwrap(), 40.0);
        close(d["well_plan"]["section"][2][1].as_f64().unwrap(), 1004.0);
        assert_eq!(drawing(&stations, None)["well_plan"], Value::Null);
    }

    #[test]
    fn a_covariance_that_is_not_one_draws_no_ellipse() {
        let stations = [PlacedStation {
            nev: [1.0, 2.0, 3.0],
            cov: Some([f64::NAN, 1.0, 1.0, 0.0, 0.0, 0.0]),
        }];
        let d = drawing(&stations, None);
        assert_eq!(d["plan_ellipses"], json!([]));
        assert_eq!(d["plan"].as_array().unwrap().len(), 1);
    }
}
