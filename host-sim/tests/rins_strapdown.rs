//! The error-state simulation of a rotating INS (`host_sim::rins::system`)
//! against the full strapdown mechanization of the same sensor errors
//! (`host_sim::rins::strapdown_check`), short spans for the debug build.

use host_sim::rins::strapdown_check::{compare, Check, System};
use host_sim::rins::Scenario;

fn report(c: &host_sim::rins::strapdown_check::Comparison) {
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
    eprintln!("  end strapdown   {:?}", c.end_strapdown);
    eprintln!("  end error-state {:?}", c.end_error_state);
}

#[test]
fn backup_strapdown_agrees_with_error_state() {
    let s = Scenario::paper();
    let c = compare(&s, &Check::new(System::Backup, 1.0, 10.0, &s)).unwrap();
    report(&c);
}
