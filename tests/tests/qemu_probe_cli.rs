//! `host-sim probe` against the QEMU probe over its pty, as an engineer
//! configures a real probe (issue 15 items 4-5): a job file (site, tie-in,
//! calibration file) sent with `probe configure`, read back with `probe
//! status`, kept across `probe reboot` (the boot event says a software
//! reset and the configuration from flash at the same version), and
//! `probe status` after the reboot agrees.
//!
//! The tool holds the pty only while it runs; the boot events are read
//! from QEMU's record of everything the probe sent (the chardev's
//! `logfile`, written whether or not anyone holds the pty open). Between
//! runs of the tool QEMU sees the pty closed and takes up to a second to
//! notice it open again (it polls), so a reply may be lost: the tool's
//! resending covers it (`--attempts`).
//!
//! qemu-system-arm must be installed: without it this test fails, it does
//! not skip. Linux only (ptys of /dev/pts).
#![cfg(target_os = "linux")]

mod qemu_link;

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

use firmware::app::boot::{boot_event_value, ConfigSource, ResetCause};
use qemu_link::{boot_events, QemuOnPty, BOOT_TIMEOUT};
use system_tests::{build_firmware_for, build_host_sim, require_qemu, summary_value};

/// Simulated seconds each boot streams (the QEMU pty test's build).
const RUN_SECONDS: u32 = 10;

/// The job: site, tie-in and a calibration file (one accelerometer triad
/// for both parts, the z gyro's bias), each a change from the defaults.
const JOB: &str = r#"{
  "format": "mwd-job", "version": 1,
  "site": { "latitude_deg": 35.5, "longitude_deg": -101.25, "height_m": 980.0 },
  "tie_in": { "inclination_deg": 12.0, "azimuth_deg": 271.0, "toolface_deg": 15.0,
              "inclination_sigma_deg": 0.1, "azimuth_sigma_deg": 1.5,
              "toolface_sigma_deg": 0.3 },
  "calibration_file": "probe-cal.json"
}"#;
const CALIBRATION: &str = r#"{
  "format": "mwd-calibration", "version": 1, "method": "tls",
  "latitude_deg": 35.5, "gravity": 9.797,
  "accel": [{ "columns": ["ax", "ay", "az"], "bias": [0.01, -0.02, 0.003],
              "correction": [[1.01, 0.001, 0.0], [0.0, 0.99, 0.002], [0.0, 0.0, 1.0]] }],
  "gyro": [{ "column": "gz", "axis": "z", "bias": 1e-5, "scale": 1.0 }]
}"#;
/// Site, tie-in, part 0's calibration, part 1's: four changes.
const CONFIGURED_VERSION: u32 = 4;

/// Runs `host-sim probe ARGS --port PTY`; its status and output.
fn probe(host_sim: &Path, pty: &str, args: &[&str]) -> (bool, String) {
    let out = Command::new(host_sim)
        .arg("probe")
        .args(args)
        .args([
            "--port",
            pty,
            "--reply-timeout-ms",
            "1500",
            "--attempts",
            "4",
        ])
        .output()
        .expect("run host-sim probe");
    let text =
        String::from_utf8_lossy(&out.stdout).to_string() + &String::from_utf8_lossy(&out.stderr);
    (out.status.success(), text)
}

/// Waits until QEMU's record of the downlink holds `count` boot events;
/// returns them.
fn wait_for_boots(log: &Path, count: usize) -> Vec<u32> {
    let deadline = Instant::now() + BOOT_TIMEOUT;
    loop {
        let boots = boot_events(&std::fs::read(log).unwrap_or_default());
        if boots.len() >= count {
            return boots;
        }
        assert!(
            Instant::now() < deadline,
            "{} boot events in {}, waited for {count}",
            boots.len(),
            log.display()
        );
        std::thread::sleep(Duration::from_millis(50));
    }
}

fn temp_dir() -> PathBuf {
    let dir = std::env::temp_dir().join(format!("qemu-probe-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("a temporary folder");
    dir
}

#[test]
fn host_sim_configures_the_qemu_probe_and_the_configuration_survives_a_reboot() {
    require_qemu();
    let elf = build_firmware_for("board-qemu", "pty", Some(RUN_SECONDS));
    let host_sim = build_host_sim();
    let dir = temp_dir();
    let job = dir.join("job.json");
    std::fs::write(&job, JOB).expect("write the job");
    std::fs::write(dir.join("probe-cal.json"), CALIBRATION).expect("write the calibration");
    let log = dir.join("downlink.bin");
    let job_arg = job.to_string_lossy().to_string();

    let mut qemu = QemuOnPty::start(&elf, Some(&log));
    let pty = qemu.pty_path.clone();
    qemu.monitor("cont");
    let defaults = boot_event_value(ResetCause::PowerOn, ConfigSource::Defaults, 0);
    assert_eq!(wait_for_boots(&log, 1), [defaults]);

    let (ok, configure) = probe(&host_sim, &pty, &["configure", "--job", &job_arg]);
    println!("{configure}");
    assert!(ok, "probe configure failed:\n{configure}");
    // Each setting acknowledged with the version it made.
    let versions: Vec<&str> = configure
        .lines()
        .filter_map(|l| {
            l.split_once(": ACK, configuration version ")
                .map(|(_, v)| v)
        })
        .collect();
    assert_eq!(versions, ["1", "2", "3", "4", "4"], "{configure}");
    let read_back =
        format!("report configuration: ACK, configuration version {CONFIGURED_VERSION}");
    assert!(configure.contains(&read_back), "{configure}");

    let (ok, status) = probe(&host_sim, &pty, &["status"]);
    assert!(ok && status.contains(&read_back), "{status}");

    let (ok, reboot) = probe(&host_sim, &pty, &["reboot"]);
    let rebooting = format!("reboot: ACK, configuration version {CONFIGURED_VERSION}");
    assert!(ok && reboot.contains(&rebooting), "{reboot}");
    let software = boot_event_value(
        ResetCause::Software,
        ConfigSource::Flash,
        CONFIGURED_VERSION,
    );
    assert_eq!(wait_for_boots(&log, 2), [defaults, software]);

    let (ok, status) = probe(&host_sim, &pty, &["status"]);
    assert!(ok && status.contains(&read_back), "{status}");
    println!("{status}");

    let status = qemu.wait();
    assert!(status.success(), "probe-qemu failed: {}", qemu.out);
    // The tool's sessions cost the probe nothing: every byte accepted,
    // every frame sent (the last boot's run).
    for zero in ["frames_dropped", "skipped", "uplink_replies_dropped"] {
        assert_eq!(summary_value(&qemu.out, zero), 0, "{zero}: {}", qemu.out);
    }
    let _ = std::fs::remove_dir_all(&dir);
}
