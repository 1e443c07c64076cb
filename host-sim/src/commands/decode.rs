//! `host-sim decode FILE [--csv OUT]`: summary of a UART capture (frames by
//! kind, sequence gaps, CRC failures, garbage) and optional CSV export. The
//! capture is read as a stream: a capture of any length takes the memory
//! of its summary.
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::PathBuf;

use anyhow::Context;
use host_sim::formats::capture::{self, CaptureSummary, Item, ProbeCaptureFile};

#[derive(clap::Args, Debug)]
pub struct Args {
    /// Capture of the probe's UART bytes (`.bin`).
    pub file: PathBuf,
    /// Write every good frame as one CSV row here.
    #[arg(long, value_name = "OUT")]
    pub csv: Option<PathBuf>,
}

pub fn run(args: Args) -> anyhow::Result<()> {
    let mut cap = ProbeCaptureFile::open(&args.file)?;
    let mut csv = match &args.csv {
        Some(out) => {
            let file = File::create(out).with_context(|| format!("creating {}", out.display()))?;
            let mut w = BufWriter::new(file);
            writeln!(w, "{}", capture::CSV_HEADER)
                .with_context(|| format!("writing {}", out.display()))?;
            Some((out, w))
        }
        None => None,
    };
    let mut summary = CaptureSummary::default();
    let mut rows = 0u64;
    while let Some(item) = cap.next_item()? {
        summary.note(item.received());
        if let (Some((out, w)), Item::Frame(frame)) = (csv.as_mut(), &item) {
            capture::write_csv_row(frame, w)
                .with_context(|| format!("writing {}", out.display()))?;
            rows += 1;
        }
    }
    summary.stats = *cap.stats();
    outln!("capture          {}", args.file.display());
    outln!("{summary}");
    if let Some((out, mut w)) = csv {
        w.flush()
            .with_context(|| format!("writing {}", out.display()))?;
        outln!("csv              {} ({rows} rows)", out.display());
    }
    Ok(())
}
