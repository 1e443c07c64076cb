//! A capture decoded whole into memory: its good frames in order, the
//! replies among them and what was lost (for tests, studies and the small
//! captures a dashboard or a demo reads; commands that read a capture of
//! any size stream it instead, [`super::ProbeCaptureFile`]).

use std::fs::File;
use std::io::{self, Read};
use std::path::Path;

use mwd_core::protocol::uplink::Reply;
use mwd_core::protocol::{Decoder, DecoderStats, Frame};

use super::items::{feed, Item, Received};
use super::stream::FrameStream;

/// A decoded capture: the good frames in order and what was lost.
#[derive(Debug, Clone, Default)]
pub struct Capture {
    pub frames: Vec<Frame>,
    pub stats: DecoderStats,
    /// The replies to uplink commands (downlink kind 5, outside
    /// [`Payload`]: `mwd_core::protocol::uplink::reply`), each with its
    /// place among `frames`.
    pub replies: Vec<CapturedReply>,
}

/// A reply to an uplink command as the capture holds it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CapturedReply {
    /// How many of the capture's frames came before it.
    pub after_frames: usize,
    /// Its downlink sequence number (the one counter of all kinds).
    pub seq: u16,
    pub reply: Reply,
}

impl Capture {
    /// Every good frame in the order it came, replies included.
    pub fn in_order(&self) -> impl Iterator<Item = Received<'_>> {
        let (mut next_reply, mut next_frame) = (0, 0);
        std::iter::from_fn(move || match self.replies.get(next_reply) {
            Some(r) if r.after_frames <= next_frame || next_frame >= self.frames.len() => {
                next_reply += 1;
                Some(Received::Reply {
                    seq: r.seq,
                    reply: &r.reply,
                })
            }
            _ => {
                let frame = self.frames.get(next_frame)?;
                next_frame += 1;
                Some(Received::Frame(frame))
            }
        })
    }

    /// Feeds `bytes` to `decoder`, keeping its frames and replies;
    /// `on_new` sees each as it comes.
    pub fn feed(&mut self, decoder: &mut Decoder, bytes: &[u8], mut on_new: impl FnMut(Received)) {
        feed(decoder, bytes, |item| {
            self.push(item);
            on_new(item.received());
        });
    }

    /// Keeps one good item, in order.
    fn push(&mut self, item: Item) {
        match item {
            Item::Frame(frame) => self.frames.push(frame),
            Item::Reply { seq, reply } => self.replies.push(CapturedReply {
                after_frames: self.frames.len(),
                seq,
                reply,
            }),
        }
    }
}

/// A capture's bytes with frame `index` (counting every frame in the
/// order sent, the boot event first) left out: a loss on the line, for
/// tests and studies of the host's loss handling.
pub fn without_frame(bytes: &[u8], index: usize) -> Vec<u8> {
    let mut out = Vec::new();
    for (i, chunk) in bytes
        .split(|b| *b == 0)
        .filter(|c| !c.is_empty())
        .enumerate()
    {
        if i != index {
            out.push(0);
            out.extend_from_slice(chunk);
            out.push(0);
        }
    }
    out
}

/// Decodes a whole capture held in memory.
pub fn decode_bytes(bytes: &[u8]) -> Capture {
    let mut decoder = Decoder::new();
    let mut capture = Capture::default();
    capture.feed(&mut decoder, bytes, |_| {});
    decoder.finish();
    capture.stats = *decoder.stats();
    capture
}

/// Reads and decodes a whole capture from any reader into memory (a
/// command that reads a capture of any size goes through
/// [`ProbeCaptureFile`] instead, keeping only what it reports).
pub fn decode_reader(reader: impl Read) -> io::Result<Capture> {
    let mut stream = FrameStream::new(reader);
    let mut capture = Capture::default();
    while let Some(item) = stream.next_item()? {
        capture.push(item);
    }
    capture.stats = *stream.stats();
    Ok(capture)
}

/// Reads and decodes a `.bin` capture file into memory.
pub fn read_capture(path: &Path) -> io::Result<Capture> {
    decode_reader(io::BufReader::new(File::open(path)?))
}
