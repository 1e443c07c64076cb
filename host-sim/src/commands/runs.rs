//! The studies' runs on the command line: worker threads, a progress bar,
//! and Ctrl-C (or SIGTERM): the first one lets the runs under way finish
//! and the study write what it has, a second one quits at once. A leaf of
//! `commands/`, used by the study commands.

use anyhow::Context;

/// Where a study's seeds start and how many threads run them (after its
/// own `--runs`, whose default and help differ by study).
#[derive(clap::Args, Debug)]
pub struct SeedsAndThreads {
    #[arg(long, default_value_t = 1)]
    pub first_seed: u64,
    /// Worker threads (default: all cores).
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=256))]
    pub threads: Option<u64>,
}

impl SeedsAndThreads {
    /// Worker threads: `--threads`, else all cores.
    pub fn threads(&self) -> usize {
        self.threads.map_or_else(
            || std::thread::available_parallelism().map_or(1, |n| n.get()),
            |t| t as usize,
        )
    }

    /// `runs` seeds from `--first-seed` on [`threads`](Self::threads),
    /// `progress` after each, until `stop`.
    pub fn runs<'a>(
        &self,
        runs: u64,
        progress: &'a (dyn Fn() + Sync),
        stop: &'a std::sync::atomic::AtomicBool,
    ) -> host_sim::study::StudyRuns<'a> {
        host_sim::study::StudyRuns {
            runs: runs as usize,
            first_seed: self.first_seed,
            threads: self.threads(),
            progress,
            stop,
        }
    }
}

/// The gyro grades a study by grade runs: built-in ones by name, and
/// grade files that add or replace one.
#[derive(clap::Args, Debug, Clone)]
pub struct GradeChoice {
    /// Gyro grades by name (default: all built-in ones and those of
    /// --grade-file): scc1300, high-end-mems, ge-mwd-2020, navigation.
    #[arg(long, value_delimiter = ',')]
    pub grades: Vec<String>,
    /// A grade file (JSON, host-sim/data/grades/): adds a grade, or
    /// replaces the built-in one of the same name. Repeatable.
    #[arg(long = "grade-file")]
    pub grade_files: Vec<std::path::PathBuf>,
}

impl GradeChoice {
    /// The grades chosen, the files read and checked in the command
    /// line's order (`host_sim::study::grade::select`).
    pub fn select(&self) -> anyhow::Result<Vec<host_sim::study::grade::Grade>> {
        host_sim::study::grade::select(&self.grades, &self.grade_files)
    }
}

/// A study's results: `table` on standard output and, with `--json`, the
/// results in that file.
pub fn print_and_write_json<T: serde::Serialize>(
    table: &str,
    json: Option<&std::path::Path>,
    results: &T,
) -> anyhow::Result<()> {
    out!("{table}");
    if let Some(path) = json {
        host_sim::formats::files::write_json(path, results)?;
    }
    Ok(())
}

/// A progress bar over `len` runs drawn with `template`.
pub fn progress_bar(len: u64, template: &str) -> anyhow::Result<indicatif::ProgressBar> {
    let bar = indicatif::ProgressBar::new(len);
    bar.set_style(indicatif::ProgressStyle::with_template(template).context("progress bar")?);
    Ok(bar)
}

/// A flag the first Ctrl-C (or SIGTERM) sets: a study then finishes the
/// runs under way and writes what it has. A second one quits at once. The
/// note goes above `bar` when it is drawn (one bar for the whole study),
/// else to standard error.
pub fn stop_on_ctrl_c(
    bar: Option<&indicatif::ProgressBar>,
) -> anyhow::Result<std::sync::Arc<std::sync::atomic::AtomicBool>> {
    use std::sync::atomic::{AtomicBool, Ordering};
    use std::sync::Arc;
    let stop = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&stop);
    let bar = bar.filter(|b| !b.is_hidden()).cloned();
    ctrlc::set_handler(move || {
        if flag.swap(true, Ordering::Relaxed) {
            std::process::exit(130);
        }
        let note = "interrupted: finishing the runs under way, then writing the results so \
                    far (Ctrl-C again to quit at once, writing nothing)";
        // A bar that is not drawn (no terminal) prints nothing either.
        match &bar {
            Some(bar) => bar.println(note),
            None => eprintln!("{note}"),
        }
    })
    .context("installing the SIGINT/SIGTERM handler")?;
    Ok(stop)
}
