extern crate std;

use super::*;
use crate::conventions::DEG;
use core::f64::consts::{FRAC_PI_2, PI};
use nalgebra::{Matrix3, Vector3};

fn st(md: f64, inc_deg: f64, az_deg: f64) -> TrueStation {
    TrueStation::new(md, inc_deg * DEG, az_deg * DEG).unwrap()
}

fn last(tie: &TieOn<TrueNorth>, stations: &[TrueStation]) -> SurveyPoint<TrueNorth> {
    let mut out = None;
    for p in positions(tie, stations) {
        out = Some(p.unwrap());
    }
    out.unwrap()
}

#[test]
fn straight_line_is_exact() {
    let stations = [
        st(100.0, 30.0, 40.0),
        st(250.0, 30.0, 40.0),
        st(400.0, 30.0, 40.0),
    ];
    let tie = TieOn::new(100.0, 90.0, 5.0, -3.0, Matrix3::zeros()).unwrap();
    let end = last(&tie, &stations);
    let expected = Vector3::new(5.0, -3.0, 90.0) + tangent(30.0 * DEG, 40.0 * DEG) * 300.0;
    assert!((end.nev - expected).norm() < 1e-12, "{:?}", end.nev);
    assert_eq!(end.dls_deg_per_30m, 0.0);
}

/// drillingformulas.com, "Minimum Curvature Method" (after Lyons,
/// Formulas and Calculations for Drilling, Production and Workover):
/// 3500 ft, 15 deg, 20 deg to 3600 ft, 25 deg, 45 deg gives a dogleg of
/// 0.22605 rad and N 27.22 ft, E 19.45 ft, TVD 94.01 ft. (Its printed
/// RF of 1.00408 does not reproduce its own N/E/TVD; 2/beta tan(beta/2) =
/// 1.00428 does.) The method is unit-free, so feet in, feet out.
#[test]
fn published_example_drillingformulas() {
    let stations = [st(3500.0, 15.0, 20.0), st(3600.0, 25.0, 45.0)];
    let segment = Segment::new(stations[0], stations[1]).unwrap();
    assert!((segment.dogleg() - 0.22605).abs() < 5e-6);
    assert!((ratio_factor(segment.dogleg()) - 1.00428).abs() < 5e-6);
    let d = segment.increment();
    assert!((d.x - 27.22).abs() < 0.005, "north {}", d.x);
    assert!((d.y - 19.45).abs() < 0.005, "east {}", d.y);
    assert!((d.z - 94.01).abs() < 0.005, "tvd {}", d.z);
}

#[test]
fn quarter_circle_build_matches_the_arc() {
    // Vertical to horizontal due east over a radius R: E = R, TVD = R.
    let r = 300.0;
    let stations = [st(0.0, 0.0, 90.0), st(FRAC_PI_2 * r, 90.0, 90.0)];
    let end = last(&TieOn::origin(), &stations);
    assert!(
        (end.nev - Vector3::new(0.0, r, r)).norm() < 1e-9,
        "{:?}",
        end.nev
    );
    let segment = Segment::new(stations[0], stations[1]).unwrap();
    let (mid, chord) = segment.at(FRAC_PI_2 * r / 2.0).unwrap();
    assert!((mid.inclination() - 45.0 * DEG).abs() < 1e-14);
    assert!((mid.azimuth() - 90.0 * DEG).abs() < 1e-14);
    let s = libm::sqrt(0.5);
    assert!((chord - Vector3::new(0.0, r * (1.0 - s), r * s)).norm() < 1e-9);
}

#[test]
fn tiny_dogleg_is_stable() {
    let a = st(0.0, 40.0, 10.0);
    let b = TrueStation::new(10.0, 40.0 * DEG + 1e-9, 10.0 * DEG).unwrap();
    let beta = dogleg(a.inclination(), a.azimuth(), b.inclination(), b.azimuth());
    assert!((beta - 1e-9).abs() < 1e-15, "{beta}");
    assert_eq!(ratio_factor(beta), 1.0);
    assert_eq!(ratio_factor(0.0), 1.0);
    let segment = Segment::new(a, b).unwrap();
    assert!(segment.increment().iter().all(|x| x.is_finite()));
    let (mid, _) = segment.at(5.0).unwrap();
    assert!(mid.inclination().is_finite() && mid.azimuth().is_finite());
    // Series and closed form meet at the threshold.
    let t = SERIES_THRESHOLD;
    let closed = libm::tan(0.5 * t) / (0.5 * t);
    assert!((ratio_factor(t * (1.0 - 1e-12)) - closed).abs() < 1e-15);
}

#[test]
fn vertical_section_and_dogleg_severity() {
    let stations = [
        st(0.0, 0.0, 0.0),
        st(1.0, 60.0, 135.0),
        st(501.0, 60.0, 135.0),
    ];
    let end = last(&TieOn::origin(), &stations);
    let horizontal = libm::hypot(end.north(), end.east());
    assert!((end.vertical_section(135.0 * DEG) - horizontal).abs() < 1e-9);
    assert!(end.vertical_section(45.0 * DEG).abs() < 1e-9);
    assert!((dogleg_severity_deg_per_30m(3.0 * DEG, 30.0) - 3.0).abs() < 1e-12);
    assert!((dogleg_severity_deg_per_100ft(3.0 * DEG, 30.48) - 3.0).abs() < 1e-12);
}

#[test]
fn interpolation_at_a_station_returns_it() {
    let (a, b) = (st(1000.0, 12.3, 350.0), st(1030.0, 17.9, 8.5));
    let segment = Segment::new(a, b).unwrap();
    assert_eq!(segment.at(1000.0).unwrap(), (a, Vector3::zeros()));
    assert_eq!(segment.at(1030.0).unwrap(), (b, segment.increment()));
    assert_eq!(segment.at(1030.1), Err(SurveyError::InterpolationDepth));
    assert_eq!(segment.at(f64::NAN), Err(SurveyError::InterpolationDepth));
}

#[test]
fn bad_inputs_are_errors() {
    assert_eq!(
        TrueStation::new(f64::NAN, 0.0, 0.0),
        Err(SurveyError::MeasuredDepth)
    );
    assert_eq!(
        TrueStation::new(f64::INFINITY, 0.0, 0.0),
        Err(SurveyError::MeasuredDepth)
    );
    assert_eq!(
        TrueStation::new(0.0, -1e-12, 0.0),
        Err(SurveyError::Inclination)
    );
    assert_eq!(
        TrueStation::new(0.0, PI + 1e-12, 0.0),
        Err(SurveyError::Inclination)
    );
    assert_eq!(
        TrueStation::new(0.0, f64::NAN, 0.0),
        Err(SurveyError::Inclination)
    );
    assert_eq!(
        TrueStation::new(0.0, 0.0, f64::NAN),
        Err(SurveyError::Azimuth)
    );
    assert_eq!(
        TrueStation::new(0.0, 0.0, -f64::INFINITY),
        Err(SurveyError::Azimuth)
    );
    assert!(TrueStation::new(0.0, PI, -1.0).unwrap().azimuth() < 2.0 * PI);
    assert_eq!(GridConvergence::new(2.0), Err(SurveyError::Convergence));
    assert_eq!(
        GridConvergence::new(f64::NAN),
        Err(SurveyError::Convergence)
    );
    let mut skewed = Matrix3::identity();
    skewed[(0, 1)] = 0.1;
    let bad_cov = TieOn::<TrueNorth>::new(0.0, 0.0, 0.0, 0.0, skewed);
    assert_eq!(bad_cov, Err(SurveyError::TieOnCovariance));
    let bad_pos = TieOn::<TrueNorth>::new(0.0, f64::NAN, 0.0, 0.0, Matrix3::zeros());
    assert_eq!(bad_pos, Err(SurveyError::TieOnPosition));

    let tie = TieOn::origin();
    let repeated = [
        st(0.0, 1.0, 0.0),
        st(10.0, 2.0, 0.0),
        st(10.0, 3.0, 0.0),
        st(20.0, 3.0, 0.0),
    ];
    let items: std::vec::Vec<_> = positions(&tie, &repeated).collect();
    assert_eq!(items.len(), 3, "the iterator ends after an error");
    assert_eq!(items[2], Err(SurveyError::DepthNotIncreasing { index: 2 }));
    let shallower = [st(0.0, 1.0, 0.0), st(-5.0, 2.0, 0.0)];
    let err = positions(&tie, &shallower).nth(1).unwrap();
    assert_eq!(err, Err(SurveyError::DepthNotIncreasing { index: 1 }));
    let off = [st(1.0, 1.0, 0.0)];
    assert_eq!(
        positions(&tie, &off).next().unwrap(),
        Err(SurveyError::TieOnDepth)
    );
    let opposite = [st(0.0, 90.0, 0.0), st(10.0, 90.0, 180.0)];
    let err = positions(&tie, &opposite).nth(1).unwrap();
    assert_eq!(err, Err(SurveyError::OppositeDirections { index: 1 }));
}

#[test]
fn messages_name_the_field_and_range() {
    use std::string::ToString;
    let inclination = SurveyError::Inclination.to_string();
    assert!(inclination.contains("inclination") && inclination.contains("0 to pi"));
    let depth = SurveyError::DepthNotIncreasing { index: 3 }.to_string();
    assert!(depth.contains("station 3") && depth.contains("station 2"));
    let _: &dyn core::error::Error = &SurveyError::Azimuth;
}

#[test]
fn grid_and_true_north_agree() {
    let c = GridConvergence::new(1.7 * DEG).unwrap();
    assert!((c.grid_azimuth(1.0 * DEG) - (359.3 * DEG)).abs() < 1e-12);
    let stations = [
        st(500.0, 20.0, 30.0),
        st(530.0, 24.0, 33.0),
        st(560.0, 29.0, 37.0),
    ];
    let mut cov = Matrix3::from_diagonal(&Vector3::new(4.0, 1.0, 0.25));
    cov[(0, 1)] = 0.5;
    cov[(1, 0)] = 0.5;
    let tie = TieOn::new(500.0, 480.0, 12.0, -7.0, cov).unwrap();
    let grid_stations = stations.map(|s| s.to_grid(c));
    let grid_tie = tie.to_grid(c);
    let back = grid_tie.to_true(c);
    assert!((back.nev() - tie.nev()).norm() < 1e-12);
    assert!((back.covariance() - tie.covariance()).norm() < 1e-12);
    let end_true = last(&tie, &stations);
    let mut end_grid = None;
    for p in positions(&grid_tie, &grid_stations) {
        end_grid = Some(p.unwrap());
    }
    let end_grid = end_grid.unwrap();
    let back = TieOn::<GridNorth>::new(
        0.0,
        end_grid.tvd(),
        end_grid.north(),
        end_grid.east(),
        Matrix3::zeros(),
    )
    .unwrap()
    .to_true(c);
    assert!((back.nev() - end_true.nev).norm() < 1e-9);
    for (s, g) in stations.iter().zip(&grid_stations) {
        assert!((g.to_true(c).azimuth() - s.azimuth()).abs() < 1e-12);
    }
}

#[test]
fn interpolation_along_a_survey() {
    let tie = TieOn::new(100.0, 99.0, 1.0, 2.0, Matrix3::zeros()).unwrap();
    let stations = [
        st(100.0, 5.0, 10.0),
        st(130.0, 9.0, 20.0),
        st(160.0, 14.0, 25.0),
    ];
    let points: std::vec::Vec<_> = positions(&tie, &stations).map(Result::unwrap).collect();
    for p in &points {
        assert_eq!(interpolate(&tie, &stations, p.station.md()).unwrap(), *p);
    }
    let mid = interpolate(&tie, &stations, 145.0).unwrap();
    let segment = Segment::new(stations[1], stations[2]).unwrap();
    let (station, chord) = segment.at(145.0).unwrap();
    assert_eq!(mid.station, station);
    assert_eq!(mid.nev, points[1].nev + chord);
    assert_eq!(
        interpolate(&tie, &stations, 99.9),
        Err(SurveyError::InterpolationDepth)
    );
    assert_eq!(
        interpolate(&tie, &stations, 160.1),
        Err(SurveyError::InterpolationDepth)
    );
    assert_eq!(
        interpolate(&tie, &stations, f64::NAN),
        Err(SurveyError::InterpolationDepth)
    );
}

#[test]
fn dogleg_near_180_deg_keeps_its_digits() {
    for eps in [1e-3, 1e-5, 1e-7] {
        // Horizontal north, then back down-south eps short of opposite.
        let (i1, a1, i2, a2) = (FRAC_PI_2, 0.0, FRAC_PI_2 + eps, PI);
        let (t1, t2) = (tangent(i1, a1), tangent(i2, a2));
        let reference = t1.cross(&t2).norm().atan2(t1.dot(&t2));
        let beta = dogleg(i1, a1, i2, a2);
        assert!(((PI - beta) - (PI - reference)).abs() < 1e-9 * eps, "{eps}");
    }
}
