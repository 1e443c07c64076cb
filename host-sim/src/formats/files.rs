//! Files the commands write or read whole, with the path in every error:
//! a text or pretty JSON output written at once, a buffered output file
//! created, the depth log read from its path. Every output is written
//! under a temporary name in its own folder and renamed to its name only
//! when whole ([`OutputFile`]): a write that fails (a full disk) is an
//! error and leaves no partial file, nor a file it replaced half written.

use crate::formats::depth_log::DepthLog;
use anyhow::{Context, Result};
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// Writes `text` to `path` ("writing PATH" on failure), whole or not at
/// all ([`OutputFile`]).
pub fn write_text(path: &Path, text: &str) -> Result<()> {
    let write = || -> Result<()> {
        let mut out = OutputFile::create(path)?;
        out.write_all(text.as_bytes())?;
        out.finish()
    };
    write().with_context(|| format!("writing {}", path.display()))
}

/// An output file being written: buffered, under a temporary name beside
/// `path` (`.NAME.part-PID`) until [`Self::finish`] renames it; dropped
/// unfinished (an error on the way), the temporary file is removed and
/// `path` is left as it was. A path that is not a regular file (a device
/// such as `/dev/stdout`, a named pipe) is written directly.
#[derive(Debug)]
pub struct OutputFile {
    out: BufWriter<File>,
    path: PathBuf,
    /// The temporary name, while the file is not finished.
    part: Option<PathBuf>,
}

impl OutputFile {
    /// Creates the temporary file for `path` ("creating PATH" on failure).
    pub fn create(path: &Path) -> Result<Self> {
        let creating = || format!("creating {}", path.display());
        let special = std::fs::metadata(path).is_ok_and(|m| !m.is_file());
        let part = match path.file_name() {
            Some(name) if !special => {
                let mut part_name = std::ffi::OsString::from(".");
                part_name.push(name);
                part_name.push(format!(".part-{}", std::process::id()));
                Some(path.with_file_name(part_name))
            }
            _ => None,
        };
        let file = File::create(part.as_deref().unwrap_or(path)).with_context(creating)?;
        Ok(Self {
            out: BufWriter::new(file),
            path: path.to_owned(),
            part,
        })
    }

    /// Flushes the file and gives it its name ("writing PATH" on failure).
    pub fn finish(mut self) -> Result<()> {
        let writing = || format!("writing {}", self.path.display());
        self.out.flush().with_context(writing)?;
        if let Some(part) = &self.part {
            std::fs::rename(part, &self.path).with_context(writing)?;
        }
        self.part = None;
        Ok(())
    }

    /// Where the file goes.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

impl Write for OutputFile {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.out.write(buf)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.out.flush()
    }
}

impl Drop for OutputFile {
    fn drop(&mut self) {
        if let Some(part) = self.part.take() {
            // Unfinished: nothing of it is kept (what was buffered is lost
            // with it, on purpose).
            let _ = std::fs::remove_file(part);
        }
    }
}

/// Several outputs of one command written as a set: each staged whole
/// under its temporary name ([`OutputSet::stage`]), all given their names
/// together at the end ([`OutputSet::commit`]). A set dropped uncommitted
/// (a later output failed) leaves none of them.
#[derive(Default)]
pub struct OutputSet {
    staged: Vec<OutputFile>,
}

impl OutputSet {
    /// Writes `text` for `path` under its temporary name, flushed (a full
    /// disk fails here, "writing PATH").
    pub fn stage(&mut self, path: &Path, text: &str) -> Result<()> {
        let stage = || -> Result<OutputFile> {
            let mut out = OutputFile::create(path)?;
            out.write_all(text.as_bytes())?;
            out.flush()?;
            Ok(out)
        };
        let staged = stage().with_context(|| format!("writing {}", path.display()))?;
        self.staged.push(staged);
        Ok(())
    }

    /// Gives every staged output its name.
    pub fn commit(self) -> Result<()> {
        for file in self.staged {
            file.finish()?;
        }
        Ok(())
    }
}

/// Writes `value` as pretty JSON (with a final newline) to `path`, the
/// path named in the error: the studies' `--json` outputs.
pub fn write_json(path: &Path, value: &impl serde::Serialize) -> Result<()> {
    let text = serde_json::to_string_pretty(value)? + "\n";
    write_text(path, &text)
}

/// Creates `path` for writing, buffered ("creating PATH" on failure): an
/// [`OutputFile`], named only when [`OutputFile::finish`]ed.
pub fn create_buffered(path: &Path) -> Result<OutputFile> {
    OutputFile::create(path)
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
    fn an_output_is_named_only_when_whole() {
        let dir = std::env::temp_dir().join(format!("host-sim-files-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("out.csv");
        std::fs::write(&path, "before\n").unwrap();
        let mut out = create_buffered(&path).unwrap();
        writeln!(out, "after").unwrap();
        out.flush().unwrap();
        // written, not finished: the old file stands
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "before\n");
        drop(out);
        // dropped unfinished: the old file stands, nothing else is left
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "before\n");
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);
        let mut out = create_buffered(&path).unwrap();
        writeln!(out, "after").unwrap();
        out.finish().unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "after\n");
        write_text(&path, "text").unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "text");
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_full_device_is_an_error() {
        let full = Path::new("/dev/full");
        if !full.exists() {
            return;
        }
        let e = write_text(full, "x").unwrap_err();
        assert_eq!(e.to_string(), "writing /dev/full");
        assert!(full.exists(), "the device is written, not replaced");
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
