//! `study rins-probe` (issue 17 item 4): one short seeded lateral, the
//! reference heading at the first two stations, then lost.
use host_sim::sim::Plan;
use host_sim::study::rins_probe::{run, ProbeConfig, GRADES};

/// The 100 m lateral drilled fast with short stills: the window station,
/// three connections and TD in ~35 simulated minutes.
fn short_plan() -> host_sim::sim::BuiltPlan {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/data/plans/lateral-100m.json");
    let text = std::fs::read_to_string(path).expect("the plan file");
    let mut plan: Plan = serde_json::from_str(&text).expect("a plan");
    plan.drilling.rop_m_per_h = 300.0;
    plan.drilling.initial_still_s = 120.0;
    plan.drilling.connection_still_s = 120.0;
    plan.build().expect("a valid plan")
}

#[test]
fn the_reference_bounds_the_azimuth_and_its_loss_is_not_hidden() {
    let sigma = 0.5f64.to_radians();
    let config = ProbeConfig {
        plan: short_plan(),
        tie_in_azimuth_sigma: sigma,
        reference_sigma: sigma,
        reference_stations: 2,
        grade: GRADES[0],
        white_noise_kept: false,
    };
    let outcome = run(&config, 7).expect("the run");
    assert!(outcome.stations >= 4, "{outcome:?}");
    assert_eq!(outcome.references_applied, 2, "{outcome:?}");
    // Just after the last reference update the filter cannot know the
    // azimuth worse than the reference alone, and its error is inside 3
    // sigma of what it reports.
    let last = outcome.last_reference.expect("an update");
    let s = last.sigma.expect("a determined azimuth");
    assert!(s <= sigma, "{last:?}");
    assert!(last.error.abs() <= 3.0 * s, "{last:?}");
    // At TD, stations after the loss: the aided navigator reports a sigma
    // that covers its error; the unaided one's is not smaller (or it
    // withholds the azimuth as undetermined).
    let with = outcome.with.expect("the aided navigator at TD");
    let without = outcome.without.expect("the unaided navigator at TD");
    let s_with = with.sigma.expect("aided TD azimuth determined");
    assert!(s_with > s, "the sigma must grow after the loss: {with:?}");
    assert!(with.error.abs() <= 3.0 * s_with, "{with:?}");
    if let Some(s_without) = without.sigma {
        assert!(s_without >= s_with, "{without:?} vs {with:?}");
    }
}
