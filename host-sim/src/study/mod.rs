//! Monte Carlo studies over simulated runs (`host-sim study ...`).

pub mod drilling_coverage;
pub mod drilling_run;
pub mod grade;
pub mod lateral;
pub mod lateral_covariance;
pub mod lateral_figures;
pub mod lateral_plots;
pub mod lateral_summary;
pub mod lateral_table;
pub mod owsg;
pub mod rins_probe;

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

/// Runs seeds `first_seed..first_seed + runs` on `threads` threads (each
/// takes the next seed when done), calling `progress` after each; the
/// outcomes in seed order, errors as "seed N: ...".
pub fn run_seeds<T: Send>(
    runs: usize,
    first_seed: u64,
    threads: usize,
    progress: &(dyn Fn() + Sync),
    run: impl Fn(u64) -> anyhow::Result<T> + Sync,
) -> Vec<(u64, Result<T, String>)> {
    let next = AtomicUsize::new(0);
    let results: Mutex<Vec<(u64, Result<T, String>)>> = Mutex::new(Vec::new());
    std::thread::scope(|scope| {
        for _ in 0..threads.max(1) {
            scope.spawn(|| loop {
                let k = next.fetch_add(1, Ordering::Relaxed);
                if k >= runs {
                    break;
                }
                let seed = first_seed + k as u64;
                let outcome = run(seed).map_err(|e| format!("seed {seed}: {e:#}"));
                if let Ok(mut r) = results.lock() {
                    r.push((seed, outcome));
                }
                progress();
            });
        }
    });
    let mut results = results.into_inner().unwrap_or_default();
    results.sort_by_key(|r| r.0);
    results
}
