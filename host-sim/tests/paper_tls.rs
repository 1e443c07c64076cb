//! The TLS paper's nine-accelerometer experiment (Ding et al. 2011,
//! section 5): decoupling must remove the coupling drift, and TLS must beat
//! LS when the calibration references carry errors (the paper's claim).
//! Means over 100 seeded runs; the set-up is `Experiment::default()`.

use host_sim::analysis::paper_tls::{monte_carlo, Experiment};

#[test]
fn tls_beats_ls_and_decoupling_removes_the_drift() {
    let exp = Experiment::default();
    for n in [100usize, 200, 500] {
        let [before, tls, ls] = monte_carlo(&exp, 0.001, n, 100, 42).unwrap();
        println!("N = {n}: mean error before {before:.1} %, TLS {tls:.2} %, LS {ls:.2} %");
        assert!(tls < ls, "N = {n}: TLS {tls} % not better than LS {ls} %");
        assert!(
            tls < 10.0,
            "N = {n}: TLS error {tls} % (the paper: under about 8 % for N >= 50)"
        );
        assert!(
            before > 10.0 * tls,
            "N = {n}: decoupling gained little ({before} % -> {tls} %)"
        );
    }
}

#[test]
fn undecoupled_error_grows_with_the_coupling_angle() {
    let exp = Experiment::default();
    let small = monte_carlo(&exp, 0.001, 200, 20, 3).unwrap()[0];
    let large = monte_carlo(&exp, 0.005, 200, 20, 3).unwrap()[0];
    assert!(
        large > 3.0 * small,
        "before decoupling: {small} % at 0.001 rad, {large} % at 0.005 rad"
    );
}
