//! What the CLI test files share: running the binary and a scratch
//! directory per test.
#![allow(dead_code)] // each test file uses its own part of it

use std::path::{Path, PathBuf};
use std::process::Command;

/// One run of the binary: exit code and both outputs as text.
pub struct Run {
    pub code: Option<i32>,
    pub stdout: String,
    pub stderr: String,
}

/// Runs `host-sim` with `args`.
pub fn run(args: &[&str]) -> Run {
    let out = Command::new(env!("CARGO_BIN_EXE_host-sim"))
        .args(args)
        .output()
        .expect("host-sim runs");
    Run {
        code: out.status.code(),
        stdout: String::from_utf8_lossy(&out.stdout).into(),
        stderr: String::from_utf8_lossy(&out.stderr).into(),
    }
}

/// Runs `host-sim` with owned `args` and asserts it succeeded (exit 0).
pub fn succeeded(args: &[String]) -> Run {
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let out = run(&args);
    assert_eq!(out.code, Some(0), "{args:?}: {}", out.stderr);
    out
}

/// A file the test reads whole, its path named if it cannot.
pub fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// A fresh directory for one test: `<tag>-<pid>-<name>` in the temp dir.
pub fn scratch(tag: &str, name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("{tag}-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A path as the `&str` an argument list takes.
pub fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The run was refused: exit 1 (an error, the command line's too),
/// `needle` in its stderr, and no panic.
pub fn refused(run: &Run, needle: &str) {
    assert!(
        matches!(run.code, Some(1)),
        "exit {:?}, stderr {}",
        run.code,
        run.stderr
    );
    assert!(
        run.stderr.contains(needle),
        "`{needle}` not in stderr: {}",
        run.stderr
    );
    assert!(!run.stderr.contains("panicked"), "{}", run.stderr);
}

/// The job of the tied-in lateral: the parent well's survey at the window
/// (the probe's tie-in attitude) and the survey's tie-on there.
pub const TIED_IN_JOB: &str = r#"{ "format": "mwd-job", "version": 1,
  "site": { "latitude_deg": 45.77755, "longitude_deg": 126.687898, "height_m": 124.0 },
  "tie_in": { "inclination_deg": 90.0, "azimuth_deg": 120.0, "toolface_deg": 0.0,
              "inclination_sigma_deg": 0.1, "azimuth_sigma_deg": 0.5, "toolface_sigma_deg": 0.3 },
  "survey": { "tie_on": { "md": 3000.0, "tvd": 2450.0, "north": 420.0, "east": 310.0 } } }"#;

/// A built-in plan of the simulator (`host-sim/data/plans/`).
pub fn plan(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("data/plans")
        .join(name)
}

/// The short lateral (`qemu-short.json`, seed 3) simulated by a probe
/// configured with [`TIED_IN_JOB`], in `dir`: the capture, its depth log
/// and the job file.
pub fn simulate_tied_in(dir: &Path) -> (PathBuf, PathBuf, PathBuf) {
    simulate_tied_in_on(dir, "qemu-short.json")
}

/// [`simulate_tied_in`] along the built-in plan `plan_name` (seed 3).
pub fn simulate_tied_in_on(dir: &Path, plan_name: &str) -> (PathBuf, PathBuf, PathBuf) {
    let (bin, depth, job) = (
        dir.join("run.bin"),
        dir.join("depth.csv"),
        dir.join("job.json"),
    );
    std::fs::write(&job, TIED_IN_JOB).unwrap();
    let sim = run(&[
        "simulate",
        "--motion",
        "lateral",
        "--plan",
        s(&plan(plan_name)),
        "--seed",
        "3",
        "-o",
        s(&bin),
        "--depth-log",
        s(&depth),
        "--tie-in-job",
        s(&job),
    ]);
    assert_eq!(sim.code, Some(0), "{}", sim.stderr);
    (bin, depth, job)
}

/// ISCWSA test well #1's stations in the tool's format
/// (`tests/data/iscwsa/well1_stations.csv`).
pub fn well1() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/data/iscwsa/well1_stations.csv")
}

/// Well #1's site (`tests/data/iscwsa/wells.json`) as `survey` flags.
pub const WELL1_SITE: [&str; 8] = [
    "--lat",
    "60",
    "--b-total-nt",
    "50000",
    "--dip-deg",
    "72",
    "--declination-deg",
    "-4",
];

/// A capture's frames, each with its delimiter and what it decoded to
/// (`None`: a reply, garbage, or a frame the decoder dropped).
pub fn capture_frames(bytes: &[u8]) -> Vec<(Vec<u8>, Option<mwd_core::protocol::Frame>)> {
    let mut decoder = mwd_core::protocol::Decoder::new();
    let mut out = Vec::new();
    let mut chunk = Vec::new();
    for &b in bytes {
        chunk.push(b);
        let frame = decoder.push(b);
        if b == 0 {
            out.push((std::mem::take(&mut chunk), frame));
        }
    }
    if !chunk.is_empty() {
        out.push((chunk, None));
    }
    out
}
