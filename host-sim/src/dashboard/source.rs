//! Where the dashboard's frames come from: a capture replayed at a chosen
//! pace, or a serial port (recorded raw to a file as the bytes arrive, as
//! `replay --port --save` does), and the probe's commands sent over that
//! port with their ACK/NAK awaited (as `host-sim probe` does: matched by
//! sequence number, sent again without a reply).

use std::fs::File;
use std::io::{ErrorKind, Read, Write};
use std::path::{Path, PathBuf};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError, Sender};
use std::sync::{Arc, Mutex, MutexGuard};
use std::thread;
use std::time::{Duration, Instant};

use anyhow::{Context, Result};
use mwd_core::protocol::uplink::reply::decode_reply_body;
use mwd_core::protocol::uplink::{encode_command, Command, Reply, MAX_COMMAND_WIRE_LEN};
use mwd_core::protocol::{Decoder, Frame, Payload};

use super::state::DashboardState;
use crate::formats::capture::decode_bytes;
use crate::formats::display::reply_text;

pub type Shared = Arc<Mutex<DashboardState>>;

/// The state, also after a thread panicked while holding it (the state
/// stays readable; the page shows what it holds).
pub fn lock(state: &Shared) -> MutexGuard<'_, DashboardState> {
    state
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// Bytes read to check that a file is a probe capture before serving it.
const HEAD_BYTES: u64 = 256 * 1024;

/// An error naming the file unless its first bytes hold a good frame of
/// the probe's protocol.
pub fn check_capture(path: &Path) -> Result<()> {
    let file = File::open(path).with_context(|| format!("reading {}", path.display()))?;
    let mut head = Vec::new();
    file.take(HEAD_BYTES)
        .read_to_end(&mut head)
        .with_context(|| format!("reading {}", path.display()))?;
    let stats = decode_bytes(&head).stats;
    anyhow::ensure!(
        stats.good_frames() > 0,
        "{} is not a probe capture: no good frame of the probe's protocol in its first {} \
         bytes (docs/protocol.md)",
        path.display(),
        head.len()
    );
    Ok(())
}

/// The probe time (us) of a frame that paces a replay.
fn frame_time_us(frame: &Frame) -> Option<u64> {
    match frame.payload {
        Payload::Raw(r) => Some(r.time_us),
        Payload::Nav(n) => Some(n.time_us),
        _ => None,
    }
}

/// Replays a capture into `state` at `speed` times the probe's pace, on a
/// thread of its own.
pub fn replay_file(path: PathBuf, speed: f64, state: Shared) -> thread::JoinHandle<()> {
    thread::spawn(move || {
        let status = match replay_paced(&path, speed, &state) {
            Ok(frames) => format!("end of capture: {frames} frames replayed"),
            Err(e) => format!("replay stopped: {e:#}"),
        };
        lock(&state).finish(status);
    })
}

fn replay_paced(path: &Path, speed: f64, state: &Shared) -> Result<u64> {
    let mut file = File::open(path).with_context(|| format!("reading {}", path.display()))?;
    lock(state).set_status(format!("replaying at {speed}x"));
    let mut decoder = Decoder::new();
    let mut buf = [0u8; 4096];
    let mut frames = Vec::new();
    // (probe time, wall time) that the pace is counted from; set again
    // when the probe's clock starts over (a restart).
    let mut base: Option<(u64, Instant)> = None;
    let mut last_us = 0u64;
    let mut count = 0u64;
    loop {
        let n = file
            .read(&mut buf)
            .with_context(|| format!("reading {}", path.display()))?;
        if n == 0 {
            break;
        }
        frames.clear();
        decoder.feed(&buf[..n], |f| frames.push(f));
        for frame in &frames {
            if let Some(t_us) = frame_time_us(frame) {
                let (t0, wall0) = match base {
                    Some((t0, wall0)) if t_us >= last_us => (t0, wall0),
                    _ => (t_us, Instant::now()),
                };
                base = Some((t0, wall0));
                last_us = t_us;
                let due = Duration::from_secs_f64((t_us - t0) as f64 * 1e-6 / speed);
                let now = wall0.elapsed();
                if due > now {
                    thread::sleep(due - now);
                }
            }
            let mut s = lock(state);
            s.push_frame(frame);
            s.set_link(*decoder.stats(), Instant::now());
            count += 1;
        }
    }
    decoder.finish();
    lock(state).set_link(*decoder.stats(), Instant::now());
    Ok(count)
}

/// A batch of labelled commands for the probe (one button: one command;
/// configure: the job's commands).
pub type CommandBatch = Vec<(String, Command)>;

/// Reads a serial port into `state` (recording every byte to `save` as it
/// arrives) and sends the commands given to the returned sender.
pub fn run_port(
    port: &str,
    baud: u32,
    save: Option<File>,
    state: Shared,
) -> Result<Sender<CommandBatch>> {
    let serial = serialport::new(port, baud)
        .timeout(Duration::from_millis(100))
        .open()
        .with_context(|| format!("opening serial port {port}"))?;
    let writer = serial
        .try_clone()
        .with_context(|| format!("opening serial port {port} for writing"))?;
    let (reply_tx, reply_rx) = mpsc::channel();
    let (command_tx, command_rx) = mpsc::channel();
    let reader_state = Arc::clone(&state);
    thread::spawn(move || {
        let status = read_port(serial, save, &reader_state, &reply_tx);
        lock(&reader_state).finish(status);
    });
    thread::spawn(move || send_commands(writer, &command_rx, &reply_rx, &state));
    Ok(command_tx)
}

/// Reads until the port fails; returns why it stopped.
fn read_port(
    mut serial: impl Read,
    mut save: Option<File>,
    state: &Shared,
    replies: &Sender<Reply>,
) -> String {
    let mut decoder = Decoder::new();
    let mut buf = [0u8; 4096];
    let mut frames = Vec::new();
    lock(state).set_status("listening");
    loop {
        let n = match serial.read(&mut buf) {
            Ok(0) => return "the port reported end of file".into(),
            Ok(n) => n,
            Err(e) if matches!(e.kind(), ErrorKind::TimedOut | ErrorKind::Interrupted) => 0,
            Err(e) => return format!("port closed ({e})"),
        };
        if let Some(file) = save.as_mut() {
            if let Err(e) = file.write_all(&buf[..n]).and_then(|()| file.flush()) {
                // Stop rather than show what is not recorded.
                return format!("recording failed ({e}): stopped reading");
            }
        }
        frames.clear();
        for b in &buf[..n] {
            if let Some(frame) = decoder.push(*b) {
                frames.push(frame);
            }
            // Replies are the frames the telemetry decoder passes over.
            if let Some(Ok((_, reply))) = decoder.unknown_body().map(decode_reply_body) {
                let _ = replies.send(reply);
            }
        }
        let mut s = lock(state);
        for frame in &frames {
            s.push_frame(frame);
        }
        s.set_link(*decoder.stats(), Instant::now());
    }
}

const REPLY_TIMEOUT: Duration = Duration::from_millis(1000);
const ATTEMPTS: u32 = 3;

fn send_commands(
    mut port: impl Write,
    batches: &Receiver<CommandBatch>,
    replies: &Receiver<Reply>,
    state: &Shared,
) {
    // A new number each run, so that a late reply to an earlier run's
    // command is not taken for this one's.
    let mut seq: u16 = rand::random();
    while let Ok(batch) = batches.recv() {
        for (label, command) in batch {
            let number = lock(state).command_sent(&label);
            seq = seq.wrapping_add(1);
            let (result, reply) = match send_one(&mut port, seq, &command, replies) {
                Ok(Some(reply)) => (reply_text(&reply), Some(reply)),
                Ok(None) => (
                    format!(
                        "no reply after {ATTEMPTS} attempts of {} ms",
                        REPLY_TIMEOUT.as_millis()
                    ),
                    None,
                ),
                Err(e) => (format!("not sent: {e:#}"), None),
            };
            lock(state).command_result(number, result, reply.as_ref());
        }
    }
}

fn send_one(
    port: &mut impl Write,
    seq: u16,
    command: &Command,
    replies: &Receiver<Reply>,
) -> Result<Option<Reply>> {
    let mut wire = [0u8; MAX_COMMAND_WIRE_LEN];
    let n = encode_command(seq, command, &mut wire)?;
    for _ in 0..ATTEMPTS {
        port.write_all(&wire[..n])
            .and_then(|()| port.flush())
            .context("writing to the serial port")?;
        let deadline = Instant::now() + REPLY_TIMEOUT;
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            match replies.recv_timeout(left) {
                Ok(reply) if reply.command_seq == seq => return Ok(Some(reply)),
                Ok(_) => continue,
                Err(RecvTimeoutError::Timeout) => break,
                Err(RecvTimeoutError::Disconnected) => {
                    anyhow::bail!("the port is no longer read")
                }
            }
        }
    }
    Ok(None)
}
