//! Captures of the probe's UART stream (`.bin`: exactly the bytes the probe
//! sends, see `docs/protocol.md`): writing simulated samples as raw-sample
//! frames (and the navigation frames a probe makes of them), reading and
//! decoding a capture with its loss statistics, and exporting the frames
//! as CSV.
//!
//! - [`items`]: the decoder's good items (frames and replies), and the feed.
//! - [`stream`]: a capture read one item at a time from any reader, and a
//!   capture file checked to hold the probe's protocol.
//! - [`memory`]: a capture decoded whole into memory.
//! - [`summary`]: what `decode` and `replay` print of a capture.
//! - [`writer`]: a simulated probe's capture written.
//! - [`csv`]: the frames as CSV.

mod csv;
mod items;
mod memory;
mod stream;
mod summary;
mod writer;

pub use csv::{write_csv, write_csv_row, CSV_HEADER};
pub use items::{feed, Item, Received};
pub use memory::{
    decode_bytes, decode_reader, read_capture, without_frame, Capture, CapturedReply,
};
pub use stream::{FrameStream, ProbeCaptureFile};
pub use summary::CaptureSummary;
pub use writer::{
    create_capture, raw_sample_from_body, raw_sample_from_si, write_simulated_probe, CaptureWriter,
    ProbeSetup, SiSample,
};

#[cfg(test)]
mod stream_tests;
#[cfg(test)]
mod tests;
