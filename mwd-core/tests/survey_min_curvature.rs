//! Property tests of the minimum curvature survey: exact straight lines,
//! exact circular arcs however finely the stations sample them, the
//! haversine dogleg against the cosine form, small-angle stability,
//! interpolation on the arc, and refusal of bad stations.

use core::f64::consts::{PI, TAU};
use mwd_core::survey::{
    dogleg, positions, ratio_factor, tangent, Segment, SurveyError, SurveyPoint, TieOn, TrueNorth,
    TrueStation,
};
use nalgebra::{Matrix3, Vector3};
use proptest::prelude::*;

/// An exact circular arc: it starts at the origin along t0 and turns
/// towards the unit u (perpendicular to t0) at curvature k (rad/m).
struct Arc {
    t0: Vector3<f64>,
    u: Vector3<f64>,
    k: f64,
}

impl Arc {
    /// inc, az: the start direction; toolface: where u points around it
    /// (0: towards increasing inclination, pi/2: towards increasing azimuth).
    fn new(inc: f64, az: f64, toolface: f64, k: f64) -> Self {
        let t0 = tangent(inc, az);
        let e1 = Vector3::new(inc.cos() * az.cos(), inc.cos() * az.sin(), -inc.sin());
        let e2 = Vector3::new(-az.sin(), az.cos(), 0.0);
        Self {
            t0,
            u: e1 * toolface.cos() + e2 * toolface.sin(),
            k,
        }
    }

    fn direction(&self, s: f64) -> Vector3<f64> {
        self.t0 * (self.k * s).cos() + self.u * (self.k * s).sin()
    }

    /// Position at arc length s: sin(ks)/k t0 + (1 - cos ks)/k u, with
    /// 1 - cos x written 2 sin^2(x/2) to keep its digits.
    fn position(&self, s: f64) -> Vector3<f64> {
        if self.k == 0.0 {
            return self.t0 * s;
        }
        let h = (0.5 * self.k * s).sin();
        self.t0 * ((self.k * s).sin() / self.k) + self.u * (2.0 * h * h / self.k)
    }

    fn station(&self, s: f64) -> TrueStation {
        let t = self.direction(s);
        let inc = t.x.hypot(t.y).atan2(t.z);
        let az = t.y.atan2(t.x);
        TrueStation::new(s, inc, az).unwrap()
    }
}

fn all(tie: &TieOn<TrueNorth>, stations: &[TrueStation]) -> Vec<SurveyPoint<TrueNorth>> {
    positions(tie, stations).map(|p| p.unwrap()).collect()
}

fn angle_between(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    a.cross(b).norm().atan2(a.dot(b))
}

proptest! {
    #[test]
    fn straight_line_is_exact(
        inc in 0.0..=PI, az in 0.0..TAU, steps in prop::collection::vec(0.01..500.0f64, 1..20),
    ) {
        let mut md = 0.0;
        let mut stations = vec![TrueStation::new(0.0, inc, az).unwrap()];
        for step in steps {
            md += step;
            stations.push(TrueStation::new(md, inc, az).unwrap());
        }
        let end = *all(&TieOn::origin(), &stations).last().unwrap();
        prop_assert!((end.nev - tangent(inc, az) * md).norm() < 1e-9);
        let horizontal = end.north().hypot(end.east());
        prop_assert!((end.vertical_section(az) - horizontal).abs() < 1e-9);
    }

    #[test]
    fn circular_arc_is_invariant_to_subdivision(
        inc in 0.0..=PI, az in 0.0..TAU, toolface in 0.0..TAU,
        turn in 1e-9..3.0f64, length in 1.0..3000.0f64,
        cuts in prop::collection::vec(0.0..1.0f64, 0..40),
    ) {
        let arc = Arc::new(inc, az, toolface, turn / length);
        let coarse = [arc.station(0.0), arc.station(length)];
        let mut depths: Vec<f64> = cuts.iter().map(|f| f * length).filter(|&s| s > 0.0).collect();
        depths.push(length);
        depths.sort_by(f64::total_cmp);
        depths.dedup();
        let mut fine = vec![arc.station(0.0)];
        fine.extend(depths.iter().map(|&s| arc.station(s)));

        let tie = TieOn::origin();
        let coarse_end = all(&tie, &coarse)[1].nev;
        let fine_points = all(&tie, &fine);
        prop_assert!((coarse_end - fine_points.last().unwrap().nev).norm() < 1e-9);
        for p in &fine_points {
            let exact = arc.position(p.station.md());
            prop_assert!((p.nev - exact).norm() < 1e-9, "{} m: {:?} vs {:?}", p.station.md(), p.nev, exact);
        }
    }

    #[test]
    fn interpolation_follows_the_arc(
        inc in 0.0..=PI, az in 0.0..TAU, toolface in 0.0..TAU,
        turn in 0.0..3.0f64, length in 1.0..3000.0f64, f in 0.0..=1.0f64,
    ) {
        let arc = Arc::new(inc, az, toolface, turn / length);
        let segment = Segment::new(arc.station(0.0), arc.station(length)).unwrap();
        let s = f * length;
        let (station, chord) = segment.at(s).unwrap();
        prop_assert_eq!(station.md(), s);
        let t = tangent(station.inclination(), station.azimuth());
        prop_assert!(angle_between(&t, &arc.direction(s)) < 1e-12);
        prop_assert!((chord - arc.position(s)).norm() < 1e-9);
    }

    #[test]
    fn haversine_equals_cosine_form_where_well_conditioned(
        i1 in 0.0..=PI, a1 in 0.0..TAU, i2 in 0.0..=PI, a2 in 0.0..TAU,
    ) {
        let c = (i2 - i1).cos() - i1.sin() * i2.sin() * (1.0 - (a2 - a1).cos());
        let cosine = c.clamp(-1.0, 1.0).acos();
        prop_assume!(cosine > 0.05 && cosine < PI - 0.05);
        prop_assert!((dogleg(i1, a1, i2, a2) - cosine).abs() < 1e-12);
    }

    #[test]
    fn tiny_doglegs_are_stable(
        inc in 0.1..3.0f64, az in 0.0..TAU, di in -1e-9..1e-9f64, da in -1e-9..1e-9f64,
    ) {
        let (i2, a2) = (inc + di, az + da);
        // The steps as stored (the sums round), exact by Sterbenz's lemma.
        let (di, da) = (i2 - inc, a2 - az);
        let beta = dogleg(inc, az, i2, a2);
        let expected = (di * di + inc.sin() * i2.sin() * da * da).sqrt();
        prop_assert!(beta.is_finite());
        prop_assert!((beta - expected).abs() <= 1e-6 * expected + 1e-300);
        let rf = ratio_factor(beta);
        prop_assert!((rf - 1.0).abs() < 1e-15);
        let a = TrueStation::new(0.0, inc, az).unwrap();
        let b = TrueStation::new(30.0, inc + di, az + da).unwrap();
        let step = Segment::new(a, b).unwrap().increment();
        prop_assert!(step.iter().all(|x| x.is_finite()));
        prop_assert!((step.norm() - 30.0).abs() < 1e-9);
    }

    #[test]
    fn bad_stations_are_refused(md in -1e6..1e6f64, inc in 0.0..=PI, az in -10.0..10.0f64, back in 0.0..100.0f64) {
        prop_assert_eq!(TrueStation::new(f64::NAN, inc, az), Err(SurveyError::MeasuredDepth));
        prop_assert_eq!(TrueStation::new(md, inc + PI + 1e-9, az), Err(SurveyError::Inclination));
        prop_assert_eq!(TrueStation::new(md, -inc - 1e-9, az), Err(SurveyError::Inclination));
        prop_assert_eq!(TrueStation::new(md, f64::NAN, az), Err(SurveyError::Inclination));
        prop_assert_eq!(TrueStation::new(md, inc, f64::NAN), Err(SurveyError::Azimuth));
        let s = TrueStation::new(md, inc, az).unwrap();
        prop_assert!((0.0..TAU).contains(&s.azimuth()));
        let tie = TieOn::new(md, 0.0, 0.0, 0.0, Matrix3::zeros()).unwrap();
        let stations = [s, TrueStation::new(md - back, inc, az).unwrap()];
        let second = positions(&tie, &stations).nth(1).unwrap();
        prop_assert_eq!(second, Err(SurveyError::DepthNotIncreasing { index: 1 }));
    }
}
