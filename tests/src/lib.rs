//! System tests across crates live in `tests/tests/`; this library only
//! holds helpers they share: cross-building the QEMU probe, building the
//! host tool, finding QEMU, waiting for a child process with a guard
//! against hangs, and reading the probe's semihosting summary line.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::sync::Mutex;
use std::time::{Duration, Instant};

pub const TARGET: &str = "thumbv7em-none-eabihf";

pub fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("tests/ sits in the workspace")
        .to_path_buf()
}

/// A build started from a test gets its own directory inside the
/// workspace's target directory: a separate lock from the `cargo test`
/// that runs the test, and no thrashing between host and target builds.
fn sub_target_dir(name: &str) -> PathBuf {
    // A relative CARGO_TARGET_DIR is relative to the workspace root, not
    // to the test's working directory (tests/).
    let base = std::env::var_os("CARGO_TARGET_DIR")
        .map(|dir| workspace_root().join(dir))
        .unwrap_or_else(|| workspace_root().join("target"));
    base.join(name)
}

fn cargo() -> Command {
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let mut command = Command::new(cargo);
    command.current_dir(workspace_root());
    command
}

/// Builds of different features share one target directory (only the
/// firmware crate differs) and so one output path: build and copy the
/// binary out one test at a time.
static BUILD: Mutex<()> = Mutex::new(());

/// Cross-builds `probe-qemu` with `features` and copies it to a file of its
/// own, `probe-qemu-<name>.elf`.
pub fn build_firmware(features: &str, name: &str) -> PathBuf {
    build_firmware_for(features, name, None)
}

/// As [`build_firmware`], for a run of `run_seconds` simulated seconds
/// (`PROBE_QEMU_RUN_SECONDS`, compiled in) when given. Every variant builds
/// in one directory: the dependencies are cross-compiled once, and a
/// variant rebuilds only the firmware crate (a directory per run length
/// cross-compiled the whole dependency tree again, about half a minute of
/// a 2-core CI machine each).
pub fn build_firmware_for(features: &str, name: &str, run_seconds: Option<u32>) -> PathBuf {
    let _one_at_a_time = BUILD.lock().unwrap_or_else(|e| e.into_inner());
    let target_dir = sub_target_dir("qemu-probe");
    let mut command = cargo();
    command
        .args([
            "build",
            "-p",
            "firmware",
            "--profile",
            "probe",
            "--target",
            TARGET,
        ])
        .args(["--features", features, "--bin", "probe-qemu"])
        .env("CARGO_TARGET_DIR", &target_dir);
    match run_seconds {
        Some(s) => command.env("PROBE_QEMU_RUN_SECONDS", s.to_string()),
        None => command.env_remove("PROBE_QEMU_RUN_SECONDS"),
    };
    let status = command
        .status()
        .expect("run cargo to cross-build the firmware");
    assert!(
        status.success(),
        "cross-build of probe-qemu failed (is the {TARGET} target installed? \
         `rustup target add {TARGET}`)"
    );
    let built = target_dir.join(TARGET).join("probe").join("probe-qemu");
    let length = run_seconds.map(|s| format!("-{s}s")).unwrap_or_default();
    let elf = target_dir.join(format!("probe-qemu-{name}{length}.elf"));
    std::fs::copy(&built, &elf).expect("copy the firmware binary");
    elf
}

/// The variable naming a `host-sim` binary already built from this
/// workspace: the test command sets it to the one its `cargo test
/// --workspace` builds for host-sim's own CLI tests, so the system tests
/// do not build the host tool and its dependencies a second time (about
/// 3 min of a cold 2-core CI machine).
pub const HOST_SIM_BINARY_VARIABLE: &str = "SYSTEM_TESTS_HOST_SIM";

/// Builds the `host-sim` command-line tool (a test of another package does
/// not get it built by cargo) and returns its path; or the binary named by
/// [`HOST_SIM_BINARY_VARIABLE`], which must exist.
pub fn build_host_sim() -> PathBuf {
    if let Some(given) = std::env::var_os(HOST_SIM_BINARY_VARIABLE) {
        let path = PathBuf::from(given);
        assert!(
            path.is_file(),
            "{HOST_SIM_BINARY_VARIABLE}={} is not a file",
            path.display()
        );
        return path;
    }
    let _one_at_a_time = BUILD.lock().unwrap_or_else(|e| e.into_inner());
    let target_dir = sub_target_dir("host-tool");
    let status = cargo()
        .args(["build", "-p", "host-sim", "--bin", "host-sim"])
        .env("CARGO_TARGET_DIR", &target_dir)
        .status()
        .expect("run cargo to build host-sim");
    assert!(status.success(), "build of host-sim failed");
    target_dir
        .join("debug")
        .join(format!("host-sim{}", std::env::consts::EXE_SUFFIX))
}

/// Fails (does not skip) when QEMU is missing.
pub fn require_qemu() {
    let found = Command::new("qemu-system-arm")
        .arg("--version")
        .stdout(Stdio::null())
        .status()
        .is_ok_and(|s| s.success());
    assert!(
        found,
        "qemu-system-arm is not installed: this end-to-end test needs it \
         (Debian: `apt-get install -y qemu-system-arm`, as scripts/test-all.sh does)"
    );
}

/// Waits for `child` to exit; kills it and panics after `timeout`, which
/// only a hang reaches (no timing is asserted).
pub fn wait_or_kill(child: &mut Child, what: &str, timeout: Duration) -> ExitStatus {
    let started = Instant::now();
    loop {
        if let Some(status) = child.try_wait().expect("wait for a child process") {
            return status;
        }
        if started.elapsed() > timeout {
            let _ = child.kill();
            let _ = child.wait();
            panic!("{what} did not exit within {timeout:?}: it hung");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// The figure `key=` of the QEMU probe's summary line (semihosting).
pub fn summary_value(stdout: &str, key: &str) -> u64 {
    let line = stdout
        .lines()
        .find_map(|l| l.split_once("probe-qemu: samples=").map(|(_, rest)| rest))
        .unwrap_or_else(|| panic!("no summary line in: {stdout}"));
    let full = format!("samples={line}");
    full.split_whitespace()
        .find_map(|kv| kv.strip_prefix(&format!("{key}=")))
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("no {key} in the summary: {full}"))
}
