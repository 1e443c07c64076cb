//! Monte Carlo studies over simulated runs (`host-sim study ...`).

pub mod coverage_shard;
pub mod drilling_coverage;
pub mod drilling_run;
pub mod grade;
pub mod indexing;
pub mod lateral;
pub mod owsg;
pub mod rins_probe;
pub mod run_checks;
pub mod shard;
pub mod stats;

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Mutex;

use serde::Serialize;

/// How much of a study was done when it was stopped (Ctrl-C): every
/// figure of it is then over the jobs done.
#[derive(Clone, Copy, Debug, Serialize, PartialEq, Eq)]
pub struct Interruption {
    /// Jobs finished (Monte Carlo runs, covariance analyses, sweep points).
    pub jobs_done: usize,
    pub jobs: usize,
}

impl Interruption {
    /// The interruption of a study that did `jobs_done` of its `jobs`,
    /// `None` when it did them all.
    pub fn of(jobs_done: usize, jobs: usize) -> Option<Self> {
        (jobs_done < jobs).then_some(Self { jobs_done, jobs })
    }
}

/// Which runs a Monte Carlo study makes and how: seeds `first_seed..
/// first_seed + runs` on `threads` threads, `progress` called after each,
/// until `stop` is set.
pub struct StudyRuns<'a> {
    pub runs: usize,
    pub first_seed: u64,
    pub threads: usize,
    pub progress: &'a (dyn Fn() + Sync),
    pub stop: &'a AtomicBool,
}

impl StudyRuns<'_> {
    /// [`run_seeds_until`] over these runs.
    pub fn run<T: Send>(
        &self,
        run: impl Fn(u64) -> anyhow::Result<T> + Sync,
    ) -> Vec<(u64, Result<T, String>)> {
        run_seeds_until(
            self.runs,
            self.first_seed,
            self.threads,
            self.progress,
            self.stop,
            run,
        )
    }
}

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
    let never = AtomicBool::new(false);
    run_seeds_until(runs, first_seed, threads, progress, &never, run)
}

/// The same, until `stop` is set ([`run_jobs_until`]): the outcomes of
/// the seeds done, in seed order.
pub fn run_seeds_until<T: Send>(
    runs: usize,
    first_seed: u64,
    threads: usize,
    progress: &(dyn Fn() + Sync),
    stop: &AtomicBool,
    run: impl Fn(u64) -> anyhow::Result<T> + Sync,
) -> Vec<(u64, Result<T, String>)> {
    run_jobs_until(runs, threads, progress, stop, |k| {
        let seed = first_seed + k as u64;
        (seed, run(seed).map_err(|e| format!("seed {seed}: {e:#}")))
    })
    .into_iter()
    .flatten()
    .collect()
}

/// Runs `jobs` jobs on `threads` threads (each takes the next job when
/// done), calling `progress` after each; the outcomes in job order.
pub fn run_jobs<T: Send>(
    jobs: usize,
    threads: usize,
    progress: &(dyn Fn() + Sync),
    job: impl Fn(usize) -> T + Sync,
) -> Vec<T> {
    let never = AtomicBool::new(false);
    run_jobs_until(jobs, threads, progress, &never, job)
        .into_iter()
        .flatten()
        .collect()
}

/// The same, until `stop` is set (Ctrl-C): the jobs under way finish, no
/// other starts; `None` for each job not run.
pub fn run_jobs_until<T: Send>(
    jobs: usize,
    threads: usize,
    progress: &(dyn Fn() + Sync),
    stop: &AtomicBool,
    job: impl Fn(usize) -> T + Sync,
) -> Vec<Option<T>> {
    let next = AtomicUsize::new(0);
    let done: Mutex<Vec<(usize, T)>> = Mutex::new(Vec::with_capacity(jobs));
    std::thread::scope(|scope| {
        for _ in 0..threads.max(1) {
            scope.spawn(|| loop {
                if stop.load(Ordering::Relaxed) {
                    break;
                }
                let k = next.fetch_add(1, Ordering::Relaxed);
                if k >= jobs {
                    break;
                }
                let outcome = job(k);
                if let Ok(mut d) = done.lock() {
                    d.push((k, outcome));
                }
                progress();
            });
        }
    });
    let mut out: Vec<Option<T>> = (0..jobs).map(|_| None).collect();
    for (k, outcome) in done.into_inner().unwrap_or_default() {
        out[k] = Some(outcome);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_pool_keeps_the_job_order() {
        let calls = AtomicUsize::new(0);
        let out = run_jobs(
            50,
            3,
            &|| {
                calls.fetch_add(1, Ordering::Relaxed);
            },
            |k| k * 2,
        );
        assert_eq!(out, (0..50).map(|k| k * 2).collect::<Vec<_>>());
        assert_eq!(calls.load(Ordering::Relaxed), 50);
    }

    #[test]
    fn a_stop_lets_the_jobs_under_way_finish_and_starts_no_other() {
        let stop = AtomicBool::new(false);
        let finished = AtomicUsize::new(0);
        // Stop after the third job is done (the progress call).
        let out = run_jobs_until(
            40,
            2,
            &|| {
                if finished.fetch_add(1, Ordering::Relaxed) + 1 == 3 {
                    stop.store(true, Ordering::Relaxed);
                }
            },
            &stop,
            |k| k * 2,
        );
        assert_eq!(out.len(), 40);
        let done: Vec<usize> = out.iter().flatten().copied().collect();
        // The third job and the one the other thread had under way.
        assert!((3..=4).contains(&done.len()), "{done:?}");
        assert_eq!(done.len(), finished.load(Ordering::Relaxed));
        for (k, o) in out.iter().enumerate() {
            assert!(o.is_none_or(|v| v == k * 2), "job {k}: {o:?}");
        }
        let stopped = AtomicBool::new(true);
        assert!(run_jobs_until(5, 2, &|| {}, &stopped, |k| k)
            .iter()
            .all(Option::is_none));
    }

    #[test]
    fn seeds_come_back_in_order_with_their_errors_named() {
        let out = run_seeds(6, 10, 2, &|| {}, |seed| {
            anyhow::ensure!(seed != 12, "bad");
            Ok(seed * 2)
        });
        let seeds: Vec<u64> = out.iter().map(|r| r.0).collect();
        assert_eq!(seeds, (10..16).collect::<Vec<_>>());
        assert_eq!(out[0].1, Ok(20));
        assert_eq!(out[2].1, Err("seed 12: bad".to_string()));
    }
}
