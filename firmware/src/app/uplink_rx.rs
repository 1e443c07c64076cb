//! The probe's receiver of the host's commands, built so that nothing the
//! host (or a broken line) sends can hurt the probe:
//!
//! - the UART's receive interrupt only puts bytes into a bounded lock-free
//!   queue ([`UplinkInbox`], heapless' single-producer single-consumer
//!   ring); a full queue drops the byte and counts it, never blocks;
//! - the main loop drains at most a given number of bytes per call
//!   ([`UplinkReceiver::poll`]), after its 20 Hz work, so a flood of bytes
//!   cannot delay acquisition;
//! - frames are split at 0x00 as the downlink's decoder does: a chunk
//!   longer than the longest command is dropped whole at the next
//!   delimiter (never buffered past its bound), so garbage costs the chunk
//!   it is in and nothing after;
//! - every chunk lands in exactly one counter ([`UplinkStats`]); commands
//!   whose CRC held are answered, an ACK or a NAK with its reason
//!   ([`apply`]).

use core::sync::atomic::{AtomicU32, Ordering};
use heapless::spsc::{Consumer, Producer, Queue};
use mwd_core::config::{Applied, ProbeConfig};
use mwd_core::protocol::uplink::{
    decode_command, Command, IndexingProcedure, NakReason, Received, Reply, ReplyStatus,
    UplinkError, MAX_COMMAND_WIRE_LEN,
};
use mwd_core::protocol::wire::DELIMITER;

/// The ring's size; it holds one byte less, 1023: at 115200 baud a fully
/// busy line brings 576 bytes per 50 ms cycle, so a main loop that drains
/// once per cycle loses nothing even when one cycle runs late by most of
/// another. Commands are rare and short (at most 124 bytes on the wire).
pub const UPLINK_QUEUE_LEN: usize = 1024;

/// Largest chunk kept between delimiters: the longest command, encoded.
pub const MAX_CHUNK_LEN: usize = MAX_COMMAND_WIRE_LEN - 2;

/// The bytes between the receive interrupt and the main loop.
pub struct UplinkInbox {
    queue: Queue<u8, UPLINK_QUEUE_LEN>,
    overflowed: AtomicU32,
}

impl Default for UplinkInbox {
    fn default() -> Self {
        Self::new()
    }
}

impl UplinkInbox {
    pub const fn new() -> Self {
        Self {
            queue: Queue::new(),
            overflowed: AtomicU32::new(0),
        }
    }

    /// The interrupt's end and the main loop's end.
    pub fn split(&mut self) -> (InboxWriter<'_>, InboxReader<'_>) {
        let (producer, consumer) = self.queue.split();
        let overflowed = &self.overflowed;
        (
            InboxWriter {
                producer,
                overflowed,
            },
            InboxReader {
                consumer,
                overflowed,
            },
        )
    }
}

/// The receive interrupt's end of the inbox.
pub struct InboxWriter<'a> {
    producer: Producer<'a, u8>,
    overflowed: &'a AtomicU32,
}

impl InboxWriter<'_> {
    /// Queues a received byte; a full queue drops it and counts it.
    pub fn push(&mut self, byte: u8) {
        if self.producer.enqueue(byte).is_err() {
            self.overflowed.fetch_add(1, Ordering::Relaxed);
        }
    }
}

/// The main loop's end of the inbox.
pub struct InboxReader<'a> {
    consumer: Consumer<'a, u8>,
    overflowed: &'a AtomicU32,
}

impl InboxReader<'_> {
    pub fn pop(&mut self) -> Option<u8> {
        self.consumer.dequeue()
    }

    /// Bytes waiting.
    pub fn pending(&self) -> usize {
        self.consumer.len()
    }

    /// Bytes dropped because the queue was full.
    pub fn overflowed(&self) -> u32 {
        self.overflowed.load(Ordering::Relaxed)
    }
}

/// What the receiver has seen. Every non-empty chunk between delimiters is
/// counted once, in one of `frames_ok` .. `out_of_range` ([`Self::chunks`]);
/// the counters saturate (4e9 chunks) rather than wrap.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct UplinkStats {
    /// Bytes taken from the inbox.
    pub bytes: u32,
    /// Commands decoded with every field in range.
    pub frames_ok: u32,
    pub crc_failures: u32,
    /// Not COBS, too short, the wrong length for its kind, another version.
    pub malformed: u32,
    /// Longer than the longest command: dropped unread.
    pub oversized: u32,
    /// A good CRC on a kind the probe does not know.
    pub unknown: u32,
    /// A good CRC, a field out of its range.
    pub out_of_range: u32,
    /// Bytes the interrupt dropped because the inbox was full.
    pub overflowed_bytes: u32,
}

impl UplinkStats {
    /// Chunks seen: the sum of the per-outcome counters.
    pub fn chunks(&self) -> u64 {
        [
            self.frames_ok,
            self.crc_failures,
            self.malformed,
            self.oversized,
            self.unknown,
            self.out_of_range,
        ]
        .iter()
        .map(|n| u64::from(*n))
        .sum()
    }
}

/// The main loop's decoder of the inbox's bytes.
#[derive(Debug, Clone)]
pub struct UplinkReceiver {
    chunk: [u8; MAX_CHUNK_LEN],
    len: usize,
    oversized: bool,
    stats: UplinkStats,
}

impl Default for UplinkReceiver {
    fn default() -> Self {
        Self::new()
    }
}

/// A received command, or one to NAK (its CRC held).
pub type Decoded = Result<Received, UplinkError>;

impl UplinkReceiver {
    pub const fn new() -> Self {
        Self {
            chunk: [0; MAX_CHUNK_LEN],
            len: 0,
            oversized: false,
            stats: UplinkStats {
                bytes: 0,
                frames_ok: 0,
                crc_failures: 0,
                malformed: 0,
                oversized: 0,
                unknown: 0,
                out_of_range: 0,
                overflowed_bytes: 0,
            },
        }
    }

    pub fn stats(&self) -> &UplinkStats {
        &self.stats
    }

    /// Drains at most `max_bytes` from the inbox, stopping after the first
    /// byte that completes something to answer.
    pub fn poll(&mut self, inbox: &mut InboxReader, max_bytes: usize) -> Option<Decoded> {
        self.stats.overflowed_bytes = inbox.overflowed();
        for _ in 0..max_bytes {
            let decoded = self.push(inbox.pop()?);
            if decoded.is_some() {
                return decoded;
            }
        }
        None
    }

    /// Feeds one byte; returns what a delimiter completed, when it is to
    /// be answered: a command, or an error whose CRC held.
    pub fn push(&mut self, byte: u8) -> Option<Decoded> {
        self.stats.bytes = self.stats.bytes.wrapping_add(1);
        if byte != DELIMITER {
            match self.chunk.get_mut(self.len) {
                Some(slot) if !self.oversized => {
                    *slot = byte;
                    self.len += 1;
                }
                _ => self.oversized = true,
            }
            return None;
        }
        let decoded = self.finish_chunk();
        self.len = 0;
        self.oversized = false;
        decoded
    }

    fn finish_chunk(&mut self) -> Option<Decoded> {
        let s = &mut self.stats;
        if self.len == 0 {
            return None; // Between two delimiters.
        }
        if self.oversized {
            s.oversized = s.oversized.saturating_add(1);
            return None;
        }
        let decoded = self
            .chunk
            .get_mut(..self.len)
            .and_then(|chunk| {
                let n = cobs::decode_in_place(chunk).ok()?;
                chunk.get(..n)
            })
            .map(decode_command);
        let counter = match &decoded {
            Some(Ok(_)) => &mut s.frames_ok,
            Some(Err(UplinkError::BadCrc)) => &mut s.crc_failures,
            Some(Err(UplinkError::UnknownCommand { .. })) => &mut s.unknown,
            Some(Err(UplinkError::OutOfRange { .. })) => &mut s.out_of_range,
            Some(Err(
                UplinkError::TooShort
                | UplinkError::BadLength { .. }
                | UplinkError::UnsupportedVersion { .. },
            ))
            | None => &mut s.malformed,
        };
        // Saturating: a counter stuck at its limit, never a panic.
        *counter = counter.saturating_add(1);
        decoded.filter(|d| {
            d.as_ref()
                .map_or_else(|e| e.addressed().is_some(), |_| true)
        })
    }
}

/// What the main loop is asked to do (after the ACK is sent).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Action {
    Realign,
    StartSurveying,
    TakeStation,
    IndexToolface(IndexingProcedure),
    /// Send the configuration (its version is in the ACK).
    ReportConfig,
    Reboot,
}

/// A command's answer and, when acknowledged, what to do.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Outcome {
    pub reply: Reply,
    pub action: Option<Action>,
}

fn action(command: &Command) -> Option<Action> {
    Some(match command {
        Command::Realign => Action::Realign,
        Command::StartSurveying => Action::StartSurveying,
        Command::TakeStation => Action::TakeStation,
        Command::IndexToolface(p) => Action::IndexToolface(*p),
        Command::ReportConfig => Action::ReportConfig,
        Command::Reboot => Action::Reboot,
        Command::SetSite(_)
        | Command::SetTieIn { .. }
        | Command::ClearTieIn
        | Command::SetCalibration { .. }
        | Command::SetStillSettings(_) => return None,
    })
}

/// Turns a decoded command into a configuration change or an action
/// request, and its ACK or NAK. A setting is refused (NAK busy) unless
/// `accepts_changes` (the probe is not surveying), applied
/// (`ProbeConfig::apply`: the navigator's tie-in limits, NAK out of range
/// with the field), then stored by `store` before it is acknowledged; a
/// failed store keeps the previous configuration (NAK storage failed).
/// `None`: nothing to answer (the CRC failed).
pub fn apply<E>(
    decoded: &Decoded,
    config: &mut ProbeConfig,
    time_us: u64,
    accepts_changes: bool,
    store: impl FnOnce(&ProbeConfig) -> Result<(), E>,
) -> Option<Outcome> {
    let received = match decoded {
        Ok(received) => received,
        Err(error) => {
            return Reply::for_error(error, time_us, config.version).map(|reply| Outcome {
                reply,
                action: None,
            })
        }
    };
    let kind = received.command.kind() as u8;
    let nak = |reason, detail: u8, version| Outcome {
        reply: Reply {
            status: ReplyStatus::Nak(reason),
            detail,
            ..Reply::ack(time_us, received.seq, kind, version)
        },
        action: None,
    };
    let requested = action(&received.command);
    if requested.is_none() && !accepts_changes {
        return Some(nak(NakReason::Busy, 0, config.version));
    }
    let before = *config;
    match config.apply(&received.command) {
        Err(field) => return Some(nak(NakReason::OutOfRange, field as u8, config.version)),
        Ok(Applied::Changed) => {
            if store(config).is_err() {
                *config = before;
                return Some(nak(NakReason::StorageFailed, 0, config.version));
            }
        }
        Ok(Applied::Unchanged | Applied::NotASetting) => {}
    }
    Some(Outcome {
        reply: Reply::ack(time_us, received.seq, kind, config.version),
        action: requested,
    })
}
