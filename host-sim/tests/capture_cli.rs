//! `host-sim decode` and `replay` on the command line: files that are not
//! probe captures are refused, replay's exit statuses tell parity, a loss
//! and post-processing apart, and every printing command survives a closed
//! standard output (`| head -1`).

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

use host_sim::formats::capture::{self, CaptureWriter};
use mwd_core::protocol::Payload;

const HOST_SIM: &str = env!("CARGO_BIN_EXE_host-sim");

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("host-sim-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn host_sim(args: &[&str]) -> Output {
    Command::new(HOST_SIM).args(args).output().unwrap()
}

fn text(out: &Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr)
}

/// A simulated probe's capture of `seconds`.
fn simulated(dir: &Path, name: &str, seconds: u32) -> PathBuf {
    let path = dir.join(name);
    let out = host_sim(&[
        "simulate",
        "--duration",
        &seconds.to_string(),
        "-o",
        path.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", text(&out));
    path
}

#[test]
fn files_that_are_not_probe_captures_are_refused() {
    let dir = temp_dir("not-capture");
    let csv = dir.join("samples.csv");
    std::fs::write(&csv, "time_s,gyro_x_rad_s\n0.0,0.001\n0.05,0.002\n").unwrap();
    let empty = dir.join("empty.bin");
    std::fs::write(&empty, b"").unwrap();
    let random = dir.join("random.bin");
    // A fixed pseudo-random byte stream (xorshift), 64 KiB.
    let mut x = 0x2545_f491_4f6c_dd1du64;
    let bytes: Vec<u8> = (0..65_536)
        .map(|_| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x as u8
        })
        .collect();
    std::fs::write(&random, bytes).unwrap();
    for file in [&csv, &empty, &random] {
        for command in ["decode", "replay"] {
            let out = host_sim(&[command, file.to_str().unwrap()]);
            assert_eq!(
                out.status.code(),
                Some(1),
                "{command} {}: {}",
                file.display(),
                text(&out)
            );
            assert!(
                text(&out).contains("is not a probe capture"),
                "{command} {}: {}",
                file.display(),
                text(&out)
            );
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn replay_exit_statuses_tell_parity_restart_loss_and_post_processing_apart() {
    let dir = temp_dir("replay-status");
    let run = simulated(&dir, "run.bin", 8);
    let bytes = std::fs::read(&run).unwrap();
    let path = |name: &str, content: &[u8]| {
        let p = dir.join(name);
        std::fs::write(&p, content).unwrap();
        p.to_str().unwrap().to_string()
    };
    // Parity, also across a restart.
    let twice = path("twice.bin", &[bytes.clone(), bytes.clone()].concat());
    let out = host_sim(&["replay", &twice]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    assert!(text(&out).contains("probe restarts   1"), "{}", text(&out));
    assert!(
        text(&out).contains("0 frames lost, 1 restarts"),
        "{}",
        text(&out)
    );
    assert!(
        text(&out).contains("320 identical, 0 different, 0 not compared"),
        "{}",
        text(&out)
    );
    // The raw frame of sample 69 lost: compared up to sample 68, the rest
    // said, the lost frame counted among those not compared, status 2.
    let lost = path("lost.bin", &capture::without_frame(&bytes, 139));
    let csv = dir.join("lost.csv");
    let out = host_sim(&["replay", &lost, "--csv", csv.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out));
    assert!(
        text(&out).contains(
            "69 identical, 0 different, 92 not compared (1 of them frames lost in the capture)"
        ),
        "{}",
        text(&out)
    );
    assert!(
        text(&out).contains("not compared from sample 70 on"),
        "{}",
        text(&out)
    );
    let rows = std::fs::read_to_string(&csv).unwrap();
    assert!(
        rows.lines().nth(70).unwrap().ends_with(",unchecked"),
        "{rows}"
    );
    // A probe solution that is not what the navigation makes: status 3.
    let mut writer = CaptureWriter::new(Vec::new());
    for frame in capture::decode_bytes(&bytes).frames {
        let mut payload = frame.payload;
        if let Payload::Nav(nav) = &mut payload {
            // A fine-alignment sample: during the coarse alignment the
            // attitude is a NaN placeholder, which no offset changes.
            if nav.sample_counter == 150 {
                nav.attitude[0] += 1e-6;
            }
        }
        writer.write(&payload).unwrap();
    }
    let changed = path("changed.bin", &writer.finish().unwrap());
    let out = host_sim(&["replay", &changed]);
    assert_eq!(out.status.code(), Some(3), "{}", text(&out));
    assert!(
        text(&out).contains("159 identical, 1 different"),
        "{}",
        text(&out)
    );
    let out = host_sim(&["replay", &twice, "--lat", "10"]);
    // Post-processing at another site: differences are expected, status 0.
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    assert!(text(&out).contains("post-processed"), "{}", text(&out));
    std::fs::remove_dir_all(&dir).ok();
}

/// Runs `args` with standard output a pipe whose reader is already gone,
/// as `host-sim ... | head -1` once `head` has exited.
fn into_closed_pipe(dir: &Path, args: &[&str]) -> Output {
    let mut child = Command::new(HOST_SIM)
        .args(args)
        .current_dir(dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    child.wait_with_output().unwrap()
}

#[test]
fn every_printing_command_survives_a_closed_standard_output() {
    let dir = temp_dir("epipe");
    let run = simulated(&dir, "run.bin", 6);
    let run = run.to_str().unwrap();
    let commands: [&[&str]; 6] = [
        &["decode", run],
        &["replay", run],
        &["demo"],
        &["observability"],
        &["paper", "mgwd", "--runs", "2"],
        &["simulate", "--duration", "2", "-o", "-"],
    ];
    for args in commands {
        let out = into_closed_pipe(&dir, args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(0), "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
    }
    std::fs::remove_dir_all(&dir).ok();
}
