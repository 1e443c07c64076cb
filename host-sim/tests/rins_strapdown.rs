//! The error-state simulation of a rotating INS (`host_sim::paper::rins::system`)
//! against the full strapdown mechanization of the same sensor errors and
//! initial attitude error (`host_sim::paper::rins::strapdown_check`). Spans and
//! rates are shortened for the debug build; `host-sim paper rins
//! --strapdown-check` runs the long ones.

use host_sim::paper::rins::strapdown_check::{compare, Check, Comparison, System};
use host_sim::paper::rins::Scenario;

/// Largest difference over the run relative to the largest error, per
/// quantity. Measured ~4e-4 (1 h, 10 Hz): the error model's first-order
/// terms and its mid-second forcing. A drift or bias with the wrong sign,
/// or the rotation left out on one side, makes it order 1.
const TOLERANCE: f64 = 0.01;

fn check(c: &Comparison) {
    eprintln!(
        "{:?} {} h {} Hz: attitude {:.4} of {:.3} arcsec, velocity {:.2e} of {:.3e} m/s, position {:.3} of {:.2} m",
        c.system,
        c.hours,
        c.sample_rate_hz,
        c.attitude_arcsec.max_difference,
        c.attitude_arcsec.max_error,
        c.velocity.max_difference,
        c.velocity.max_error,
        c.position_m.max_difference,
        c.position_m.max_error
    );
    for (what, a) in [
        ("attitude", c.attitude_arcsec),
        ("velocity", c.velocity),
        ("position", c.position_m),
    ] {
        // NaN (a diverged run) fails too
        assert!(a.relative() <= TOLERANCE, "{what}: {a:?}");
    }
}

#[test]
fn backup_strapdown_agrees_with_error_state() {
    let s = Scenario::paper();
    check(&compare(&s, &Check::new(System::Backup, 2.0, 20.0, &s)).unwrap());
}

#[test]
fn master_strapdown_agrees_with_error_state() {
    let s = Scenario::paper();
    check(&compare(&s, &Check::new(System::Master, 2.0, 20.0, &s)).unwrap());
}

#[test]
fn error_free_strapdown_stays_on_the_truth() {
    // The mechanization's own error on this route, the floor of the
    // comparison: far below the sensor-error figures above (27 arcsec,
    // 0.3 m/s, 380 m after 1 h).
    let s = Scenario::paper();
    let mut perfect = Check::new(System::Master, 1.0, 20.0, &s);
    perfect.sensor_errors = false;
    let c = compare(&s, &perfect).unwrap();
    assert_eq!(c.attitude_arcsec.max_error, 0.0);
    // measured at 20 Hz: 0.001 arcsec, 3.7e-4 m/s, 0.03 m (the flips turn
    // g through the body at 0.5 deg per sample; at 100 Hz it is smaller)
    assert!(c.attitude_arcsec.max_difference < 0.01, "{c:?}");
    assert!(c.velocity.max_difference < 1e-3, "{c:?}");
    assert!(c.position_m.max_difference < 0.1, "{c:?}");
}

#[test]
fn refuses_a_route_off_east_west_and_a_bad_rate() {
    let mut s = Scenario::paper();
    let c = Check::new(System::Backup, 0.01, 7.5, &s);
    assert!(compare(&s, &c).is_err());
    s.course_deg = 45.0;
    assert!(compare(&s, &Check::new(System::Backup, 0.01, 10.0, &s)).is_err());
}
