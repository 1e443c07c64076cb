//! A capture read as a stream: its frames and replies one at a time, in
//! order, from any reader, with the decoder's loss statistics at the end;
//! and the summary `decode` and `replay` print of it, gathered as the
//! frames go by. A day and a half of drilling (the 1000 m lateral) is
//! 400 MB of capture and 5 M frames: read this way, a command keeps only
//! what it reports, not the frames.

use std::fmt;
use std::fs::File;
use std::io::{self, BufReader, ErrorKind, Read};
use std::path::{Path, PathBuf};

use anyhow::Context;
use mwd_core::protocol::frame::Payload;
use mwd_core::protocol::uplink::reply::decode_reply_body;
use mwd_core::protocol::uplink::Reply;
use mwd_core::protocol::{Decoder, DecoderStats, Frame, StationSurvey};

use super::{Capture, Received};

/// One good item of the downlink, owned: a telemetry frame or a reply to
/// an uplink command.
#[derive(Debug, Clone, Copy)]
pub enum Item {
    Frame(Frame),
    Reply { seq: u16, reply: Reply },
}

impl Item {
    /// The item as [`Capture::in_order`] gives it.
    pub fn received(&self) -> Received<'_> {
        match self {
            Item::Frame(frame) => Received::Frame(frame),
            Item::Reply { seq, reply } => Received::Reply { seq: *seq, reply },
        }
    }
}

/// Decodes `bytes` with `decoder`, handing each good item to `on_item`
/// and keeping nothing (a live session's bytes come this way).
pub fn feed(decoder: &mut Decoder, bytes: &[u8], mut on_item: impl FnMut(Item)) {
    for &b in bytes {
        if let Some(item) = push_byte(decoder, b) {
            on_item(item);
        }
    }
}

fn push_byte(decoder: &mut Decoder, byte: u8) -> Option<Item> {
    if let Some(frame) = decoder.push(byte) {
        return Some(Item::Frame(frame));
    }
    match decoder.unknown_body().map(decode_reply_body) {
        Some(Ok((seq, reply))) => Some(Item::Reply { seq, reply }),
        _ => None,
    }
}

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

/// What `decode` and `replay` print of a capture: its loss statistics, the
/// time its raw samples span and the probe's station surveys, gathered as
/// the frames go by ([`note`](Self::note)).
#[derive(Debug, Clone, Default)]
pub struct CaptureSummary {
    /// Set by the owner at the end of the stream.
    pub stats: DecoderStats,
    /// The earliest and latest raw sample's time stamp, us.
    raw_span_us: Option<(u64, u64)>,
    /// The station survey frames, in order.
    pub stations: Vec<StationSurvey>,
}

impl CaptureSummary {
    /// Takes in one item of the capture.
    pub fn note(&mut self, received: Received) {
        let Received::Frame(frame) = received else {
            return;
        };
        match &frame.payload {
            Payload::Raw(r) => {
                let (first, last) = self.raw_span_us.unwrap_or((r.time_us, r.time_us));
                self.raw_span_us = Some((first.min(r.time_us), last.max(r.time_us)));
            }
            Payload::Station(st) => self.stations.push(*st),
            _ => {}
        }
    }

    /// The summary of a capture held in memory.
    pub fn of(capture: &Capture) -> Self {
        let mut summary = Self {
            stats: capture.stats,
            ..Self::default()
        };
        for frame in &capture.frames {
            summary.note(Received::Frame(frame));
        }
        summary
    }
}

impl fmt::Display for CaptureSummary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let s = &self.stats;
        let [raw, nav, event, station] = s.frames;
        writeln!(f, "bytes            {}", s.bytes)?;
        writeln!(
            f,
            "frames           {} good: raw sample {raw}, navigation {nav}, event {event}, \
             station survey {station}, unknown kind {}",
            s.good_frames(),
            s.unknown_kind
        )?;
        writeln!(
            f,
            "sequence gaps    {} frames lost, {} restarts",
            s.lost, s.sequence_restarts
        )?;
        writeln!(
            f,
            "corrupt          {} CRC failures, {} malformed ({} other version)",
            s.crc_errors, s.malformed, s.unsupported_version
        )?;
        write!(f, "garbage          {} bytes", s.garbage_bytes)?;
        if let Some((first, last)) = self.raw_span_us {
            write!(
                f,
                "\nraw samples span {:.3} s .. {:.3} s",
                first as f64 * 1e-6,
                last as f64 * 1e-6
            )?;
        }
        for st in &self.stations {
            write!(f, "\nprobe {}", crate::formats::display::station_text(st))?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::formats::capture::{decode_bytes, without_frame, CaptureWriter, SiSample};
    use mwd_core::protocol::uplink::reply::{Reply, ReplyStatus};
    use std::io::Write;

    /// A short capture: raw frames, a reply among them, a station frame.
    fn capture_bytes() -> Vec<u8> {
        let mut w = CaptureWriter::new(Vec::new());
        for index in 0..40 {
            let sample = SiSample {
                index,
                accel_body_m_s2: [[0.0, 0.0, 9.8]; 2],
                ..SiSample::default()
            };
            w.write_si_sample(&sample).unwrap();
            if index == 17 {
                w.write_reply(&Reply {
                    time_us: 900_000,
                    command_seq: 3,
                    command_kind: 1,
                    status: ReplyStatus::Ack,
                    detail: 0,
                    config_version: 0,
                })
                .unwrap();
            }
        }
        w.finish().unwrap()
    }

    /// Reads `bytes` a few at a time, as a slow pipe would give them.
    struct Trickle<'a>(&'a [u8]);

    impl Read for Trickle<'_> {
        fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
            let n = buf.len().min(self.0.len()).min(7);
            buf[..n].copy_from_slice(&self.0[..n]);
            self.0 = &self.0[n..];
            Ok(n)
        }
    }

    fn streamed(bytes: &[u8]) -> (Vec<Item>, DecoderStats) {
        let mut stream = FrameStream::new(Trickle(bytes));
        let mut items = Vec::new();
        while let Some(item) = stream.next_item().unwrap() {
            items.push(item);
        }
        (items, *stream.stats())
    }

    #[test]
    fn the_stream_gives_the_whole_captures_items_in_order_and_its_statistics() {
        // With a frame lost on the line, so the statistics have a gap.
        let bytes = without_frame(&capture_bytes(), 5);
        let whole = decode_bytes(&bytes);
        let (items, stats) = streamed(&bytes);
        assert_eq!(stats, whole.stats);
        assert_eq!(stats.lost, 1, "the gap is seen");
        let in_order: Vec<String> = whole.in_order().map(|r| format!("{r:?}")).collect();
        let from_stream: Vec<String> = items
            .iter()
            .map(|i| format!("{:?}", i.received()))
            .collect();
        assert_eq!(from_stream, in_order);
        assert!(
            items.iter().any(|i| matches!(i, Item::Reply { .. })),
            "the reply is among them"
        );
    }

    #[test]
    fn the_summary_of_a_stream_is_the_summary_of_the_capture_in_memory() {
        let bytes = capture_bytes();
        let whole = decode_bytes(&bytes);
        let (items, stats) = streamed(&bytes);
        let mut summary = CaptureSummary::default();
        for item in &items {
            summary.note(item.received());
        }
        summary.stats = stats;
        let text = summary.to_string();
        assert_eq!(text, CaptureSummary::of(&whole).to_string());
        assert!(
            text.contains("raw samples span 0.000 s .. 1.950 s"),
            "{text}"
        );
    }

    #[test]
    fn a_file_without_the_probes_frames_is_refused_by_name_and_a_capture_is_read_to_its_end() {
        let dir = std::env::temp_dir().join(format!("mwd-stream-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let text = dir.join("stations.csv");
        std::fs::File::create(&text)
            .unwrap()
            .write_all(b"md,inc,azi\n100,1,2\n")
            .unwrap();
        let e = ProbeCaptureFile::open(&text).err().unwrap().to_string();
        assert!(e.contains("stations.csv is not a probe capture"), "{e}");
        let missing = ProbeCaptureFile::open(&dir.join("missing.bin"))
            .err()
            .unwrap();
        assert!(
            format!("{missing:#}").contains("missing.bin"),
            "{missing:#}"
        );

        let bin = dir.join("capture.bin");
        std::fs::write(&bin, capture_bytes()).unwrap();
        let mut file = ProbeCaptureFile::open(&bin).unwrap();
        let mut n = 0;
        while file.next_item().unwrap().is_some() {
            n += 1;
        }
        assert_eq!(n, 41, "40 raw frames and the reply, the first one included");
        assert_eq!(file.stats().frames[0], 40);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
