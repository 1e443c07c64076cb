//! `host-sim decode FILE [--csv OUT]`: summary of a UART capture (frames by
//! kind, sequence gaps, CRC failures, garbage) and optional CSV export. The
//! capture is read as a stream (`host_sim::formats::capture_export`): a
//! capture of any length takes the memory of its summary.
use std::path::PathBuf;

use host_sim::formats::capture_export::decode_file;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// Capture of the probe's UART bytes (`.bin`).
    pub file: PathBuf,
    /// Write every good frame as one CSV row here.
    #[arg(long, value_name = "OUT")]
    pub csv: Option<PathBuf>,
}

pub fn run(args: Args) -> anyhow::Result<()> {
    let decoded = decode_file(&args.file, args.csv.as_deref())?;
    outln!("capture          {}", args.file.display());
    outln!("{}", decoded.summary);
    if let Some((out, rows)) = decoded.finish_csv()? {
        outln!("csv              {} ({rows} rows)", out.display());
    }
    Ok(())
}
