//! Figures of the lateral study: the error growth along MD with the
//! predicted bounds, per sensor grade ([`along_md`]), and the sweep of the
//! TD error over gyro bias and ARW as a contour map ([`sweep`], with
//! [`contour`]'s marching squares). Each is written as SVG and PNG of the
//! same drawing through the survey figures' [`Figure`] and
//! [`write_svg_png`] (embedded font, so PNG text needs no system fonts);
//! `log_axis` holds both figures' log axes (range and tick labels).
//!
//! Undetermined values (NaN) are never drawn as numbers: a line is broken
//! at them, and a sweep cell without a value is left blank.
//!
//! [`Figure`]: crate::formats::figure::Figure
//! [`write_svg_png`]: crate::formats::figure::write_svg_png

pub mod along_md;
pub mod contour;
mod log_axis;
pub mod sweep;

pub use along_md::{plot_error_along_md, AlongMdSeries};
pub use sweep::{plot_sweep_contour, Sweep};

use anyhow::{anyhow, Result};
use std::path::Path;

/// `STEM` as (directory, file stem) for
/// [`write_svg_png`](crate::formats::figure::write_svg_png).
fn split_stem(stem: &Path) -> Result<(&Path, &str)> {
    let name = stem
        .file_name()
        .and_then(|n| n.to_str())
        .ok_or_else(|| anyhow!("{}: not a file name for the figures", stem.display()))?;
    let dir = match stem.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    Ok((dir, name))
}

#[cfg(test)]
mod tests;
