//! A capture read as a stream: its frames and replies one at a time, in
//! order, from any reader, with the decoder's loss statistics at the end.
//! A day and a half of drilling (the 1000 m lateral) is 400 MB of capture
//! and 5 M frames: read this way, a command keeps only what it reports,
//! not the frames.

use std::fs::File;
use std::io::{self, BufReader, ErrorKind, Read};
use std::path::{Path, PathBuf};

use anyhow::Context;
use mwd_core::protocol::{Decoder, DecoderStats};

use super::items::{push_byte, Item};

/// The items of a capture read from `reader` as they are needed.
pub struct FrameStream<R> {
    reader: R,
    decoder: Decoder,
    buf: Vec<u8>,
    pos: usize,
    len: usize,
    ended: bool,
}

impl<R: Read> FrameStream<R> {
    pub fn new(reader: R) -> Self {
        Self {
            reader,
            decoder: Decoder::new(),
            buf: vec![0; 64 * 1024],
            pos: 0,
            len: 0,
            ended: false,
        }
    }

    /// The next good item, `None` at the end of the stream.
    pub fn next_item(&mut self) -> io::Result<Option<Item>> {
        loop {
            while self.pos < self.len {
                let byte = self.buf[self.pos];
                self.pos += 1;
                if let Some(item) = push_byte(&mut self.decoder, byte) {
                    return Ok(Some(item));
                }
            }
            if self.ended {
                return Ok(None);
            }
            match self.reader.read(&mut self.buf) {
                Ok(0) => {
                    // A frame cut off at the end counts as corrupt.
                    self.decoder.finish();
                    self.ended = true;
                }
                Ok(n) => (self.pos, self.len) = (0, n),
                Err(e) if e.kind() == ErrorKind::Interrupted => {}
                Err(e) => return Err(e),
            }
        }
    }

    /// The decoder's statistics so far: the whole stream's once
    /// [`next_item`](Self::next_item) has returned `None`.
    pub fn stats(&self) -> &DecoderStats {
        self.decoder.stats()
    }
}

/// A capture file opened for `decode`, `replay` and `survey`, checked to
/// hold the probe's protocol, read one item at a time.
pub struct ProbeCaptureFile {
    path: PathBuf,
    stream: FrameStream<BufReader<File>>,
    /// The item read to check the file, not handed out yet.
    first: Option<Item>,
}

impl ProbeCaptureFile {
    /// Opens `path` and reads up to its first good item: an error naming
    /// the file when it cannot be read or holds no good frame of the
    /// probe's protocol (an empty file, a CSV, random bytes): that is not a
    /// probe capture.
    pub fn open(path: &Path) -> anyhow::Result<Self> {
        let file = File::open(path).with_context(|| format!("reading {}", path.display()))?;
        let mut stream = FrameStream::new(BufReader::new(file));
        let first = stream
            .next_item()
            .with_context(|| format!("reading {}", path.display()))?;
        let s = stream.stats();
        anyhow::ensure!(
            first.is_some() || s.good_frames() > 0,
            "{} is not a probe capture: {} bytes without one good frame of the probe's \
             protocol ({} corrupt chunks, {} of another protocol version; the layout is in \
             docs/protocol.md)",
            path.display(),
            s.bytes,
            s.corrupt(),
            s.unsupported_version
        );
        Ok(Self {
            path: path.to_path_buf(),
            stream,
            first,
        })
    }

    /// The next good item, `None` at the end of the file.
    pub fn next_item(&mut self) -> anyhow::Result<Option<Item>> {
        if let Some(item) = self.first.take() {
            return Ok(Some(item));
        }
        self.stream
            .next_item()
            .with_context(|| format!("reading {}", self.path.display()))
    }

    /// The decoder's statistics: the whole file's once
    /// [`next_item`](Self::next_item) has returned `None`.
    pub fn stats(&self) -> &DecoderStats {
        self.stream.stats()
    }
}
