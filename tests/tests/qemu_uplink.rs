//! The QEMU probe told things over its serial line, end to end (issue 15):
//! QEMU puts the probe's UART on a pseudo-terminal that this test holds
//! open, reads the downlink from and writes commands to.
//!
//! 1. Fresh QEMU RAM: the boot event says power-on and the defaults.
//! 2. Set the site (ACK, configuration version 1), read it back (report
//!    the configuration: ACK with version 1).
//! 3. The uplink's reboot command: the boot event says a software reset and
//!    a configuration from flash at version 1, and the report agrees; then
//!    QEMU's monitor `system_reset`: the boot event says the reset pin, the
//!    configuration still from flash.
//! 4. Random uplink byte strings for [`FUZZ`], at the line's pace: every
//!    sample of the period comes as a raw frame with its navigation frame
//!    (20 per simulated second: consecutive sample counters, nothing
//!    dropped or skipped on board), a good command afterwards is still
//!    answered, and the probe's summary accounts for every byte sent.
//!
//! The probe runs at its real pace (`-icount shift=0,sleep=on`), so the
//! test takes about [`RUN_SECONDS`] plus the first two boots. Counts are
//! per simulated second (the probe's own timestamps): QEMU's virtual clock
//! falls behind the wall clock when the host is busy, and more so under a
//! byte stream (QEMU's CMSDK UART takes one byte per main-loop turn), so
//! the wall-clock rate is printed and only checked to be far from zero (a
//! wedged probe sends nothing). The pty is
//! raw: QEMU makes it so when it creates it (`qemu_openpty_raw`); a
//! cooked line would show as corrupt frames, which are asserted absent.
//!
//! qemu-system-arm must be installed: without it this test fails, it does
//! not skip. Linux only (ptys of /dev/pts), like the CI that runs it.
#![cfg(target_os = "linux")]

use std::fs::File;
use std::io::{BufRead, BufReader, Read, Write};
use std::process::{Command, Stdio};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError};
use std::time::{Duration, Instant};

use firmware::app::boot::{boot_event_value, ConfigSource, ResetCause};
use mwd_core::earth::Position;
use mwd_core::protocol::uplink::reply::decode_reply_body;
use mwd_core::protocol::uplink::{
    encode_command, Command as Uplink, Reply, ReplyStatus, MAX_COMMAND_WIRE_LEN,
};
use mwd_core::protocol::{Decoder, EventKind, Payload};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use system_tests::{build_firmware_for, require_qemu, summary_value, wait_or_kill};

/// Simulated seconds each boot streams before the probe ends its run; the
/// last boot's run holds the fuzzing and the check after it.
const RUN_SECONDS: u32 = 36;
/// How long random strings are sent.
const FUZZ: Duration = Duration::from_secs(30);
const RATE_HZ: f64 = 20.0;
/// The line's pace, 115200 baud 8N1: the host sends no faster.
const LINE_BYTES_PER_S: f64 = 11_520.0;
/// Only a hang reaches these.
const REPLY_TIMEOUT: Duration = Duration::from_secs(3);
const BOOT_TIMEOUT: Duration = Duration::from_secs(30);
const QEMU_TIMEOUT: Duration = Duration::from_secs(300);

/// What the downlink brought, as the reader thread saw it.
enum Seen {
    Boot(u32),
    Raw { counter: u32, at: Instant },
    Nav { at: Instant },
    Reply(Reply),
    Other,
}

/// Reads and decodes the pty until it closes.
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
struct Link {
    pty: File,
    seen: Receiver<Seen>,
    /// Raw frames (sample counter, arrival) and navigation frames
    /// (arrival) seen so far.
    raws: Vec<(u32, Instant)>,
    navs: Vec<Instant>,
    next_seq: u16,
    /// Bytes written since the last `take_written`.
    written: u64,
}

impl Link {
    /// Waits for what `wanted` picks, noting raw frames meanwhile.
    fn wait_for<T>(
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

    fn write(&mut self, bytes: &[u8]) {
        self.pty
            .write_all(bytes)
            .and_then(|()| self.pty.flush())
            .expect("write to the pty");
        self.written += bytes.len() as u64;
    }

    /// Sends `command` until it is answered (3 attempts).
    fn send(&mut self, command: &Uplink) -> Reply {
        let seq = self.next_seq;
        self.next_seq += 1;
        let mut wire = [0u8; MAX_COMMAND_WIRE_LEN];
        let n = encode_command(seq, command, &mut wire).expect("encode a command");
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

    fn boot_value(&mut self) -> u32 {
        self.wait_for(BOOT_TIMEOUT, |s| match s {
            Seen::Boot(value) => Some(*value),
            _ => None,
        })
        .expect("a boot event")
    }
}

fn acked(reply: &Reply, version: u32) {
    assert_eq!(
        (reply.status, reply.config_version),
        (ReplyStatus::Ack, version),
        "{reply:?}"
    );
}

/// A random uplink string: noise, noise with delimiters, a good command
/// with a flipped bit (its CRC fails), or an oversized run.
fn random_string(rng: &mut ChaCha8Rng, seq: u16) -> Vec<u8> {
    match rng.random_range(0..4) {
        0 => (0..rng.random_range(1..64)).map(|_| rng.random()).collect(),
        1 => (0..rng.random_range(1..64))
            .map(|_| {
                if rng.random_bool(0.2) {
                    0
                } else {
                    rng.random()
                }
            })
            .collect(),
        2 => {
            let mut wire = [0u8; MAX_COMMAND_WIRE_LEN];
            let n = encode_command(seq, &Uplink::ReportConfig, &mut wire).expect("encode");
            let bit = rng.random_range(8..8 * (n - 1));
            wire[bit / 8] ^= 1 << (bit % 8);
            wire[..n].to_vec()
        }
        _ => (0..rng.random_range(130..400))
            .map(|_| rng.random_range(1..=255))
            .chain([0])
            .collect(),
    }
}

#[test]
fn the_qemu_probe_is_configured_keeps_it_across_reboots_and_survives_random_uplink_bytes() {
    require_qemu();
    let elf = build_firmware_for("board-qemu", "uplink", Some(RUN_SECONDS));
    let mut qemu = Command::new("qemu-system-arm")
        .args(["-M", "mps2-an386", "-cpu", "cortex-m4", "-nographic", "-S"])
        .args(["-semihosting-config", "enable=on,target=native"])
        .args(["-serial", "pty", "-icount", "shift=0,sleep=on", "-kernel"])
        .arg(&elf)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start qemu-system-arm");
    let (out_tx, qemu_lines) = mpsc::channel::<String>();
    for stream in [
        Box::new(qemu.stdout.take().expect("piped")) as Box<dyn Read + Send>,
        Box::new(qemu.stderr.take().expect("piped")),
    ] {
        let out_tx = out_tx.clone();
        std::thread::spawn(move || {
            for line in BufReader::new(stream).lines().map_while(Result::ok) {
                let _ = out_tx.send(line);
            }
        });
    }
    drop(out_tx);
    let mut qemu_out = String::new();
    let pty_path = loop {
        let line = qemu_lines
            .recv_timeout(BOOT_TIMEOUT)
            .unwrap_or_else(|e| panic!("no pty from QEMU ({e}): {qemu_out}"));
        qemu_out += &line;
        qemu_out.push('\n');
        if let Some(path) = line.split_whitespace().find(|w| w.starts_with("/dev/pts/")) {
            break path.to_string();
        }
    };
    let pty = File::options()
        .read(true)
        .write(true)
        .open(&pty_path)
        .expect("open QEMU's pty");
    let (seen_tx, seen) = mpsc::channel();
    let (corrupt_tx, corrupt) = mpsc::channel();
    read_downlink(
        pty.try_clone().expect("a second handle"),
        seen_tx,
        corrupt_tx,
    );
    let mut link = Link {
        pty,
        seen,
        raws: Vec::new(),
        navs: Vec::new(),
        next_seq: 1,
        written: 0,
    };
    let mut monitor = qemu.stdin.take().expect("piped");
    let mut tell_monitor = |command: &str| {
        monitor
            .write_all(command.as_bytes())
            .and_then(|()| monitor.flush())
            .expect("QEMU's monitor takes commands");
    };
    tell_monitor("cont\n");

    // 1-2: the defaults, then a site set and read back.
    let defaults = boot_event_value(ResetCause::PowerOn, ConfigSource::Defaults, 0);
    assert_eq!(link.boot_value(), defaults);
    let site = Position::new(0.61, -1.85, 1_520.0);
    acked(&link.send(&Uplink::SetSite(site)), 1);
    acked(&link.send(&Uplink::ReportConfig), 1);
    // The same site again changes nothing: no new version.
    acked(&link.send(&Uplink::SetSite(site)), 1);

    // 3: reboot through the uplink, then through QEMU's monitor.
    acked(&link.send(&Uplink::Reboot), 1);
    let software = boot_event_value(ResetCause::Software, ConfigSource::Flash, 1);
    assert_eq!(link.boot_value(), software);
    acked(&link.send(&Uplink::ReportConfig), 1);
    tell_monitor("system_reset\n");
    let pin = boot_event_value(ResetCause::Pin, ConfigSource::Flash, 1);
    assert_eq!(link.boot_value(), pin);
    // The first raw frame of this boot: streaming has started.
    link.wait_for(BOOT_TIMEOUT, |s| {
        matches!(s, Seen::Raw { .. }).then_some(())
    })
    .expect("raw frames after the reset");

    // 4: random strings at the line's pace, frames counted meanwhile.
    let mut rng = ChaCha8Rng::seed_from_u64(15);
    link.raws.clear();
    link.written = 0;
    let started = Instant::now();
    let mut strings = 0u32;
    while started.elapsed() < FUZZ {
        let string = random_string(&mut rng, strings as u16);
        link.write(&string);
        strings += 1;
        // Drain what came meanwhile, and keep to the line's pace.
        let due = Duration::from_secs_f64(link.written as f64 / LINE_BYTES_PER_S);
        let wait = due.saturating_sub(started.elapsed());
        link.wait_for(wait, |_| None::<()>);
    }
    let fuzz_end = Instant::now();
    let fuzz_wall = (fuzz_end - started).as_secs_f64();
    // A delimiter ends whatever the last string left open.
    link.write(&[0]);
    let fuzz_bytes = link.written;

    // Still answering, with the configuration intact.
    let reply = link.send(&Uplink::ReportConfig);
    acked(&reply, 1);
    let sent_after_reset = link.written;
    // The frames that arrived during the fuzzing (the reader stamped them).
    let during = |at: &Instant| (started..=fuzz_end).contains(at);
    let raws: Vec<(u32, Instant)> = std::mem::take(&mut link.raws)
        .into_iter()
        .filter(|(_, at)| during(at))
        .collect();
    let navs = link.navs.iter().filter(|at| during(at)).count();

    let status = wait_or_kill(&mut qemu, "QEMU", QEMU_TIMEOUT);
    while let Ok(line) = qemu_lines.recv_timeout(Duration::from_secs(5)) {
        qemu_out += &line;
        qemu_out.push('\n');
    }
    assert!(status.success(), "probe-qemu failed: {qemu_out}");
    drop(link);

    let frames = raws.len();
    let counters: Vec<u32> = raws.iter().map(|(c, _)| *c).collect();
    let (first, last) = (counters[0], counters[frames - 1]);
    // Samples the probe's clock says the period held, 20 per second.
    let expected = (last - first + 1) as usize;
    let simulated_s = f64::from(last - first + 1) / RATE_HZ;
    println!(
        "uplink fuzz: {strings} strings, {fuzz_bytes} bytes in {fuzz_wall:.1} s of wall clock; \
         {frames} raw frames and {navs} navigation frames in that time, {expected} samples \
         ({simulated_s:.1} simulated s at 20 Hz); wall-clock rate {:.1} Hz",
        frames as f64 / fuzz_wall
    );
    assert!(strings > 1_000, "{strings} strings");
    // Every sample of the fuzz period came, in order, and was navigated
    // (the last few navigation frames may follow the period's end).
    assert!(
        counters.windows(2).all(|w| w[1] == w[0] + 1),
        "sample counters not consecutive"
    );
    assert!(frames as f64 >= 0.95 * expected as f64);
    assert!(
        navs + 2 >= frames,
        "{navs} navigation frames for {frames} samples"
    );
    // Not wedged: far from no frames at all, whatever the host's load.
    assert!(
        frames as f64 >= 0.25 * fuzz_wall * RATE_HZ,
        "{frames} raw frames in {fuzz_wall:.1} s"
    );
    if let Ok(corrupt) = corrupt.recv_timeout(Duration::from_secs(5)) {
        assert_eq!(corrupt, 0, "corrupt downlink frames");
    }

    // The probe took every byte sent since the reset, each chunk counted.
    let summary = |key| summary_value(&qemu_out, key);
    assert_eq!(
        summary("samples"),
        u64::from(RUN_SECONDS) * 20,
        "{qemu_out}"
    );
    for zero in [
        "frames_dropped",
        "skipped",
        "nav_samples_dropped",
        "cycle_overruns",
    ] {
        assert_eq!(summary(zero), 0, "{zero}: {qemu_out}");
    }
    assert_eq!(
        summary("uplink_bytes") + summary("uplink_overflowed_bytes"),
        sent_after_reset,
        "{qemu_out}"
    );
    assert_eq!(summary("uplink_replies_dropped"), 0, "{qemu_out}");
    // The one good command (resent if a reply was slow), nothing else.
    assert!((1..=3).contains(&summary("uplink_ok")), "{qemu_out}");
    let refused =
        summary("uplink_crc_failures") + summary("uplink_malformed") + summary("uplink_oversized");
    assert!(refused > u64::from(strings) / 4, "{qemu_out}");
    println!(
        "{}",
        qemu_out
            .lines()
            .find(|l| l.contains("samples="))
            .unwrap_or("")
    );
}
