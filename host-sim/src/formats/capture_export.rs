//! A capture decoded as a stream (`host-sim decode`): its summary (frames
//! by kind, sequence gaps, CRC failures, garbage) and, when asked, every
//! good frame as one CSV row. A capture of any length takes the memory of
//! its summary.

use crate::formats::capture::{self, CaptureSummary, Item, ProbeCaptureFile};
use crate::formats::files::{create_buffered, OutputFile};
use anyhow::{Context, Result};
use std::io::Write;
use std::path::{Path, PathBuf};

/// A decoded capture: its summary, and the CSV of its frames still to be
/// flushed ([`Decoded::finish_csv`]).
pub struct Decoded {
    pub summary: CaptureSummary,
    csv: Option<(PathBuf, OutputFile)>,
    rows: u64,
}

/// Decodes the capture `path`, writing its good frames to `csv` (after
/// the header) as they come.
pub fn decode_file(path: &Path, csv: Option<&Path>) -> Result<Decoded> {
    let mut cap = ProbeCaptureFile::open(path)?;
    let mut csv = match csv {
        Some(out) => {
            let mut w = create_buffered(out)?;
            writeln!(w, "{}", capture::CSV_HEADER)
                .with_context(|| format!("writing {}", out.display()))?;
            Some((out.to_path_buf(), w))
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
    Ok(Decoded { summary, csv, rows })
}

impl Decoded {
    /// Flushes the CSV; gives its path and rows, if one was asked for.
    pub fn finish_csv(self) -> Result<Option<(PathBuf, u64)>> {
        let Some((out, w)) = self.csv else {
            return Ok(None);
        };
        w.finish()?;
        Ok(Some((out, self.rows)))
    }
}
