//! Figures as files: one drawing function, generic over the plotters
//! backend, rendered once into an SVG and once into a PNG of the same size
//! ([`Figure`] + [`write_svg_png`]). PNG text needs glyphs, so the DejaVu
//! Sans font is embedded in the binary (`host-sim/assets/fonts/`,
//! Bitstream Vera licence, which allows redistribution inside other
//! software; its text is in `LICENSE-DejaVu.txt` beside the font) and
//! registered with plotters' `ab_glyph` renderer: a machine without system
//! fonts still gets labelled PNGs.

use anyhow::{anyhow, bail, Result};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

/// Font family name the embedded font is registered under.
pub const FONT: &str = "sans-serif";
static DEJAVU_SANS: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");

/// Registers the embedded font as [`FONT`] (once per process). Every
/// plotters text (SVG layout too) needs it with the `ab_glyph` feature.
pub fn register_font() -> Result<()> {
    static DONE: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    let ok = *DONE.get_or_init(|| {
        plotters::style::register_font(FONT, FontStyle::Normal, DEJAVU_SANS).is_ok()
    });
    if !ok {
        bail!("the embedded font DejaVuSans.ttf could not be read");
    }
    Ok(())
}

/// A drawing that can be rendered on any plotters backend.
pub trait Figure {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<()>;
}

/// A plotters drawing error as an `anyhow` one.
pub fn plot_error<E: std::error::Error + Send + Sync>(e: DrawingAreaErrorKind<E>) -> anyhow::Error {
    anyhow!("drawing: {e}")
}

/// A line's sample in a legend: 20 pixels of `style`.
pub fn legend_line(style: ShapeStyle) -> impl Fn((i32, i32)) -> PathElement<(i32, i32)> {
    move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style)
}

/// Renders `figure` to `DIR/STEM.svg` and `DIR/STEM.png` (`size` pixels);
/// returns the two paths.
pub fn write_svg_png(
    dir: &Path,
    stem: &str,
    size: (u32, u32),
    figure: &impl Figure,
) -> Result<[PathBuf; 2]> {
    register_font()?;
    let svg = dir.join(format!("{stem}.svg"));
    let png = dir.join(format!("{stem}.png"));
    {
        let root = SVGBackend::new(&svg, size).into_drawing_area();
        figure.draw(&root)?;
        root.present()
            .map_err(|e| anyhow!("writing {}: {e}", svg.display()))?;
    }
    {
        let root = BitMapBackend::new(&png, size).into_drawing_area();
        figure.draw(&root)?;
        root.present()
            .map_err(|e| anyhow!("writing {}: {e}", png.display()))?;
    }
    Ok([svg, png])
}

/// Creates `dir` if missing; an existing non-directory is an error.
pub fn prepare_dir(dir: &Path) -> Result<()> {
    if dir.exists() && !dir.is_dir() {
        bail!(
            "--plot {}: exists and is not a directory (give a directory for the figures)",
            dir.display()
        );
    }
    std::fs::create_dir_all(dir)
        .map_err(|e| anyhow!("--plot {}: cannot create the directory: {e}", dir.display()))
}
