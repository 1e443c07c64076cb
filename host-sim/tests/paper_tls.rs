//! The TLS paper's nine-accelerometer experiment (Ding et al. 2011,
//! section 5): decoupling must remove the coupling drift, and TLS must beat
//! LS when the calibration references carry errors (the paper's claim).
//! Paired over 400 seeded runs (TLS and LS on the same data); the set-up is
//! `Experiment::default()`, both of the paper's coupling angles.
//!
//! What holds here: TLS beats LS by a margin of more than two standard
//! errors for every N from 20 up (the paper's N = 50 .. 500 and N = 20),
//! at both angles. At N = 10 it does not: the two mean errors (~12 %) are
//! equal within their noise (over 1000 runs LS - TLS = 0.14 +- 0.19 percent
//! points, TLS better in 52 % of runs), so that is what is asserted there.

use host_sim::paper::tls::{error_percent, monte_carlo, run_once, Experiment};

const RUNS: u64 = 400;
const ANGLES: [f64; 2] = [0.001, 0.005];

/// Means over paired runs, errors in percent.
struct Paired {
    before: f64,
    tls: f64,
    ls: f64,
    /// Mean of LS minus TLS error, run by run, and its standard error.
    ls_minus_tls: f64,
    standard_error: f64,
}

fn paired(exp: &Experiment, angle: f64, n: usize) -> Paired {
    let (mut before, mut tls, mut ls, mut d) = (0.0, 0.0, 0.0, Vec::new());
    for r in 0..RUNS {
        let row = run_once(exp, angle, n, 42 * 1_000_003 + r).unwrap();
        let t = error_percent(row.after_tls, row.true_rate);
        let l = error_percent(row.after_ls, row.true_rate);
        before += error_percent(row.before, row.true_rate) / RUNS as f64;
        tls += t / RUNS as f64;
        ls += l / RUNS as f64;
        d.push(l - t);
    }
    let mean = d.iter().sum::<f64>() / d.len() as f64;
    let var = d.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (d.len() - 1) as f64;
    let p = Paired {
        before,
        tls,
        ls,
        ls_minus_tls: mean,
        standard_error: (var / d.len() as f64).sqrt(),
    };
    println!(
        "{angle} rad, N = {n}: mean error before {:.1} %, TLS {:.2} %, LS {:.2} %; LS - TLS {:.2} +- {:.2}",
        p.before, p.tls, p.ls, p.ls_minus_tls, p.standard_error
    );
    p
}

#[test]
fn tls_beats_ls_and_decoupling_removes_the_drift() {
    let exp = Experiment::default();
    for n in [20usize, 50, 100, 150, 200, 300, 400, 500] {
        let at: Vec<Paired> = ANGLES.iter().map(|&a| paired(&exp, a, n)).collect();
        for (angle, p) in ANGLES.iter().zip(&at) {
            let tag = format!("{angle} rad, N = {n}");
            assert!(
                p.ls_minus_tls > 2.0 * p.standard_error,
                "{tag}: TLS {} % not better than LS {} % (LS - TLS {} +- {})",
                p.tls,
                p.ls,
                p.ls_minus_tls,
                p.standard_error
            );
            // At N = 300 the true rate, 0.005 sin 3, is near a zero crossing
            // (0.0007 rad/s): the same absolute error is ~30 % of it.
            let bound = if n == 300 { 40.0 } else { 10.0 };
            assert!(
                p.tls < bound,
                "{tag}: TLS error {} % (the paper: under about 8 % for N >= 50)",
                p.tls
            );
            assert!(
                p.before > 10.0 * p.tls,
                "{tag}: decoupling gained little ({} % -> {} %)",
                p.before,
                p.tls
            );
        }
        // Decoupled, the coupling angle is gone: five times the angle leaves
        // the remaining error as it was.
        assert!(
            (at[1].tls - at[0].tls).abs() < 0.01 * at[0].tls,
            "N = {n}: TLS {} % at 0.001 rad, {} % at 0.005 rad",
            at[0].tls,
            at[1].tls
        );
    }
}

#[test]
fn tls_does_not_beat_ls_at_ten_samples() {
    let exp = Experiment::default();
    for angle in ANGLES {
        let p = paired(&exp, angle, 10);
        assert!(
            p.ls_minus_tls.abs() < 2.0 * p.standard_error,
            "{angle} rad, N = 10: LS - TLS {} +- {} percent points is no longer a tie",
            p.ls_minus_tls,
            p.standard_error
        );
        assert!(
            p.tls > 10.0 && p.ls > 10.0,
            "TLS {} %, LS {} %",
            p.tls,
            p.ls
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
