//! Outputs that cannot be written: an error (exit 1) that claims no
//! success and leaves no partial file; a reader that went away (`| head`)
//! ends the output quietly (exit 0, as Unix tools do).
mod common;

use common::{plan, run, s, scratch};
use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Command, Stdio};

/// A short capture, simulated in `dir`.
fn capture(dir: &Path) -> std::path::PathBuf {
    let bin = dir.join("run.bin");
    let sim = run(&["simulate", "--duration", "5", "-o", s(&bin)]);
    assert_eq!(sim.code, Some(0), "{}", sim.stderr);
    bin
}

/// Runs `host-sim args` with its standard output to `/dev/full`.
fn to_full_disk(args: &[&str]) -> (Option<i32>, String) {
    let full = std::fs::OpenOptions::new()
        .write(true)
        .open("/dev/full")
        .expect("/dev/full");
    let out = Command::new(env!("CARGO_BIN_EXE_host-sim"))
        .args(args)
        .stdout(full)
        .stderr(Stdio::piped())
        .output()
        .unwrap();
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into(),
    )
}

#[test]
fn a_full_disk_behind_standard_output_is_an_error() {
    if !Path::new("/dev/full").exists() {
        return;
    }
    let dir = scratch("writes", "full-stdout");
    let bin = capture(&dir);
    for args in [
        vec!["decode", s(&bin)],
        vec!["replay", s(&bin)],
        vec!["align", s(&bin), "--calibration", "none"],
        vec!["observability"],
    ] {
        let (code, stderr) = to_full_disk(&args);
        assert_eq!(code, Some(1), "{args:?}: {stderr}");
        assert!(
            stderr.contains("error: writing to standard output"),
            "{args:?}: {stderr}"
        );
        // said once, not once per line
        assert_eq!(stderr.matches("writing to standard output").count(), 1);
    }
}

#[test]
fn an_output_file_that_cannot_be_written_is_an_error_and_none_is_left() {
    let dir = scratch("writes", "files");
    let bin = capture(&dir);
    if Path::new("/dev/full").exists() {
        let out = run(&["decode", s(&bin), "--csv", "/dev/full"]);
        assert_eq!(out.code, Some(1), "{}", out.stderr);
        assert!(out.stderr.contains("/dev/full"), "{}", out.stderr);
        assert!(!out.stdout.contains("csv"), "no claim: {}", out.stdout);
    }
    // a later output that cannot be created: the capture is not left
    let lateral = dir.join("lateral.bin");
    let (short, depth) = (plan("qemu-short.json"), dir.join("no-such-dir/depth.csv"));
    let mut args = vec!["simulate", "--motion", "lateral", "--plan", s(&short)];
    args.extend(["-o", s(&lateral), "--depth-log", s(&depth)]);
    let out = run(&args);
    assert_eq!(out.code, Some(1), "{}", out.stderr);
    assert!(out.stderr.contains("depth.csv"), "{}", out.stderr);
    assert!(!lateral.exists());
    // nothing half-written left behind under another name either
    let names: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names, vec!["run.bin".to_string()], "{names:?}");
}

#[test]
fn a_reader_that_went_away_ends_the_output_quietly() {
    // a minute of samples as CSV on standard output: more than a pipe holds
    let mut child = Command::new(env!("CARGO_BIN_EXE_host-sim"))
        .args(["simulate", "--duration", "60", "-o", "-"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut first = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut first)
        .unwrap();
    // the reader is dropped here: `| head -1`
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(0));
    assert_eq!(String::from_utf8_lossy(&out.stderr), "");
}
