//! Files the commands write or read whole, with the path in every error:
//! a text or pretty JSON output written at once, a buffered output file
//! created, the depth log read from its path.

use crate::formats::depth_log::DepthLog;
use anyhow::{Context, Result};
use std::fs::File;
use std::io::BufWriter;
use std::path::Path;

/// Writes `text` to `path` ("writing PATH" on failure).
pub fn write_text(path: &Path, text: &str) -> Result<()> {
    std::fs::write(path, text).with_context(|| format!("writing {}", path.display()))
}

/// Writes `value` as pretty JSON (with a final newline) to `path`, the
/// path named in the error: the studies' `--json` outputs.
pub fn write_json(path: &Path, value: &impl serde::Serialize) -> Result<()> {
    let text = serde_json::to_string_pretty(value)? + "\n";
    write_text(path, &text)
}

/// Creates `path` for writing, buffered ("creating PATH" on failure).
pub fn create_buffered(path: &Path) -> Result<BufWriter<File>> {
    let file = File::create(path).with_context(|| format!("creating {}", path.display()))?;
    Ok(BufWriter::new(file))
}

/// Whether `error` is the reader of an output having gone (standard
/// output closed by `| head`).
pub fn is_broken_pipe(error: &anyhow::Error) -> bool {
    error.chain().any(|cause| {
        cause
            .downcast_ref::<std::io::Error>()
            .is_some_and(|e| e.kind() == std::io::ErrorKind::BrokenPipe)
    })
}

/// Reads the surface depth log at `path` (CSV: time_s, md_m).
pub fn read_depth_log(path: &Path) -> Result<DepthLog> {
    let file = File::open(path).with_context(|| format!("reading {}", path.display()))?;
    DepthLog::read(file).with_context(|| format!("{}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_name_the_path() {
        let dir = std::env::temp_dir().join("host-sim-files-test-no-such-dir");
        let path = dir.join("out.txt");
        let e = write_text(&path, "x").unwrap_err();
        assert_eq!(e.to_string(), format!("writing {}", path.display()));
        let e = create_buffered(&path).unwrap_err();
        assert_eq!(e.to_string(), format!("creating {}", path.display()));
        let e = read_depth_log(&path).unwrap_err();
        assert_eq!(e.to_string(), format!("reading {}", path.display()));
    }

    #[test]
    fn a_closed_pipe_is_told_through_the_context() {
        let pipe = std::io::Error::from(std::io::ErrorKind::BrokenPipe);
        assert!(is_broken_pipe(&anyhow::Error::new(pipe).context("writing")));
        let other = std::io::Error::from(std::io::ErrorKind::Other);
        assert!(!is_broken_pipe(&anyhow::Error::new(other)));
        assert!(!is_broken_pipe(&anyhow::anyhow!("not an io error")));
    }
}
