//! A capture's good items as the decoder gives them: a telemetry frame or
//! a reply to an uplink command, owned ([`Item`]) or borrowed from a
//! capture held in memory ([`Received`]), and the byte-by-byte feed that
//! makes them.

use mwd_core::protocol::uplink::reply::decode_reply_body;
use mwd_core::protocol::uplink::Reply;
use mwd_core::protocol::{Decoder, Frame};

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

pub(super) fn push_byte(decoder: &mut Decoder, byte: u8) -> Option<Item> {
    if let Some(frame) = decoder.push(byte) {
        return Some(Item::Frame(frame));
    }
    match decoder.unknown_body().map(decode_reply_body) {
        Some(Ok((seq, reply))) => Some(Item::Reply { seq, reply }),
        _ => None,
    }
}

/// One good frame of the downlink: a telemetry frame or a reply.
#[derive(Debug, Clone, Copy)]
pub enum Received<'a> {
    Frame(&'a Frame),
    Reply { seq: u16, reply: &'a Reply },
}
