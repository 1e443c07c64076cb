//! Anti-collision: for each station of the reference well, the closest
//! point on an offset well, the centre-to-centre distance and the ISCWSA
//! separation factor.
//!
//! The rule (ISCWSA Collision Avoidance Work Group; Sawaryn, S. J., Wilson,
//! H., Bang, J., Nyrnes, E., Sentance, A., Poedjono, B., Lowdon, R.,
//! Mitchell, I., Codling, J., Clark, P. J. and Allen, W. T., "Well-Collision-
//! Avoidance Separation Rule", SPE Drilling & Completion 34 (1), 2019,
//! pp. 1-15, SPE-187073-PA):
//!
//! ```text
//! SF = (D - R_ref - R_off - S_m) / (k * sqrt(sigma_S^2 + sigma_pa^2))
//! sigma_S^2 = u^T C_ref u + u^T C_off u
//! ```
//!
//! D the centre-to-centre distance, u its unit vector, C the two wells' NEV
//! covariances (1-sigma, m^2; the wells' errors taken as uncorrelated),
//! R the open-hole radii, S_m the surface margin (0.3 m), sigma_pa the
//! 1-sigma project-ahead uncertainty of the reference well (0.5 m, a sphere)
//! and k = 3.5 the dimensionless scaling factor. SF < 1 is a violation of
//! the rule. The constants are the paper's recommended values as
//! transcribed (with the variable definitions) in the open-source welleng
//! package (`welleng/clearance.py`, `Clearance`/`ISCWSA`), which cites the
//! paper above; the paper itself was not available here, so its equation
//! numbers are not given. With `sigma_pa = 0` the expression reduces to the
//! simpler `(D - R_ref - R_off - S_m) / (k sigma_S)`.
//!
//! Closest point: minimum-curvature interpolation along each offset arc
//! (`mwd_core::survey::Segment::at`), minimised by golden-section search per
//! arc (on an arc shorter than a half circle the distance to a point has at
//! most one interior extremum, so the search plus the two end points finds
//! the minimum); arcs that cannot hold a closer point than the best so far
//! are skipped (no point of an arc is further than its length from its
//! start).
//!
//! Offset covariance at the closest point: linear interpolation in MD
//! between the covariances of the arc's two stations (a convex combination
//! of covariances, so still a covariance). The exact value would need the
//! error model run with a station inserted there; between stations 30 m
//! apart the difference is second order in the station spacing. Where
//! either end has no covariance (beyond the model's validity) the SF is
//! undetermined.

use super::Row;
use crate::survey::iscwsa::{cov_matrix, Cov6};
use anyhow::{anyhow, bail, Result};
use mwd_core::survey::{Segment, Station, TrueNorth};
use nalgebra::Vector3;

/// The rule's constants (Sawaryn et al. 2019, see the module notes).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rule {
    /// Dimensionless scaling factor k.
    pub k: f64,
    /// Surface margin S_m, m.
    pub surface_margin_m: f64,
    /// Project-ahead 1-sigma uncertainty sigma_pa, m.
    pub sigma_pa_m: f64,
    /// Open-hole radius of the reference well, m.
    pub ref_radius_m: f64,
    /// Open-hole radius of the offset well, m.
    pub offset_radius_m: f64,
}

/// k of the rule.
pub const K: f64 = 3.5;
/// S_m of the rule, m.
pub const SURFACE_MARGIN_M: f64 = 0.3;
/// sigma_pa of the rule, m.
pub const SIGMA_PA_M: f64 = 0.5;

/// The closest point of the offset well to one point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Closest {
    /// MD of the point on the offset well, m.
    pub md_m: f64,
    /// Its (north, east, TVD), m.
    pub nev: Vector3<f64>,
    /// Its covariance (interpolated in MD), if both arc ends have one.
    pub cov: Option<Cov6>,
}

/// One reference station's separation from the offset well.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Separation {
    pub closest: Closest,
    /// Centre-to-centre distance D, m.
    pub ctc_m: f64,
    /// sigma_S: 1-sigma of D from both wells' covariances, m (undetermined
    /// without both covariances).
    pub sigma_s_m: Option<f64>,
    /// Separation factor (undetermined without both covariances).
    pub sf: Option<f64>,
}

fn nev(r: &Row) -> Vector3<f64> {
    Vector3::new(r.north_m, r.east_m, r.tvd_m)
}

fn station(r: &Row) -> Result<Station<TrueNorth>> {
    // the rows' angles went through degrees: clamp the rounding at 180
    let inc = r.inc_deg.to_radians().clamp(0.0, std::f64::consts::PI);
    Station::new(r.md_m, inc, r.azi_deg.to_radians())
        .map_err(|e| anyhow!("offset station at MD {} m: {e}", r.md_m))
}

fn lerp_cov(a: &Cov6, b: &Cov6, f: f64) -> Cov6 {
    let mut c = [0.0; 6];
    for i in 0..6 {
        c[i] = a[i] + f * (b[i] - a[i]);
    }
    c
}

/// The point of the arc `from`..`to` closest to `p`: (MD, position,
/// squared distance).
fn closest_on_arc(from: &Row, to: &Row, p: &Vector3<f64>) -> Result<(f64, Vector3<f64>, f64)> {
    let seg = Segment::new(station(from)?, station(to)?)
        .map_err(|e| anyhow!("offset arc MD {} to {} m: {e}", from.md_m, to.md_m))?;
    let start = nev(from);
    let at = |md: f64| -> Result<(Vector3<f64>, f64)> {
        let (_, chord) = seg
            .at(md)
            .map_err(|e| anyhow!("offset arc at MD {md} m: {e}"))?;
        let x = start + chord;
        Ok((x, (x - p).norm_squared()))
    };
    // golden-section search on [a, b]
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let (mut a, mut b) = (from.md_m, to.md_m);
    let mut c = b - g * (b - a);
    let mut d = a + g * (b - a);
    let (mut fc, mut fd) = (at(c)?.1, at(d)?.1);
    for _ in 0..80 {
        if b - a <= 1e-9 * (1.0 + b.abs()) {
            break;
        }
        if fc < fd {
            (b, d, fd) = (d, c, fc);
            c = b - g * (b - a);
            fc = at(c)?.1;
        } else {
            (a, c, fc) = (c, d, fd);
            d = a + g * (b - a);
            fd = at(d)?.1;
        }
    }
    let mid = 0.5 * (a + b);
    let mut best = (mid, at(mid)?);
    for md in [from.md_m, to.md_m] {
        let v = at(md)?;
        if v.1 < best.1 .1 {
            best = (md, v);
        }
    }
    Ok((best.0, best.1 .0, best.1 .1))
}

/// The point of the offset well (minimum curvature between its stations)
/// closest to `p`, with its covariance interpolated in MD.
pub fn closest_point(p: &Vector3<f64>, offset: &[Row]) -> Result<Closest> {
    let Some(first) = offset.first() else {
        bail!("the offset well has no stations");
    };
    // start from the nearest station: an upper bound for the arc pruning
    let (mut best_md, mut best_x, mut best_d2, mut best_cov) = (
        first.md_m,
        nev(first),
        (nev(first) - p).norm_squared(),
        first.cov,
    );
    for r in offset {
        let d2 = (nev(r) - p).norm_squared();
        if d2 < best_d2 {
            (best_md, best_x, best_d2, best_cov) = (r.md_m, nev(r), d2, r.cov);
        }
    }
    for pair in offset.windows(2) {
        let (from, to) = (&pair[0], &pair[1]);
        let reach = to.md_m - from.md_m;
        let lower = (nev(from) - p).norm() - reach;
        if lower > 0.0 && lower * lower >= best_d2 {
            continue;
        }
        let (md, x, d2) = closest_on_arc(from, to, p)?;
        if d2 < best_d2 {
            let f = (md - from.md_m) / reach;
            let cov = match (&from.cov, &to.cov) {
                (Some(a), Some(b)) => Some(lerp_cov(a, b, f)),
                _ => None,
            };
            (best_md, best_x, best_d2, best_cov) = (md, x, d2, cov);
        }
    }
    Ok(Closest {
        md_m: best_md,
        nev: best_x,
        cov: best_cov,
    })
}

/// sigma_S and SF for centre-to-centre vector `d` (reference to offset)
/// and the two covariances. At D = 0 the direction is undefined: the
/// largest combined variance (any direction) is used, which cannot raise
/// the factor of an already negative numerator above that of any direction.
pub fn factor(d: &Vector3<f64>, c_ref: &Cov6, c_off: &Cov6, rule: &Rule) -> (f64, f64) {
    let sum = cov_matrix(c_ref) + cov_matrix(c_off);
    let dist = d.norm();
    let var_s = if dist > 0.0 {
        let u = d / dist;
        (u.transpose() * sum * u)[(0, 0)]
    } else {
        sum.symmetric_eigenvalues().max()
    }
    .max(0.0);
    let sigma_s = var_s.sqrt();
    let num = dist - rule.ref_radius_m - rule.offset_radius_m - rule.surface_margin_m;
    let den = rule.k * (var_s + rule.sigma_pa_m * rule.sigma_pa_m).sqrt();
    (sigma_s, num / den)
}

/// The separation of every reference station from the offset well.
pub fn separations(reference: &[Row], offset: &[Row], rule: &Rule) -> Result<Vec<Separation>> {
    reference
        .iter()
        .map(|r| {
            let p = nev(r);
            let closest = closest_point(&p, offset)?;
            let d = closest.nev - p;
            let (sigma_s_m, sf) = match (&r.cov, &closest.cov) {
                (Some(a), Some(b)) => {
                    let (s, f) = factor(&d, a, b, rule);
                    (Some(s), Some(f))
                }
                _ => (None, None),
            };
            Ok(Separation {
                closest,
                ctc_m: d.norm(),
                sigma_s_m,
                sf,
            })
        })
        .collect()
}

/// The smallest determined SF and the index of its station.
pub fn minimum(seps: &[Separation]) -> Option<(usize, f64)> {
    seps.iter()
        .enumerate()
        .filter_map(|(i, s)| s.sf.map(|f| (i, f)))
        .min_by(|a, b| a.1.total_cmp(&b.1))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::survey::listing::{InputStation, Row};

    fn row(md: f64, inc_deg: f64, azi_deg: f64, n: f64, e: f64, v: f64, cov: Option<Cov6>) -> Row {
        Row {
            input: InputStation {
                md,
                inc_deg,
                azi_deg,
                toolface_deg: None,
                time_s: None,
            },
            md_m: md,
            inc_deg,
            azi_deg,
            tvd_m: v,
            north_m: n,
            east_m: e,
            dls_deg_per_30m: 0.0,
            vsec_m: 0.0,
            cov,
        }
    }

    fn rule() -> Rule {
        Rule {
            k: K,
            surface_margin_m: SURFACE_MARGIN_M,
            sigma_pa_m: SIGMA_PA_M,
            ref_radius_m: 0.2,
            offset_radius_m: 0.15,
        }
    }

    /// Five stations 100 m apart down a vertical well `north_m` north of
    /// the origin, each with the covariance `cov`.
    fn vertical_well(north_m: f64, cov: Cov6) -> Vec<Row> {
        (0..5)
            .map(|i| {
                let md = 100.0 * f64::from(i);
                row(md, 0.0, 0.0, north_m, 0.0, md, Some(cov))
            })
            .collect()
    }

    #[test]
    fn parallel_vertical_wells_hand_computed() {
        // reference at the origin, offset 10 m north; both vertical
        let c_ref = [4.0, 1.0, 9.0, 0.5, 0.0, 0.0];
        let c_off = [2.25, 3.0, 16.0, -0.5, 0.0, 0.0];
        let reference = vertical_well(0.0, c_ref);
        let offset = vertical_well(10.0, c_off);
        let seps = separations(&reference, &offset, &rule()).unwrap();
        for (r, s) in reference.iter().zip(&seps) {
            assert!((s.ctc_m - 10.0).abs() < 1e-9, "{}", s.ctc_m);
            assert!((s.closest.md_m - r.md_m).abs() < 1e-6);
            // along north: sigma_S^2 = nn_ref + nn_off = 4 + 2.25 = 6.25
            assert!((s.sigma_s_m.unwrap() - 2.5).abs() < 1e-12);
            // (10 - 0.2 - 0.15 - 0.3) / (3.5 sqrt(6.25 + 0.25)) = 9.35 / 8.9233
            let sf = 9.35 / (3.5 * 6.5f64.sqrt());
            assert!((s.sf.unwrap() - sf).abs() < 1e-9, "{:?} vs {sf}", s.sf);
            assert!((sf - 1.047_820).abs() < 1e-6);
        }
        // 6 m apart the rule is violated: (6 - 0.65) / 8.9233 = 0.5996
        let near: Vec<Row> = offset.iter().map(|r| Row { north_m: 6.0, ..*r }).collect();
        let seps = separations(&reference, &near, &rule()).unwrap();
        let (_, min) = minimum(&seps).unwrap();
        assert!((min - 5.35 / (3.5 * 6.5f64.sqrt())).abs() < 1e-9);
        assert!(min < 1.0);
    }

    #[test]
    fn no_covariance_is_undetermined() {
        let reference = [row(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, Some([1.0; 6]))];
        let offset = [
            row(
                0.0,
                0.0,
                0.0,
                5.0,
                0.0,
                0.0,
                Some([1.0, 1.0, 1.0, 0.0, 0.0, 0.0]),
            ),
            row(100.0, 0.0, 0.0, 5.0, 0.0, 100.0, None),
        ];
        let seps = separations(&reference, &offset, &rule()).unwrap();
        // closest is the first station exactly: its covariance is known
        assert!(seps[0].sf.is_some());
        let reference = [row(50.0, 0.0, 0.0, 0.0, 0.0, 50.0, Some([1.0; 6]))];
        let seps = separations(&reference, &offset, &rule()).unwrap();
        assert!((seps[0].closest.md_m - 50.0).abs() < 1e-6);
        assert!((seps[0].ctc_m - 5.0).abs() < 1e-9);
        assert_eq!(seps[0].sf, None);
        assert_eq!(seps[0].sigma_s_m, None);
        assert_eq!(minimum(&seps), None);
    }

    #[test]
    fn closest_point_on_a_build_arc() {
        // a quarter circle of radius R in the north-vertical plane, from
        // vertical at the origin to horizontal north: the point at angle t
        // is (N, V) = R (1 - cos t, sin t), centre (R, 0), MD = R t.
        let r = 30.0 / 3f64.to_radians(); // 3 deg/30 m
        let end_md = r * std::f64::consts::FRAC_PI_2;
        // a mid station keeps each arc under a half circle either way
        let mid_md = 0.5 * end_md;
        let mid_t = std::f64::consts::FRAC_PI_4;
        let offset = [
            row(
                0.0,
                0.0,
                0.0,
                0.0,
                0.0,
                0.0,
                Some([1.0, 1.0, 1.0, 0.0, 0.0, 0.0]),
            ),
            row(
                mid_md,
                45.0,
                0.0,
                r * (1.0 - mid_t.cos()),
                0.0,
                r * mid_t.sin(),
                Some([3.0, 3.0, 3.0, 0.0, 0.0, 0.0]),
            ),
            row(
                end_md,
                90.0,
                0.0,
                r,
                0.0,
                r,
                Some([5.0, 5.0, 5.0, 0.0, 0.0, 0.0]),
            ),
        ];
        for (t_deg, dist) in [(30.0f64, 20.0), (30.0, -20.0), (70.0, 5.0), (10.0, -100.0)] {
            let t = t_deg.to_radians();
            // outwards from the centre (dist > 0) or inwards
            let radial = Vector3::new(-t.cos(), 0.0, t.sin());
            let on_arc = Vector3::new(r * (1.0 - t.cos()), 0.0, r * t.sin());
            let p = on_arc + dist * radial;
            let c = closest_point(&p, &offset).unwrap();
            assert!(
                (c.md_m - r * t).abs() < 1e-4,
                "t {t_deg}: md {} vs {}",
                c.md_m,
                r * t
            );
            // golden-section search places a quadratic minimum to about
            // sqrt(machine epsilon) of the MD scale: ~1e-5 m here; the
            // distance itself is second order in that
            assert!((c.nev - on_arc).norm() < 1e-4, "t {t_deg}: {:?}", c.nev);
            assert!(((c.nev - p).norm() - dist.abs()).abs() < 1e-8);
            // covariance interpolated linearly in MD within its arc
            let (a, b, m0, m1) = if r * t <= mid_md {
                (1.0, 3.0, 0.0, mid_md)
            } else {
                (3.0, 5.0, mid_md, end_md)
            };
            let want = a + (b - a) * (c.md_m - m0) / (m1 - m0);
            assert!((c.cov.unwrap()[0] - want).abs() < 1e-9);
        }
        // beyond the end: the end station
        let p = Vector3::new(r + 50.0, 0.0, r);
        let c = closest_point(&p, &offset).unwrap();
        assert!((c.md_m - end_md).abs() < 1e-6);
    }

    #[test]
    fn coincident_centres_use_the_largest_variance() {
        let (s, f) = factor(
            &Vector3::zeros(),
            &[1.0, 4.0, 2.0, 0.0, 0.0, 0.0],
            &[0.0; 6],
            &rule(),
        );
        assert!((s - 2.0).abs() < 1e-12);
        assert!(f < 0.0);
    }
}
