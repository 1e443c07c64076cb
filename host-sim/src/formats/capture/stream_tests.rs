//! Tests of a capture read as a stream and of its summary.

use super::*;
use crate::formats::capture::{decode_bytes, without_frame, CaptureWriter, SiSample};
use mwd_core::protocol::uplink::reply::{Reply, ReplyStatus};
use mwd_core::protocol::DecoderStats;
use std::io::Write;
use std::io::{self, Read};

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
