//! `host-sim decode FILE [--csv OUT]`: summary of a UART capture (frames by
//! kind, sequence gaps, CRC failures, garbage) and optional CSV export.
use std::fs::File;
use std::io::BufWriter;
use std::path::PathBuf;

use anyhow::Context;
use host_sim::capture;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// Capture of the probe's UART bytes (`.bin`).
    pub file: PathBuf,
    /// Write every good frame as one CSV row here.
    #[arg(long, value_name = "OUT")]
    pub csv: Option<PathBuf>,
}

pub fn run(args: Args) -> anyhow::Result<()> {
    let cap = capture::read_probe_capture(&args.file)?;
    outln!("capture          {}", args.file.display());
    outln!("{cap}");
    if let Some(out) = &args.csv {
        let file = File::create(out).with_context(|| format!("creating {}", out.display()))?;
        capture::write_csv(&cap.frames, BufWriter::new(file))
            .with_context(|| format!("writing {}", out.display()))?;
        outln!(
            "csv              {} ({} rows)",
            out.display(),
            cap.frames.len()
        );
    }
    Ok(())
}
