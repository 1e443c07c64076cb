//! The QEMU probe read live over a serial port: QEMU puts
//! the probe's UART on a pseudo-terminal (`-serial pty`) and
//! `host-sim replay --port /dev/pts/N --baud 115200` reads it through the
//! serialport crate, the way an engineer connects to a real probe, until
//! the probe ends its run through semihosting and the pty closes.
//!
//! A pty is not a file, and three things follow:
//! - QEMU drops UART bytes while no one holds the other side open: QEMU
//!   starts halted (`-S`), the tool opens the port and says so, and only
//!   then does the test tell QEMU's monitor (on its stdin) to `cont`.
//! - A full pty stalls QEMU's UART, and with `sleep=off` idle time is
//!   skipped, so a reader slower than the emulator would make the probe drop
//!   frames: here the probe runs at its real pace (`sleep=on`, a 10 s run),
//!   as a real probe does at 115200 baud.
//! - When QEMU exits its pty master closes, and the kernel discards bytes
//!   the reader has not taken yet: the test holds a duplicate of the master
//!   (pidfd_getfd) until the tool has shown every frame, then lets go; the
//!   tool sees the port close and prints its summary.
//!
//! Counts are per simulated second (the probe's own timestamps), never
//! wall-clock timings; the timeouts only guard against hangs.
//!
//! qemu-system-arm must be installed (`scripts/test-all.sh` installs it):
//! without it this test fails, it does not skip. Linux only (ptys of
//! /dev/pts, pidfd_getfd), like the CI that runs it.
#![cfg(target_os = "linux")]

use std::io::{BufRead, BufReader, Read, Write};
use std::process::{Command, Stdio};
use std::sync::mpsc::{self, Receiver};
use std::time::Duration;

use std::os::fd::OwnedFd;

use rustix::process::{pidfd_getfd, pidfd_open, Pid, PidfdFlags, PidfdGetfdFlags};
use system_tests::{build_firmware_for, build_host_sim, require_qemu, summary_value, wait_or_kill};

/// Simulated seconds of this run (`PROBE_QEMU_RUN_SECONDS`), in real time.
const RUN_SECONDS: usize = 10;
const RATE_HZ: usize = 20;
/// Far above the few seconds the run takes; only a hang reaches it.
const TIMEOUT: Duration = Duration::from_secs(300);

/// A duplicate of QEMU's pty master (the one fd of QEMU's that points at
/// /dev/ptmx), so the pty outlives QEMU until the test drops it.
fn hold_pty_master(qemu_pid: u32) -> OwnedFd {
    let fd_dir = format!("/proc/{qemu_pid}/fd");
    let master = std::fs::read_dir(&fd_dir)
        .expect("QEMU's open files")
        .filter_map(Result::ok)
        .find(|entry| {
            std::fs::read_link(entry.path()).is_ok_and(|t| t.to_string_lossy().contains("ptmx"))
        })
        .and_then(|entry| entry.file_name().to_str()?.parse::<i32>().ok())
        .unwrap_or_else(|| panic!("no pty master among {fd_dir}"));
    let pid = Pid::from_raw(qemu_pid as i32).expect("a live process id");
    let pidfd = pidfd_open(pid, PidfdFlags::empty()).expect("pidfd_open of QEMU");
    pidfd_getfd(&pidfd, master, PidfdGetfdFlags::empty())
        .expect("a duplicate of QEMU's pty master (pidfd_getfd, Linux >= 5.6)")
}

/// Sends every line `from` prints into `to`, from a thread of its own (a
/// full pipe must never stall the child).
fn forward_lines(from: impl Read + Send + 'static, to: mpsc::Sender<String>) {
    std::thread::spawn(move || {
        for line in BufReader::new(from).lines() {
            let Ok(line) = line else { break };
            if to.send(line).is_err() {
                break;
            }
        }
    });
}

/// Waits for a line containing `needle`; returns it and what came before.
fn wait_for_line(lines: &Receiver<String>, needle: &str, seen: &mut String) -> String {
    loop {
        match lines.recv_timeout(TIMEOUT) {
            Ok(line) => {
                seen.push_str(&line);
                seen.push('\n');
                if line.contains(needle) {
                    return line;
                }
            }
            Err(e) => panic!("no line with {needle:?} ({e}); output so far:\n{seen}"),
        }
    }
}

/// The rest of a child's output after it exited.
fn drain(lines: &Receiver<String>, seen: &mut String) {
    // The forwarding thread ends at EOF, which closes the channel.
    while let Ok(line) = lines.recv_timeout(TIMEOUT) {
        seen.push_str(&line);
        seen.push('\n');
    }
}

#[test]
fn host_sim_reads_the_qemu_probe_live_over_a_pty() {
    require_qemu();
    let elf = build_firmware_for("board-qemu", "pty", Some(RUN_SECONDS as u32));
    let host_sim = build_host_sim();

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
    let (qemu_tx, qemu_lines) = mpsc::channel();
    forward_lines(qemu.stdout.take().expect("piped"), qemu_tx.clone());
    forward_lines(qemu.stderr.take().expect("piped"), qemu_tx);
    let mut qemu_out = String::new();
    // "char device redirected to /dev/pts/N (label serial0)"
    let line = wait_for_line(&qemu_lines, "redirected to /dev/pts/", &mut qemu_out);
    let pty = line
        .split_whitespace()
        .find(|w| w.starts_with("/dev/pts/"))
        .expect("a pty path")
        .to_string();
    let master = hold_pty_master(qemu.id());

    let csv = std::env::temp_dir().join(format!("qemu-pty-{}.csv", std::process::id()));
    let mut tool = Command::new(&host_sim)
        .args(["replay", "--port", &pty, "--baud", "115200", "--csv"])
        .arg(&csv)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start host-sim");
    let (tool_tx, tool_lines) = mpsc::channel();
    forward_lines(tool.stdout.take().expect("piped"), tool_tx.clone());
    forward_lines(tool.stderr.take().expect("piped"), tool_tx);
    let mut tool_out = String::new();
    wait_for_line(&tool_lines, "listening on /dev/pts/", &mut tool_out);

    // The port is open: let the probe run.
    let mut monitor = qemu.stdin.take().expect("piped");
    monitor
        .write_all(b"cont\n")
        .and_then(|()| monitor.flush())
        .expect("QEMU's monitor takes `cont`");
    let qemu_status = wait_or_kill(&mut qemu, "QEMU", TIMEOUT);
    drop(monitor);
    drain(&qemu_lines, &mut qemu_out);
    assert!(qemu_status.success(), "probe-qemu failed: {qemu_out}");
    // Every frame the probe sent is in the tool's running display (it
    // refreshes on a quiet line too) before the pty goes away.
    let samples = summary_value(&qemu_out, "samples") as usize;
    let all_frames = format!("| frames {} lost", 2 * samples + 1);
    wait_for_line(&tool_lines, &all_frames, &mut tool_out);
    drop(master);
    let tool_status = wait_or_kill(&mut tool, "host-sim replay --port", TIMEOUT);
    drain(&tool_lines, &mut tool_out);
    assert!(tool_status.success(), "host-sim replay failed:\n{tool_out}");

    // The probe sent everything: nothing dropped on board.
    assert_eq!(summary_value(&qemu_out, "frames_dropped"), 0, "{qemu_out}");
    assert_eq!(samples, RUN_SECONDS * RATE_HZ);

    // The tool saw the pty close, showed a running display, and its
    // summary says the link was clean and the replay identical.
    for expected in [
        "end of stream    port closed",
        &format!(
            "frames           {} good: raw sample {samples}, navigation {samples}, event 1,",
            2 * samples + 1
        ),
        "sequence gaps    0 frames lost, 0 restarts",
        "corrupt          0 CRC failures, 0 malformed",
        "garbage          0 bytes",
        &format!("raw frames       {samples}"),
        &format!("replay parity    {samples} identical, 0 different"),
    ] {
        assert!(
            tool_out.contains(expected),
            "no {expected:?} in:\n{tool_out}"
        );
    }
    let status_lines = tool_out.lines().filter(|l| l.contains(" | inc ")).count();
    assert!(status_lines >= 1, "no running display in:\n{tool_out}");

    // 20 raw frames in every simulated second, consecutive, each replayed
    // and identical to the probe's solution (one CSV row per raw frame).
    let text = std::fs::read_to_string(&csv).expect("the replay's CSV");
    let _ = std::fs::remove_file(&csv);
    let mut per_second = [0usize; RUN_SECONDS];
    let mut rows = 0;
    for (n, row) in text.lines().skip(1).enumerate() {
        let cols: Vec<&str> = row.split(',').collect();
        assert_eq!(cols[0].parse::<usize>().ok(), Some(n), "row {row}");
        let time_s: f64 = cols[1].parse().expect("time column");
        assert_eq!(time_s, n as f64 / RATE_HZ as f64, "row {row}");
        per_second[time_s as usize] += 1;
        assert_eq!(cols.last(), Some(&"yes"), "row {row}");
        rows += 1;
    }
    assert_eq!(rows, samples);
    assert!(per_second.iter().all(|&n| n == RATE_HZ), "{per_second:?}");
}
