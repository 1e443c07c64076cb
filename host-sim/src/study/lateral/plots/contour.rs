//! Contour lines of a value on a rectangular grid by marching squares
//! (Lorensen & Cline's marching cubes, 1987, in two dimensions): each cell
//! is classified by which of its four corners lie at or above the level,
//! the level's crossings are interpolated linearly along the cell's edges,
//! and the crossings are joined in pairs. A saddle cell (opposite corners
//! above, the other two below) is resolved by the mean of its corners, the
//! usual "asymptotic decider"-free choice. Cells with a non-finite corner
//! give no line (an undetermined value is no number to interpolate).

/// One straight piece of a contour line, (x, y) at both ends.
pub type Segment = [(f64, f64); 2];

/// The segments of the contour `z = level`, `z[i][j]` the value at
/// `(x[i], y[j])`. Rows shorter than `y` (or fewer rows than `x`) are
/// read as missing values.
pub fn contour_segments(x: &[f64], y: &[f64], z: &[Vec<f64>], level: f64) -> Vec<Segment> {
    let mut out = Vec::new();
    if !level.is_finite() {
        return out;
    }
    let at = |i: usize, j: usize| {
        z.get(i)
            .and_then(|row| row.get(j))
            .copied()
            .unwrap_or(f64::NAN)
    };
    for i in 0..x.len().saturating_sub(1) {
        for j in 0..y.len().saturating_sub(1) {
            // corners counter-clockwise from (i, j); edge k joins corner k
            // and corner k + 1
            let c = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)];
            let v = c.map(|(a, b)| at(a, b));
            if v.iter().any(|v| !v.is_finite()) {
                continue;
            }
            let p = c.map(|(a, b)| (x[a], y[b]));
            let above = v.map(|v| v >= level);
            let crossing = |k: usize| {
                let m = (k + 1) % 4;
                (above[k] != above[m]).then(|| {
                    let t = (level - v[k]) / (v[m] - v[k]);
                    (
                        p[k].0 + t * (p[m].0 - p[k].0),
                        p[k].1 + t * (p[m].1 - p[k].1),
                    )
                })
            };
            let e = [crossing(0), crossing(1), crossing(2), crossing(3)];
            let found: Vec<(usize, (f64, f64))> = e
                .iter()
                .enumerate()
                .filter_map(|(k, q)| q.map(|q| (k, q)))
                .collect();
            match found.len() {
                2 => out.push([found[0].1, found[1].1]),
                4 => {
                    let centre = v.iter().sum::<f64>() / 4.0;
                    let (e0, e1, e2, e3) = (found[0].1, found[1].1, found[2].1, found[3].1);
                    if (centre >= level) == above[0] {
                        // corners 0 and 2 joined through the centre: cut
                        // off corner 1 (edges 0, 1) and corner 3 (edges 2, 3)
                        out.push([e0, e1]);
                        out.push([e2, e3]);
                    } else {
                        // cut off corner 0 (edges 3, 0) and corner 2 (1, 2)
                        out.push([e3, e0]);
                        out.push([e1, e2]);
                    }
                }
                _ => {}
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(n: usize, lo: f64, hi: f64) -> Vec<f64> {
        (0..n)
            .map(|k| lo + (hi - lo) * k as f64 / (n - 1) as f64)
            .collect()
    }

    fn values(x: &[f64], y: &[f64], f: impl Fn(f64, f64) -> f64) -> Vec<Vec<f64>> {
        x.iter()
            .map(|&a| y.iter().map(|&b| f(a, b)).collect())
            .collect()
    }

    #[test]
    fn a_plane_is_cut_on_its_exact_line() {
        // z = x + 2 y is linear: the interpolated crossings lie exactly on
        // x + 2 y = 1.3, and the line crosses every cell it enters once
        let (x, y) = (grid(5, 0.0, 1.0), grid(4, 0.0, 1.0));
        let z = values(&x, &y, |a, b| a + 2.0 * b);
        let segs = contour_segments(&x, &y, &z, 1.3);
        assert!(!segs.is_empty());
        for s in &segs {
            for &(a, b) in s {
                assert!((a + 2.0 * b - 1.3).abs() < 1e-12, "({a}, {b})");
                assert!((0.0..=1.0).contains(&a) && (0.0..=1.0).contains(&b));
            }
        }
        // the segments join into one line from y = 0.65 at x = 0 to
        // x = 1 at y = 0.15: the total length is the chord's
        let length: f64 = segs
            .iter()
            .map(|s| (s[1].0 - s[0].0).hypot(s[1].1 - s[0].1))
            .sum();
        assert!((length - 1.0_f64.hypot(0.5)).abs() < 1e-12, "{length}");
    }

    #[test]
    fn a_circle_is_found_at_its_radius() {
        let (x, y) = (grid(41, -2.0, 2.0), grid(41, -2.0, 2.0));
        let z = values(&x, &y, |a, b| a * a + b * b);
        let segs = contour_segments(&x, &y, &z, 1.0);
        // linear interpolation of r^2 over a 0.1 cell: r within 0.01
        for s in &segs {
            for &(a, b) in s {
                assert!((a.hypot(b) - 1.0).abs() < 0.01, "({a}, {b})");
            }
        }
        let length: f64 = segs
            .iter()
            .map(|s| (s[1].0 - s[0].0).hypot(s[1].1 - s[0].1))
            .sum();
        assert!((length - std::f64::consts::TAU).abs() < 0.05, "{length}");
    }

    #[test]
    fn saddles_and_missing_values() {
        let (x, y) = ([0.0, 1.0], [0.0, 1.0]);
        // corners (0,0) and (1,1) above 0.5, the centre (mean 0.6) too:
        // they are joined, the other two corners are cut off
        let z = vec![vec![1.0, 0.0], vec![0.0, 1.4]];
        let segs = contour_segments(&x, &y, &z, 0.5);
        assert_eq!(segs.len(), 2);
        let near = |p: (f64, f64), q: (f64, f64)| (p.0 - q.0).hypot(p.1 - q.1) < 1e-12;
        // corner (1, 0) cut off between (0.5, 0) and (1, 0.5/1.4)
        assert!(near(segs[0][0], (0.5, 0.0)) && near(segs[0][1], (1.0, 0.5 / 1.4)));
        // below the centre: the other pairing
        let segs = contour_segments(&x, &y, &z, 0.65);
        assert_eq!(segs.len(), 2);
        assert!(near(segs[0][1], (0.35, 0.0)), "{:?}", segs[0]);
        // a NaN corner: nothing in that cell; a level outside: nothing
        let z = vec![vec![1.0, 0.0], vec![0.0, f64::NAN]];
        assert!(contour_segments(&x, &y, &z, 0.5).is_empty());
        let z = vec![vec![1.0, 0.0], vec![0.0, 1.0]];
        assert!(contour_segments(&x, &y, &z, 2.0).is_empty());
        assert!(contour_segments(&x, &y, &z, f64::NAN).is_empty());
        // a short row is a missing value, not a panic
        assert!(contour_segments(&x, &y, &[vec![1.0]], 0.5).is_empty());
    }
}
