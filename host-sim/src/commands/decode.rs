//! `host-sim decode FILE [--csv OUT]`: summary of a UART capture (frames by
//! kind, sequence gaps, CRC failures, garbage) and optional CSV export. The
//! capture is read as a stream (`host_sim::formats::capture_export`): a
//! capture of any length takes the memory of its summary. Written but
//! incomplete (exit 2) when frames were lost; duplicated and reordered
//! frames are counted, not incompleteness.
use std::path::PathBuf;
use std::process::ExitCode;

use super::status::complete_unless;

use host_sim::formats::capture_export::decode_file;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// Capture of the probe's UART bytes (`.bin`).
    pub file: PathBuf,
    /// Write every good frame as one CSV row here.
    #[arg(long, value_name = "OUT")]
    pub csv: Option<PathBuf>,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let decoded = decode_file(&args.file, args.csv.as_deref())?;
    outln!("capture          {}", args.file.display());
    outln!("{}", decoded.summary);
    let lost = decoded.summary.stats.lost;
    if let Some((out, rows)) = decoded.finish_csv()? {
        outln!("csv              {} ({rows} rows)", out.display());
    }
    Ok(complete_unless((lost > 0).then(|| {
        format!("the capture is incomplete: {lost} frames lost (sequence gaps)")
    })))
}
