//! Ctrl-C (and SIGTERM) during a study: the first one lets the runs under
//! way finish and the study write what it has, a second one quits at once.
//! A leaf of `commands/`, used by the study commands.

/// A flag the first Ctrl-C (or SIGTERM) sets: a study then finishes the
/// runs under way and writes what it has. A second one quits at once. The
/// note goes above `bar` when it is drawn (one bar for the whole study),
/// else to standard error.
pub fn stop_on_ctrl_c(
    bar: Option<&indicatif::ProgressBar>,
) -> anyhow::Result<std::sync::Arc<std::sync::atomic::AtomicBool>> {
    use anyhow::Context;
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
