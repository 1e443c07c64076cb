//! Allan deviation against NIST SP 1065 (Riley, 2008) reference data.
//!
//! - Section 12.3 (test suite): the 1000-point white-FM data set made by the
//!   Lehmer generator n_{k+1} = 16807 n_k mod (2^31 - 1), n_0 = 1234567890,
//!   each n normalised by 2^31 - 1, used as frequency data with tau0 = 1 s.
//!   Published ADEV 0.2922319, 0.09965736, 0.03897804 and overlapping ADEV
//!   0.2922319, 0.09159953, 0.03241343 at tau = 1, 10, 100.
//! - Section 12.1: the nine frequency values 892 .. 677 with ADEV 91.22945
//!   (tau 1) and 115.8082 (tau 2).
//!
//! The published figures have 7 significant digits: matched to 1e-6 relative.

use host_sim::analysis::allan::{nonoverlapping_avar, overlapping_avar, phase_from_rate};

fn nist_1000() -> Vec<f64> {
    const MODULUS: u64 = 2_147_483_647;
    let mut n: u64 = 1_234_567_890;
    let mut out = Vec::with_capacity(1000);
    for _ in 0..1000 {
        out.push(n as f64 / MODULUS as f64);
        n = 16_807 * n % MODULUS;
    }
    out
}

fn close(got: f64, want: f64) {
    let rel = (got / want - 1.0).abs();
    println!("ours {got:.10}, NIST {want}, relative difference {rel:.1e}");
    assert!(rel < 1e-6, "got {got}, NIST {want}, relative error {rel:e}");
}

#[test]
fn nist_1000_point_adev_and_oadev() {
    let y = nist_1000();
    let x = phase_from_rate(&y, 1.0);
    let adev = [0.2922319, 0.09965736, 0.03897804];
    let oadev = [0.2922319, 0.09159953, 0.03241343];
    for (i, m) in [1usize, 10, 100].into_iter().enumerate() {
        close(nonoverlapping_avar(&y, m).unwrap().sqrt(), adev[i]);
        close(overlapping_avar(&x, m, 1.0).unwrap().0.sqrt(), oadev[i]);
    }
}

#[test]
fn nist_nine_point_adev() {
    let y = [
        892.0, 809.0, 823.0, 798.0, 671.0, 644.0, 883.0, 903.0, 677.0,
    ];
    close(nonoverlapping_avar(&y, 1).unwrap().sqrt(), 91.22945);
    close(nonoverlapping_avar(&y, 2).unwrap().sqrt(), 115.8082);
}
