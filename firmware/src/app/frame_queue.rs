//! Encoded frames waiting for the UART: a bounded byte ring filled with
//! whole frames by the acquisition interrupt and the main loop, drained one
//! byte at a time by the transmitter.
//!
//! A frame that does not fit is dropped whole (never half-queued, which
//! would corrupt the one after it on the wire) and counted. It still uses up
//! its sequence number, so the host sees the drop as a sequence gap: the
//! probe's count and the host's loss count must agree.

use heapless::Deque;
use mwd_core::protocol::uplink::Reply;
use mwd_core::protocol::{FrameEncoder, Payload, MAX_WIRE_LEN};

/// Transmit queue size of the probe: 20 raw frames (about 90 ms of the
/// UART at 115200 baud). Enough because nothing bursts into it: the
/// acquisition queues at most 159 B per period while the UART drains 576 B,
/// and the navigation, which catches up after a recovery, waits for room
/// (`ProbeState::next_sample_to_navigate`, `budget::NAV_ROOM_BYTES`)
/// instead of having its frames dropped.
pub const TX_QUEUE_LEN: usize = 1024;

/// The transmit queue of `N` bytes, with the frame numbering.
pub struct FrameQueue<const N: usize> {
    bytes: Deque<u8, N>,
    encoder: FrameEncoder,
    queued: u32,
    dropped: u32,
}

impl<const N: usize> Default for FrameQueue<N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const N: usize> FrameQueue<N> {
    pub const fn new() -> Self {
        Self {
            bytes: Deque::new(),
            encoder: FrameEncoder::new(),
            queued: 0,
            dropped: 0,
        }
    }

    /// Numbers, encodes and queues one frame; false (and counted) when it
    /// had to be dropped for lack of room.
    pub fn push(&mut self, payload: &Payload) -> bool {
        let mut wire = [0u8; MAX_WIRE_LEN];
        let encoded = self.encoder.encode(payload, &mut wire);
        self.push_encoded(encoded.ok(), &wire)
    }

    /// Numbers, encodes and queues a reply to a host command (downlink
    /// kind 5, in the same sequence as the telemetry, so the host counts
    /// every loss); false (and counted) when it had to be dropped.
    pub fn push_reply(&mut self, reply: &Reply) -> bool {
        let mut wire = [0u8; MAX_WIRE_LEN];
        let encoded = self.encoder.encode_reply(reply, &mut wire);
        self.push_encoded(encoded.ok(), &wire)
    }

    fn push_encoded(&mut self, len: Option<usize>, wire: &[u8]) -> bool {
        let Some(len) = len else {
            // Cannot happen with a MAX_WIRE_LEN buffer; counted, not hidden.
            self.dropped = self.dropped.saturating_add(1);
            return false;
        };
        let free = N - self.bytes.len();
        if len > free {
            self.dropped = self.dropped.saturating_add(1);
            return false;
        }
        for &b in wire.iter().take(len) {
            // Room was checked above, so this never fails.
            let _ = self.bytes.push_back(b);
        }
        self.queued = self.queued.saturating_add(1);
        true
    }

    /// The next byte for the transmitter.
    pub fn pop(&mut self) -> Option<u8> {
        self.bytes.pop_front()
    }

    pub fn is_empty(&self) -> bool {
        self.bytes.is_empty()
    }

    /// Bytes waiting.
    pub fn len(&self) -> usize {
        self.bytes.len()
    }

    /// Frames accepted so far.
    pub fn queued(&self) -> u32 {
        self.queued
    }

    /// Frames dropped so far because the queue was full.
    pub fn dropped(&self) -> u32 {
        self.dropped
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use mwd_core::protocol::frame::NO_PART;
    use mwd_core::protocol::{Decoder, Event, EventKind, RawSample};

    fn event(value: u32) -> Payload {
        Payload::Event(Event {
            time_us: 0,
            kind: EventKind::Boot,
            part: NO_PART,
            code: 0,
            value,
        })
    }

    fn drain<const N: usize>(queue: &mut FrameQueue<N>, decoder: &mut Decoder) -> u32 {
        let mut frames = 0;
        while let Some(b) = queue.pop() {
            decoder.feed(&[b], |_| frames += 1);
        }
        frames
    }

    #[test]
    fn full_queue_drops_whole_frames_and_the_host_sees_the_gap() {
        // Room for two raw frames (51 bytes each) but not three.
        let mut queue = FrameQueue::<120>::new();
        let raw = Payload::Raw(RawSample::default());
        assert!(queue.push(&raw));
        assert!(queue.push(&raw));
        assert!(!queue.push(&raw));
        assert_eq!((queue.queued(), queue.dropped()), (2, 1));
        let mut decoder = Decoder::new();
        assert_eq!(drain(&mut queue, &mut decoder), 2);
        assert!(queue.is_empty());
        // The next frame goes through and its sequence shows the one lost.
        assert!(queue.push(&event(7)));
        assert_eq!(drain(&mut queue, &mut decoder), 1);
        let stats = decoder.stats();
        assert_eq!(stats.lost, 1);
        assert_eq!(stats.corrupt(), 0);
    }

    #[test]
    fn a_reply_joins_the_one_downlink_sequence() {
        use mwd_core::protocol::uplink::reply::decode_reply_body;
        let mut queue = FrameQueue::<256>::new();
        assert!(queue.push(&event(1)));
        assert!(queue.push_reply(&Reply::ack(150_000, 9, 0x49, 4)));
        assert!(queue.push(&event(2)));
        let mut decoder = Decoder::new();
        let mut replies = std::vec::Vec::new();
        let mut telemetry = 0;
        while let Some(b) = queue.pop() {
            telemetry += u32::from(decoder.push(b).is_some());
            if let Some(Ok(reply)) = decoder.unknown_body().map(decode_reply_body) {
                replies.push(reply);
            }
        }
        assert_eq!(telemetry, 2);
        assert_eq!(replies, [(1, Reply::ack(150_000, 9, 0x49, 4))]);
        assert_eq!(decoder.stats().lost, 0, "the reply's number was counted");
    }

    #[test]
    fn interleaved_push_and_pop_keep_frames_intact() {
        let mut queue = FrameQueue::<64>::new();
        let mut decoder = Decoder::new();
        let mut received = 0;
        for n in 0..50 {
            assert!(queue.push(&event(n)));
            // Drain about one frame per push: the ring wraps many times.
            for _ in 0..30 {
                if let Some(b) = queue.pop() {
                    decoder.feed(&[b], |_| received += 1);
                }
            }
        }
        received += drain(&mut queue, &mut decoder);
        assert_eq!(received, 50);
        assert_eq!(decoder.stats().lost, 0);
        assert_eq!(queue.dropped(), 0);
    }
}
