//! A simulated run's survey against its truth: each station's position
//! against where the simulated probe was at the station's last still
//! sample, and the bit at TD (the end of the run) against the drilled hole
//! the sensor-to-bit distance ahead, each inside its ellipse at the
//! listing's confidence or not: horizontally the NE ellipse (2-D normal,
//! squared Mahalanobis distance against -2 ln(1 - p)), vertically the
//! TVD's interval (1-D normal).

use crate::sim::Drilling;
use crate::survey::iscwsa::Cov6;
use crate::survey::listing::drilling::DrillingSurvey;
use crate::survey::listing::ellipse::{ne_mahalanobis2, scale_2d, Ellipse};
use mwd_core::timing::SAMPLE_INTERVAL_S;
use nalgebra::Vector3;
use std::fmt::Write as _;

/// One surveyed point against the truth.
#[derive(Clone, Debug)]
pub struct PointCheck {
    /// "station 3", "TD (station 5)", "bit".
    pub label: String,
    /// The survey's MD, m.
    pub md_m: f64,
    /// Surveyed minus true: north, east, TVD (m).
    pub error_nev: [f64; 3],
    /// The survey's NEV covariance; `None`: the position is undetermined.
    pub cov: Option<Cov6>,
}

impl PointCheck {
    /// Squared Mahalanobis distance of the north-east error; `None` where
    /// the covariance is undetermined or singular.
    pub fn d2_horizontal(&self) -> Option<f64> {
        let c = self.cov?;
        let [n, e, _] = self.error_nev;
        ne_mahalanobis2([c[0], c[1], c[3]], [n, e])
    }

    /// The truth inside the horizontal ellipse holding `p`.
    pub fn inside_horizontal(&self, p: f64) -> Option<bool> {
        Some(self.d2_horizontal()? <= scale_2d(p).powi(2))
    }

    /// The vertical error in TVD sigmas.
    pub fn vertical_sigmas(&self) -> Option<f64> {
        let v = self.cov?[2];
        (v > 0.0).then(|| self.error_nev[2].abs() / v.sqrt())
    }

    /// The truth inside the TVD interval holding `p`.
    pub fn inside_vertical(&self, p: f64) -> Option<bool> {
        Some(self.vertical_sigmas()? <= normal_two_sided(p))
    }
}

/// The z with P(|Z| <= z) = p for a standard normal (bisection on erf;
/// p in (0, 1)).
fn normal_two_sided(p: f64) -> f64 {
    let (mut lo, mut hi) = (0.0f64, 40.0f64);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if libm::erf(mid / std::f64::consts::SQRT_2) < p {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// The run's checks.
#[derive(Clone, Debug)]
pub struct TruthChecks {
    pub stations: Vec<PointCheck>,
    /// Projected from the last station, if the survey has a bit.
    pub bit: Option<PointCheck>,
    pub confidence: f64,
    /// Stations flagged "uncalibrated" (the probe ran without a
    /// calibration: all of them).
    pub uncalibrated_stations: usize,
}

impl TruthChecks {
    pub fn new(survey: &DrillingSurvey, drilling: &Drilling, confidence: f64) -> Self {
        let stations = survey
            .rows
            .iter()
            .map(|r| {
                let t = (f64::from(r.survey.end_sample) + 1.0) * SAMPLE_INTERVAL_S;
                let truth = drilling.truth(t);
                check(
                    format!("station {}", r.survey.station),
                    &r.row,
                    truth.point.nev,
                    r.position_determined,
                )
            })
            .collect();
        // The bit at the run's end: the sensors' true MD then, plus the
        // sensor-to-bit distance.
        let end_md = drilling.truth(drilling.duration()).md;
        let bit = survey.bit.as_ref().map(|b| {
            let truth = along_hole(drilling, end_md + b.sensor_to_bit_m);
            check("bit".into(), &b.row, truth, b.row.cov.is_some())
        });
        let uncalibrated_stations = if survey.uncalibrated {
            survey.rows.len()
        } else {
            0
        };
        Self {
            stations,
            bit,
            confidence,
            uncalibrated_stations,
        }
    }

    /// The last station.
    pub fn last_station(&self) -> Option<&PointCheck> {
        self.stations.last()
    }

    /// The summary's lines.
    pub fn summary(&self) -> String {
        let p = self.confidence;
        // (the tie-on is given, not surveyed: no ellipse to be inside)
        let positioned: Vec<&PointCheck> = self
            .stations
            .iter()
            .filter(|c| c.d2_horizontal().is_some())
            .collect();
        let count = |f: fn(&PointCheck, f64) -> Option<bool>| {
            positioned.iter().filter(|c| f(c, p) == Some(true)).count()
        };
        let mut text = format!(
            "stations: {} surveyed, {} positioned beyond the tie-on; the truth inside the {:.0} % \
             ellipse at {} of {} horizontally, {} of {} vertically\n",
            self.stations.len(),
            positioned.len(),
            100.0 * p,
            count(PointCheck::inside_horizontal),
            positioned.len(),
            count(PointCheck::inside_vertical),
            positioned.len()
        );
        if self.uncalibrated_stations > 0 {
            let _ = writeln!(
                text,
                "UNCALIBRATED: {} of {} stations flagged \"uncalibrated\": the probe ran without a \
                 calibration; their sigmas do not cover the parts' uncalibrated errors (turn-on \
                 bias, scale factor, misalignment)",
                self.uncalibrated_stations,
                self.stations.len()
            );
        }
        if let Some(last) = self.last_station() {
            let _ = writeln!(text, "last station {}", point_line(last, p));
        }
        if let Some(bit) = &self.bit {
            let _ = writeln!(text, "bit at TD    {}", point_line(bit, p));
        }
        text
    }
}

fn check(
    label: String,
    row: &crate::survey::listing::Row,
    truth: Vector3<f64>,
    determined: bool,
) -> PointCheck {
    PointCheck {
        label,
        md_m: row.md_m,
        error_nev: [
            row.north_m - truth.x,
            row.east_m - truth.y,
            row.tvd_m - truth.z,
        ],
        cov: row.cov.filter(|_| determined),
    }
}

/// The drilled hole's (north, east, TVD) at `md`: the hole as drilled
/// (the plan with the run's tortuosity), held straight beyond its end (the
/// bit ahead of a sensor at the plan's end).
fn along_hole(drilling: &Drilling, md: f64) -> Vector3<f64> {
    let end = drilling.plan().end_md();
    let p = drilling.hole_at(md.min(end));
    let beyond = (md - end).max(0.0);
    let (si, ci) = p.inclination.sin_cos();
    let (sa, ca) = p.azimuth.sin_cos();
    p.nev + Vector3::new(si * ca, si * sa, ci) * beyond
}

/// "(station 5) MD 3100.23 m: N 441.20 E 352.93 TVD 2451.02 m; 95 % ellipse
/// 2.10 x 0.31 m at 30.2 deg, TVD +-0.40 m; off the truth by 0.35 m
/// horizontally (0.9 of the ellipse), 0.05 m vertically: inside".
fn point_line(c: &PointCheck, p: f64) -> String {
    let [n, e, v] = c.error_nev;
    let label = if c.label == "bit" {
        String::new()
    } else {
        format!("({}) ", c.label)
    };
    let Some(cov) = c.cov else {
        return format!("{label}MD {:.2} m: position undetermined", c.md_m);
    };
    let ellipse = Ellipse::from_cov(&cov);
    let (a, b) = ellipse.scaled(p);
    let z = normal_two_sided(p);
    let horizontal = c.d2_horizontal().map_or("undetermined".into(), |d2| {
        format!("{:.2}", d2.sqrt() / scale_2d(p))
    });
    let verdict = match (c.inside_horizontal(p), c.inside_vertical(p)) {
        (Some(true), Some(true)) => "inside",
        (Some(false), _) | (_, Some(false)) => "OUTSIDE",
        _ => "undetermined",
    };
    format!(
        "{label}MD {:.2} m: {:.0} % ellipse {:.2} x {:.2} m at {:.1} deg, TVD +-{:.2} m; off the \
         truth by {:.2} m horizontally ({} of the ellipse), {:.2} m vertically: {verdict}",
        c.md_m,
        100.0 * p,
        a,
        b,
        ellipse.azimuth_deg,
        z * ellipse.sigma_vert,
        n.hypot(e),
        horizontal,
        v.abs()
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(error: [f64; 3], cov: Cov6) -> PointCheck {
        PointCheck {
            label: "station 1".into(),
            md_m: 100.0,
            error_nev: error,
            cov: Some(cov),
        }
    }

    #[test]
    fn the_two_sided_normal_quantile_is_the_tables() {
        assert!((normal_two_sided(0.95) - 1.959_964).abs() < 1e-6);
        assert!((normal_two_sided(0.6827) - 1.0).abs() < 1e-3);
    }

    #[test]
    fn a_point_is_inside_its_ellipse_by_the_mahalanobis_distance() {
        // 1 m^2 north, 4 m^2 east: 2.4 m east is 1.2 sigma, inside the
        // 95 % ellipse (2.45 sigma); 2.4 m north is 2.4 sigma: also inside;
        // 2.6 m north is outside
        let cov = [1.0, 4.0, 0.25, 0.0, 0.0, 0.0];
        assert_eq!(
            point([0.0, 2.4, 0.0], cov).inside_horizontal(0.95),
            Some(true)
        );
        assert_eq!(
            point([2.4, 0.0, 0.0], cov).inside_horizontal(0.95),
            Some(true)
        );
        assert_eq!(
            point([2.6, 0.0, 0.0], cov).inside_horizontal(0.95),
            Some(false)
        );
        // vertical: 0.5 m sigma, 1.0 m is 2 sigma: outside the 95 % interval
        assert_eq!(
            point([0.0, 0.0, 0.9], cov).inside_vertical(0.95),
            Some(true)
        );
        assert_eq!(
            point([0.0, 0.0, 1.0], cov).inside_vertical(0.95),
            Some(false)
        );
        let undetermined = PointCheck {
            cov: None,
            ..point([0.0; 3], cov)
        };
        assert_eq!(undetermined.inside_horizontal(0.95), None);
        assert!(point_line(&undetermined, 0.95).contains("undetermined"));
    }
}
