//! The QEMU probe's survey commands over its serial line (issue 15, item
//! 1: start surveying, take a station now, toolface indexing), end to end
//! through the firmware's uplink service and navigator. The QEMU probe's
//! parts are still (`hil_mock::StillProbe`), so once it navigates every
//! moment after the still detector's delay is a station in progress.
//!
//! 1. A station asked for during the coarse alignment: NAK not ready.
//! 2. Start surveying once the fine alignment has run its first second:
//!    ACK, and the navigation frames say navigating from then on (long
//!    before the 60 s alignment would have ended).
//! 3. Toolface indexing (2 positions of 3 s): ACK, then a station frame
//!    flagged "indexing dwell" once the probe has been still for 3 s.
//! 4. Take a station now: ACK, and right after it the same still period's
//!    frame again, now also flagged "requested".
//! 5. The whole downlink, replayed on the host (`host_sim::replay`, with
//!    the commands the test sent as the uplink log): every navigation
//!    frame and every station frame identical bit for bit, each command
//!    carried out at the probe's sample.
//!
//! The probe runs at its real pace (`-icount shift=0,sleep=on`), so the
//! run takes [`RUN_SECONDS`]. qemu-system-arm must be installed: without it
//! this test fails, it does not skip. Linux only (ptys of /dev/pts).
#![cfg(target_os = "linux")]

use std::fs::File;
use std::io::{BufRead, BufReader, Read, Write};
use std::process::{Command, Stdio};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use hil_mock::StillProbe;
use host_sim::formats::capture;
use host_sim::replay::commands::CommandOutcome;
use host_sim::replay::{self, Replayer};
use mwd_core::conventions::{wrap_pi, DrillingAngles};
use mwd_core::earth::Position;
use mwd_core::protocol::frame::{nav_mode, station_flags};
use mwd_core::protocol::uplink::reply::decode_reply_body;
use mwd_core::protocol::uplink::{
    encode_command, Command as Uplink, IndexingProcedure, NakReason, Reply, ReplyStatus,
    MAX_COMMAND_WIRE_LEN,
};
use mwd_core::protocol::{Decoder, Payload, StationSurvey};
use system_tests::{build_firmware_for, require_qemu, wait_or_kill};

/// Simulated seconds the probe streams before it ends its run.
const RUN_SECONDS: u32 = 20;
/// Samples after which the surface starts surveying: the 5 s coarse
/// alignment and the fine alignment's first 1.95 s
/// (`navigator::commands::MIN_FINE_ALIGNMENT_SAMPLES`), with 0.55 s spare.
const SURVEY_AT_SAMPLE: u32 = 150;
const DWELL_S: u16 = 3;
/// Only a hang reaches these.
const REPLY_TIMEOUT: Duration = Duration::from_secs(3);
const FRAME_TIMEOUT: Duration = Duration::from_secs(30);
const QEMU_TIMEOUT: Duration = Duration::from_secs(300);

/// What the downlink brought.
#[derive(Debug)]
enum Seen {
    Raw(u32),
    Nav { counter: u32, mode: u8 },
    Station(StationSurvey),
    Reply(Reply),
}

/// Reads the downlink until the pty closes; returns every byte read.
fn read_downlink(mut pty: File, to: mpsc::Sender<Seen>) -> JoinHandle<Vec<u8>> {
    std::thread::spawn(move || {
        let mut decoder = Decoder::new();
        let mut bytes = Vec::new();
        let mut buf = [0u8; 512];
        while let Ok(n) = pty.read(&mut buf) {
            if n == 0 {
                break;
            }
            bytes.extend_from_slice(&buf[..n]);
            for &b in &buf[..n] {
                let seen = match decoder.push(b).map(|f| f.payload) {
                    Some(Payload::Raw(r)) => Seen::Raw(r.sample_counter),
                    Some(Payload::Nav(s)) => Seen::Nav {
                        counter: s.sample_counter,
                        mode: s.mode,
                    },
                    Some(Payload::Station(s)) => Seen::Station(s),
                    Some(Payload::Event(_)) => continue,
                    None => match decoder.unknown_body().map(decode_reply_body) {
                        Some(Ok((_, reply))) => Seen::Reply(reply),
                        _ => continue,
                    },
                };
                // The test may have stopped listening: keep the bytes.
                let _ = to.send(seen);
            }
        }
        bytes
    })
}

struct Link {
    pty: File,
    seen: Receiver<Seen>,
    next_seq: u16,
    /// Every command byte sent: the uplink log of the replay.
    uplink: Vec<u8>,
}

impl Link {
    /// Waits for what `wanted` picks; everything before it is passed over.
    fn wait_for<T>(&mut self, timeout: Duration, mut wanted: impl FnMut(&Seen) -> Option<T>) -> T {
        let deadline = Instant::now() + timeout;
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            match self.seen.recv_timeout(left) {
                Ok(seen) => {
                    if let Some(found) = wanted(&seen) {
                        return found;
                    }
                }
                Err(RecvTimeoutError::Timeout) => panic!("nothing wanted came in {timeout:?}"),
                Err(RecvTimeoutError::Disconnected) => panic!("the pty closed"),
            }
        }
    }

    /// Sends `command` once and returns its reply and the frame that
    /// followed it, whatever it was.
    fn send(&mut self, command: &Uplink) -> (Reply, Seen) {
        let seq = self.next_seq;
        self.next_seq += 1;
        let mut wire = [0u8; MAX_COMMAND_WIRE_LEN];
        let n = encode_command(seq, command, &mut wire).expect("encode a command");
        self.uplink.extend_from_slice(&wire[..n]);
        self.pty
            .write_all(&wire[..n])
            .and_then(|()| self.pty.flush())
            .expect("write to the pty");
        let reply = self.wait_for(REPLY_TIMEOUT, |s| match s {
            Seen::Reply(r) if r.command_seq == seq => Some(*r),
            _ => None,
        });
        let next = self.wait_for(REPLY_TIMEOUT, |s| match s {
            Seen::Raw(c) => Some(Seen::Raw(*c)),
            Seen::Nav { counter, mode } => Some(Seen::Nav {
                counter: *counter,
                mode: *mode,
            }),
            Seen::Station(s) => Some(Seen::Station(*s)),
            Seen::Reply(r) => Some(Seen::Reply(*r)),
        });
        (reply, next)
    }
}

#[test]
fn the_qemu_probe_starts_surveying_reports_a_dwell_and_takes_a_station_on_request() {
    require_qemu();
    let elf = build_firmware_for("board-qemu", "commands", Some(RUN_SECONDS));
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
            .recv_timeout(FRAME_TIMEOUT)
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
    let downlink = read_downlink(pty.try_clone().expect("a second handle"), seen_tx);
    let mut link = Link {
        pty,
        seen,
        next_seq: 1,
        uplink: Vec::new(),
    };
    let mut monitor = qemu.stdin.take().expect("piped");
    monitor
        .write_all(b"cont\n")
        .and_then(|()| monitor.flush())
        .expect("QEMU's monitor takes commands");

    // 1: aligning.
    link.wait_for(FRAME_TIMEOUT, |s| matches!(s, Seen::Raw(_)).then_some(()));
    let (reply, _) = link.send(&Uplink::TakeStation);
    assert_eq!(
        reply.status,
        ReplyStatus::Nak(NakReason::NotReady),
        "{reply:?}"
    );

    // 2: start surveying once the fine alignment may end.
    link.wait_for(FRAME_TIMEOUT, |s| {
        matches!(s, Seen::Raw(c) if *c >= SURVEY_AT_SAMPLE).then_some(())
    });
    let (reply, _) = link.send(&Uplink::StartSurveying);
    assert_eq!(reply.status, ReplyStatus::Ack, "{reply:?}");
    let (counter, mode) = link.wait_for(FRAME_TIMEOUT, |s| match s {
        Seen::Nav { counter, mode } => Some((*counter, *mode)),
        _ => None,
    });
    assert_eq!(mode, nav_mode::NAVIGATING, "sample {counter}");
    assert!(counter < 60 * 20, "navigating at sample {counter}");

    // 3: indexing; the still probe's first dwell.
    let procedure = IndexingProcedure {
        positions: 2,
        dwell_s: DWELL_S,
    };
    let (reply, _) = link.send(&Uplink::IndexToolface(procedure));
    assert_eq!(reply.status, ReplyStatus::Ack, "{reply:?}");
    let dwell = link.wait_for(FRAME_TIMEOUT, |s| match s {
        Seen::Station(st) => Some(*st),
        _ => None,
    });
    assert_ne!(dwell.flags & station_flags::INDEXING_DWELL, 0, "{dwell:?}");
    assert_eq!(dwell.station, 1, "{dwell:?}");
    // The simulated parts' attitude: inclination and toolface within
    // their 3 sigma (the azimuth is still the coarse alignment's).
    let truth = DrillingAngles::from_euler(&StillProbe::paper_test(1).attitude);
    let errors = [
        f64::from(dwell.angles[0]) - truth.inclination,
        wrap_pi(f64::from(dwell.angles[2]) - truth.toolface),
    ];
    let sigmas = [dwell.angles_std[0], dwell.angles_std[2]].map(f64::from);
    for (error, sigma) in errors.iter().zip(sigmas) {
        assert!(
            sigma > 0.0 && error.abs() < 3.0 * sigma,
            "error {error} rad, sigma {sigma}: {dwell:?}"
        );
    }

    // 4: a station on request: the same still period's frame, right after
    // the ACK.
    let (reply, next) = link.send(&Uplink::TakeStation);
    assert_eq!(reply.status, ReplyStatus::Ack, "{reply:?}");
    let Seen::Station(requested) = next else {
        panic!("after the ACK: {next:?}")
    };
    assert_eq!(
        (
            requested.station,
            requested.start_sample,
            requested.end_sample
        ),
        (dwell.station, dwell.start_sample, dwell.end_sample)
    );
    assert_eq!(
        requested.flags,
        dwell.flags | station_flags::REQUESTED,
        "{requested:?}"
    );

    let status = wait_or_kill(&mut qemu, "QEMU", QEMU_TIMEOUT);
    while let Ok(line) = qemu_lines.recv_timeout(Duration::from_secs(5)) {
        qemu_out += &line;
        qemu_out.push('\n');
    }
    assert!(status.success(), "probe-qemu failed: {qemu_out}");
    // QEMU closed its end of the pty: the reader has every byte.
    drop(link.pty);
    let bytes = downlink.join().expect("the downlink reader");
    let replayed = replay_on_the_host(&bytes, &link.uplink);
    println!(
        "qemu commands: surveying from sample {counter}; dwell station {} samples {}..{}, \
         inclination error {:.3} deg (sigma {:.3}), toolface error {:.3} deg (sigma {:.3})",
        dwell.station,
        dwell.start_sample,
        dwell.end_sample,
        errors[0].to_degrees(),
        sigmas[0].to_degrees(),
        errors[1].to_degrees(),
        sigmas[1].to_degrees()
    );
    println!("{replayed}");
}

/// Replays the probe's downlink on the host with the commands sent:
/// every navigation and station frame must be identical bit for bit.
fn replay_on_the_host(bytes: &[u8], uplink: &[u8]) -> String {
    let capture = capture::decode_bytes(bytes);
    // Nothing lost or damaged on the way, but the tail: when QEMU exits,
    // the kernel discards pty bytes the reader had not taken yet (see
    // qemu_pty.rs), which leaves at most one cut frame at the end. Every
    // command was answered long before the end of the run.
    let s = &capture.stats;
    assert_eq!((s.lost, s.crc_errors), (0, 0), "{s:?}");
    assert!(s.malformed <= 1, "{s:?}");
    let mut replayer = Replayer::new(Position::paper_site());
    for (seq, command) in replay::commands::decode_uplink_log(uplink) {
        replayer.knows_sent_command(seq, &command);
    }
    for received in capture.in_order() {
        replayer.push_received(received);
    }
    let outcomes: Vec<_> = replayer.commands().iter().map(|c| c.outcome).collect();
    assert_eq!(
        outcomes,
        [
            CommandOutcome::Refused,
            CommandOutcome::Replayed,
            CommandOutcome::Replayed,
            CommandOutcome::Replayed
        ],
        "{:?}",
        replayer.commands()
    );
    assert!(
        replayer.step_losses().is_empty(),
        "{:?}",
        replayer.step_losses()
    );
    let surveying_after = replayer.commands()[1]
        .after_sample
        .expect("start surveying came after a navigated sample");
    let (_, st) = replayer.stations();
    assert_eq!(
        (
            st.replayed,
            st.probe,
            st.matched,
            st.mismatched,
            st.unchecked
        ),
        (2, 2, 2, 0, 0),
        "{st:?}"
    );
    let (_, summary) = replayer.finish();
    assert_eq!(
        (summary.mismatched, summary.unchecked),
        (0, 0),
        "{summary:?}"
    );
    assert_eq!(summary.matched, summary.probe_solutions, "{summary:?}");
    // All but (at most) the tail's last few samples.
    let samples = u64::from(RUN_SECONDS) * 20;
    assert!(
        (samples - 20..=samples).contains(&summary.raw_frames),
        "{summary:?}"
    );
    format!(
        "host replay: {} navigation frames and {} station frames identical bit for bit; \
         start surveying replayed after sample {surveying_after}",
        summary.matched, st.matched
    )
}
