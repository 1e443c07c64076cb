//! `host-sim replay --port` on a pty pair standing in for the probe's
//! serial port: SIGINT or SIGTERM, or a silent line (`--silence`), ends the
//! session cleanly with its summary, and `--save` and `--csv` hold every
//! byte and row that came before.
#![cfg(target_os = "linux")]

use std::fs::File;
use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use rustix::process::{kill_process, Pid, Signal};
use rustix::pty::{grantpt, openpt, ptsname, unlockpt, OpenptFlags};

const HOST_SIM: &str = env!("CARGO_BIN_EXE_host-sim");
/// Generous: only a hang runs into it.
const TIMEOUT: Duration = Duration::from_secs(60);

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("host-sim-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The master side and the path of the slave of a new pty pair.
fn pty_pair() -> (File, String) {
    let master = openpt(OpenptFlags::RDWR | OpenptFlags::NOCTTY).expect("openpt");
    grantpt(&master).expect("grantpt");
    unlockpt(&master).expect("unlockpt");
    let name = ptsname(&master, Vec::new()).expect("ptsname");
    (
        File::from(master),
        name.into_string().expect("a UTF-8 path"),
    )
}

/// The tool's stdout lines, forwarded to a channel.
fn lines_of(child: &mut Child) -> mpsc::Receiver<String> {
    let (tx, rx) = mpsc::channel();
    let stdout = child.stdout.take().expect("piped");
    std::thread::spawn(move || {
        for line in BufReader::new(stdout).lines().map_while(Result::ok) {
            if tx.send(line).is_err() {
                break;
            }
        }
    });
    rx
}

/// Waits for a line containing `needle`; everything seen goes to `seen`.
fn wait_for(lines: &mpsc::Receiver<String>, needle: &str, seen: &mut String) {
    let deadline = Instant::now() + TIMEOUT;
    while let Some(left) = deadline.checked_duration_since(Instant::now()) {
        match lines.recv_timeout(left) {
            Ok(line) => {
                seen.push_str(&line);
                seen.push('\n');
                if line.contains(needle) {
                    return;
                }
            }
            Err(_) => break,
        }
    }
    panic!("no line with {needle:?} in:\n{seen}");
}

fn wait_exit(child: &mut Child) -> std::process::ExitStatus {
    let deadline = Instant::now() + TIMEOUT;
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            return status;
        }
        if Instant::now() > deadline {
            child.kill().ok();
            panic!("host-sim replay --port did not end");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// A simulated probe's 6 s capture (boot event, 120 raw and navigation
/// frames).
fn capture(dir: &Path) -> Vec<u8> {
    let path = dir.join("run.bin");
    let out = Command::new(HOST_SIM)
        .args(["simulate", "--duration", "6", "-o"])
        .arg(&path)
        .output()
        .unwrap();
    assert!(out.status.success());
    std::fs::read(path).unwrap()
}

/// Streams `bytes` to the tool over a pty, then ends the session with
/// `signal` (or, with none, lets `--silence` end it); returns its output
/// and exit code, the saved bytes and the CSV.
fn live_session(
    dir: &Path,
    bytes: &[u8],
    signal: Option<Signal>,
) -> (String, i32, Vec<u8>, String) {
    let (mut master, slave) = pty_pair();
    let (save, csv) = (dir.join("saved.bin"), dir.join("live.csv"));
    let silence = if signal.is_some() { "600" } else { "0.5" };
    let mut tool = Command::new(HOST_SIM)
        .args(["replay", "--port", &slave, "--silence", silence, "--save"])
        .arg(&save)
        .arg("--csv")
        .arg(&csv)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    let lines = lines_of(&mut tool);
    let mut seen = String::new();
    wait_for(&lines, "listening on /dev/pts/", &mut seen);
    master.write_all(bytes).unwrap();
    master.flush().unwrap();
    // Every frame reached the tool (its status line counts them).
    wait_for(&lines, "| frames 241 lost 0", &mut seen);
    if let Some(signal) = signal {
        kill_process(Pid::from_child(&tool), signal).unwrap();
    }
    let status = wait_exit(&mut tool);
    while let Ok(line) = lines.recv_timeout(Duration::from_secs(5)) {
        seen.push_str(&line);
        seen.push('\n');
    }
    drop(master);
    let saved = std::fs::read(&save).unwrap();
    let rows = std::fs::read_to_string(&csv).unwrap();
    (seen, status.code().unwrap_or(-1), saved, rows)
}

#[test]
fn a_signal_or_a_silent_line_ends_a_live_session_with_everything_kept() {
    let dir = temp_dir("live");
    let bytes = capture(&dir);
    for (signal, end) in [
        (Some(Signal::INT), "end of stream    interrupted"),
        (Some(Signal::TERM), "end of stream    interrupted"),
        (None, "end of stream    no byte for 0.5 s"),
    ] {
        let (out, code, saved, rows) = live_session(&dir, &bytes, signal);
        assert_eq!(code, 0, "{signal:?}: {out}");
        for expected in [
            end,
            "replay parity    120 identical, 0 different, 0 not compared",
        ] {
            assert!(
                out.contains(expected),
                "{signal:?}: no {expected:?} in:\n{out}"
            );
        }
        assert!(
            saved == bytes,
            "{signal:?}: --save holds {} of {} bytes",
            saved.len(),
            bytes.len()
        );
        assert_eq!(rows.lines().count(), 1 + 120, "{signal:?}");
        assert!(
            rows.lines().skip(1).all(|r| r.ends_with(",yes")),
            "{signal:?}"
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}
