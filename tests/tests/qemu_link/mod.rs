//! The QEMU probe on a pseudo-terminal, shared by the uplink's end-to-end
//! tests (`qemu_uplink.rs`, `qemu_power_cut.rs`, `qemu_probe_cli.rs`):
//! QEMU started halted with the probe's UART on a pty and its monitor on
//! stdin, and the test's own end of the line ([`Link`]): the downlink
//! decoded by a reader thread, commands written with their sequence
//! numbers.
//!
//! The pty is raw: QEMU makes it so when it creates it
//! (`qemu_openpty_raw`). QEMU drops UART bytes while no one holds the
//! pty open, hence the halted start (`-S`) and the monitor's `cont` once
//! the test's side is open.
#![allow(dead_code)] // each test binary uses its part of it

use std::fs::File;
use std::io::{BufRead, BufReader, Read, Write};
use std::path::Path;
use std::process::{Child, ChildStdin, Command, ExitStatus, Stdio};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError};
use std::time::{Duration, Instant};

use mwd_core::protocol::uplink::reply::decode_reply_body;
use mwd_core::protocol::uplink::{
    encode_command, Command as Uplink, Reply, ReplyStatus, MAX_COMMAND_WIRE_LEN,
};
use mwd_core::protocol::{Decoder, EventKind, Payload};
use system_tests::wait_or_kill;

/// Only a hang reaches these.
pub const REPLY_TIMEOUT: Duration = Duration::from_secs(3);
pub const BOOT_TIMEOUT: Duration = Duration::from_secs(30);
pub const QEMU_TIMEOUT: Duration = Duration::from_secs(300);

/// QEMU running the probe, its UART on a pty.
pub struct QemuOnPty {
    child: Child,
    lines: Receiver<String>,
    monitor: ChildStdin,
    /// QEMU's output so far (and the probe's semihosting output).
    pub out: String,
    pub pty_path: String,
}

impl QemuOnPty {
    /// Starts QEMU halted on `elf` at the probe's real pace
    /// (`-icount shift=0,sleep=on`); with `log`, QEMU also writes every
    /// byte the probe sends to that file (the chardev's `logfile`, kept
    /// whether or not anyone holds the pty open).
    pub fn start(elf: &Path, log: Option<&Path>) -> Self {
        let mut command = Command::new("qemu-system-arm");
        command
            .args(["-M", "mps2-an386", "-cpu", "cortex-m4", "-nographic", "-S"])
            .args(["-semihosting-config", "enable=on,target=native"])
            .args(["-icount", "shift=0,sleep=on"]);
        match log {
            Some(log) => command
                .arg("-chardev")
                .arg(format!("pty,id=probe,logfile={}", log.display()))
                .args(["-serial", "chardev:probe"]),
            None => command.args(["-serial", "pty"]),
        };
        let mut child = command
            .arg("-kernel")
            .arg(elf)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("start qemu-system-arm");
        let (out_tx, lines) = mpsc::channel::<String>();
        for stream in [
            Box::new(child.stdout.take().expect("piped")) as Box<dyn Read + Send>,
            Box::new(child.stderr.take().expect("piped")),
        ] {
            let out_tx = out_tx.clone();
            std::thread::spawn(move || {
                for line in BufReader::new(stream).lines().map_while(Result::ok) {
                    let _ = out_tx.send(line);
                }
            });
        }
        let monitor = child.stdin.take().expect("piped");
        let mut out = String::new();
        // "char device redirected to /dev/pts/N (label ...)"
        let pty_path = loop {
            let line = lines
                .recv_timeout(BOOT_TIMEOUT)
                .unwrap_or_else(|e| panic!("no pty from QEMU ({e}): {out}"));
            out += &line;
            out.push('\n');
            if let Some(path) = line.split_whitespace().find(|w| w.starts_with("/dev/pts/")) {
                break path.to_string();
            }
        };
        Self {
            child,
            lines,
            monitor,
            out,
            pty_path,
        }
    }

    /// A command to QEMU's monitor (`cont`, `system_reset`).
    pub fn monitor(&mut self, command: &str) {
        self.monitor
            .write_all(command.as_bytes())
            .and_then(|()| self.monitor.write_all(b"\n"))
            .and_then(|()| self.monitor.flush())
            .expect("QEMU's monitor takes commands");
    }

    /// Waits for the probe to end its run (or kills a hung QEMU), and
    /// returns the exit status; [`Self::out`] then holds all QEMU said.
    pub fn wait(&mut self) -> ExitStatus {
        let status = wait_or_kill(&mut self.child, "QEMU", QEMU_TIMEOUT);
        while let Ok(line) = self.lines.recv_timeout(Duration::from_secs(5)) {
            self.out += &line;
            self.out.push('\n');
        }
        status
    }
}

impl Drop for QemuOnPty {
    /// A failed test does not leave QEMU running.
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// What the downlink brought, as the reader thread saw it.
pub enum Seen {
    Boot(u32),
    Raw { counter: u32, at: Instant },
    Nav { at: Instant },
    Reply(Reply),
    Other,
}

/// The boot events' values in a recording of the downlink, in order.
pub fn boot_events(bytes: &[u8]) -> Vec<u32> {
    let mut decoder = Decoder::new();
    bytes
        .iter()
        .filter_map(|b| match decoder.push(*b)?.payload {
            Payload::Event(e) if e.kind == EventKind::Boot => Some(e.value),
            _ => None,
        })
        .collect()
}

/// Reads and decodes the pty until it closes; at the end, the count of
/// corrupt frames.
fn read_downlink(mut pty: File, to: mpsc::Sender<Seen>, corrupt: mpsc::Sender<u64>) {
    std::thread::spawn(move || {
        let mut decoder = Decoder::new();
        let mut buf = [0u8; 512];
        while let Ok(n) = pty.read(&mut buf) {
            if n == 0 {
                break;
            }
            for &b in &buf[..n] {
                let seen = match decoder.push(b).map(|f| f.payload) {
                    Some(Payload::Event(e)) if e.kind == EventKind::Boot => Seen::Boot(e.value),
                    Some(Payload::Raw(r)) => Seen::Raw {
                        counter: r.sample_counter,
                        at: Instant::now(),
                    },
                    Some(Payload::Nav(_)) => Seen::Nav { at: Instant::now() },
                    Some(_) => Seen::Other,
                    None => match decoder.unknown_body().map(decode_reply_body) {
                        Some(Ok((_, reply))) => Seen::Reply(reply),
                        _ => continue,
                    },
                };
                if to.send(seen).is_err() {
                    return;
                }
            }
        }
        let _ = corrupt.send(decoder.stats().corrupt());
    });
}

/// The test's end of the serial line.
pub struct Link {
    pty: File,
    seen: Receiver<Seen>,
    /// The corrupt frames' count, sent when the pty closes.
    pub corrupt: Receiver<u64>,
    /// Raw frames (sample counter, arrival) and navigation frames
    /// (arrival) seen so far.
    pub raws: Vec<(u32, Instant)>,
    pub navs: Vec<Instant>,
    next_seq: u16,
    /// Bytes written so far (the caller may reset it).
    pub written: u64,
}

impl Link {
    pub fn open(pty_path: &str) -> Self {
        let pty = File::options()
            .read(true)
            .write(true)
            .open(pty_path)
            .expect("open QEMU's pty");
        let (seen_tx, seen) = mpsc::channel();
        let (corrupt_tx, corrupt) = mpsc::channel();
        read_downlink(
            pty.try_clone().expect("a second handle"),
            seen_tx,
            corrupt_tx,
        );
        Self {
            pty,
            seen,
            corrupt,
            raws: Vec::new(),
            navs: Vec::new(),
            next_seq: 1,
            written: 0,
        }
    }

    /// Waits for what `wanted` picks, noting raw frames meanwhile.
    pub fn wait_for<T>(
        &mut self,
        timeout: Duration,
        mut wanted: impl FnMut(&Seen) -> Option<T>,
    ) -> Option<T> {
        let deadline = Instant::now() + timeout;
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            match self.seen.recv_timeout(left) {
                Ok(seen) => {
                    match seen {
                        Seen::Raw { counter, at } => self.raws.push((counter, at)),
                        Seen::Nav { at } => self.navs.push(at),
                        _ => {}
                    }
                    if let Some(found) = wanted(&seen) {
                        return Some(found);
                    }
                }
                Err(RecvTimeoutError::Timeout) => return None,
                Err(RecvTimeoutError::Disconnected) => panic!("the pty closed"),
            }
        }
    }

    pub fn write(&mut self, bytes: &[u8]) {
        self.pty
            .write_all(bytes)
            .and_then(|()| self.pty.flush())
            .expect("write to the pty");
        self.written += bytes.len() as u64;
    }

    /// Sends `command` once, not waiting for a reply; returns its sequence
    /// number.
    pub fn send_once(&mut self, command: &Uplink) -> u16 {
        let seq = self.next_seq;
        self.next_seq += 1;
        let mut wire = [0u8; MAX_COMMAND_WIRE_LEN];
        let n = encode_command(seq, command, &mut wire).expect("encode a command");
        self.write(&wire[..n]);
        seq
    }

    /// Sends `command` until it is answered (3 attempts).
    pub fn send(&mut self, command: &Uplink) -> Reply {
        let seq = self.next_seq;
        let mut wire = [0u8; MAX_COMMAND_WIRE_LEN];
        let n = encode_command(seq, command, &mut wire).expect("encode a command");
        self.next_seq += 1;
        for _ in 0..3 {
            self.write(&wire[..n]);
            let reply = self.wait_for(REPLY_TIMEOUT, |s| match s {
                Seen::Reply(r) if r.command_seq == seq => Some(*r),
                _ => None,
            });
            if let Some(reply) = reply {
                return reply;
            }
        }
        panic!("no reply to {command:?}")
    }

    /// The next boot event's value.
    pub fn boot_value(&mut self) -> u32 {
        self.wait_for(BOOT_TIMEOUT, |s| match s {
            Seen::Boot(value) => Some(*value),
            _ => None,
        })
        .expect("a boot event")
    }

    /// The next boot event's value, and the replies seen before it.
    pub fn boot_value_after(&mut self) -> (u32, Vec<Reply>) {
        let mut replies = Vec::new();
        let boot = self
            .wait_for(BOOT_TIMEOUT, |s| match s {
                Seen::Boot(value) => Some(*value),
                Seen::Reply(r) => {
                    replies.push(*r);
                    None
                }
                _ => None,
            })
            .expect("a boot event");
        (boot, replies)
    }
}

pub fn acked(reply: &Reply, version: u32) {
    assert_eq!(
        (reply.status, reply.config_version),
        (ReplyStatus::Ack, version),
        "{reply:?}"
    );
}
