//! `host-sim probe configure` on a pty pair against a stand-in probe: the
//! probe's own decoding and configuration (`mwd_core::protocol::uplink`,
//! `mwd_core::config`), telemetry frames streaming in between the replies,
//! the first command's reply lost (the tool sends it again), and a busy
//! probe's NAKs making the tool fail.
#![cfg(target_os = "linux")]

use mwd_core::config::{Applied, ProbeConfig};
use mwd_core::earth::Position;
use mwd_core::protocol::uplink::reply::encode_reply;
use mwd_core::protocol::uplink::{decode_command, NakReason, Reply, ReplyStatus};
use mwd_core::protocol::{example, FrameEncoder, MAX_WIRE_LEN};
use std::fs::File;
use std::io::{Read, Write};
use std::os::fd::AsFd;
use std::process::Command;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

use rustix::pty::{grantpt, openpt, ptsname, unlockpt, OpenptFlags};

const HOST_SIM: &str = env!("CARGO_BIN_EXE_host-sim");

fn pty_pair() -> (File, String) {
    let master = openpt(OpenptFlags::RDWR | OpenptFlags::NOCTTY).expect("openpt");
    grantpt(&master).expect("grantpt");
    unlockpt(&master).expect("unlockpt");
    let name = ptsname(&master, Vec::new()).expect("ptsname");
    (File::from(master), name.into_string().unwrap())
}

/// The stand-in probe: answers every command as the probe's `apply` does
/// (settings applied and "stored", or NAK busy when `surveying`), drops
/// the first command it sees, and sends a raw-sample frame between reads.
fn fake_probe(
    mut master: File,
    surveying: bool,
    stop: Arc<AtomicBool>,
) -> std::thread::JoinHandle<ProbeConfig> {
    std::thread::spawn(move || {
        rustix::fs::fcntl_setfl(master.as_fd(), rustix::fs::OFlags::NONBLOCK).unwrap();
        let mut config = ProbeConfig::default();
        let mut downlink = FrameEncoder::new();
        let mut chunk = Vec::new();
        let mut first = true;
        let mut buf = [0u8; 256];
        let mut out = [0u8; MAX_WIRE_LEN];
        while !stop.load(Ordering::Relaxed) {
            let n = downlink.encode(&example::raw_sample(), &mut out).unwrap();
            let _ = master.write_all(&out[..n]);
            std::thread::sleep(Duration::from_millis(5));
            let got = master.read(&mut buf).unwrap_or(0);
            for b in &buf[..got] {
                if *b != 0 {
                    chunk.push(*b);
                    continue;
                }
                let Ok(len) = cobs::decode_in_place(&mut chunk) else {
                    chunk.clear();
                    continue;
                };
                let decoded = decode_command(&chunk[..len]);
                chunk.clear();
                let Ok(received) = decoded else { continue };
                if std::mem::take(&mut first) {
                    continue; // lost on the line: no reply
                }
                let kind = received.command.kind() as u8;
                let mut reply = Reply::ack(0, received.seq, kind, config.version);
                let mut trial = config;
                let setting = matches!(
                    trial.apply(&received.command),
                    Ok(Applied::Changed | Applied::Unchanged)
                );
                if setting && surveying {
                    reply.status = ReplyStatus::Nak(NakReason::Busy);
                } else {
                    config.apply(&received.command).unwrap();
                    reply.config_version = config.version;
                }
                let n = encode_reply(downlink.next_seq(), &reply, &mut out).unwrap();
                let _ = downlink.encode(&example::boot_event(), &mut [0u8; 64]);
                master.write_all(&out[..n]).unwrap();
            }
        }
        config
    })
}

fn job_file(name: &str) -> std::path::PathBuf {
    let path = std::env::temp_dir().join(format!("{name}-{}.json", std::process::id()));
    std::fs::write(
        &path,
        r#"{"format": "mwd-job", "version": 1,
            "site": {"latitude_deg": 30.5, "longitude_deg": 114.25, "height_m": 23.0},
            "tie_in": {"inclination_deg": 88.0, "azimuth_deg": 271.0, "toolface_deg": 15.0,
                       "inclination_sigma_deg": 0.1, "azimuth_sigma_deg": 1.5,
                       "toolface_sigma_deg": 0.3}}"#,
    )
    .unwrap();
    path
}

fn configure(surveying: bool) -> (std::process::Output, ProbeConfig) {
    let (master, port) = pty_pair();
    let stop = Arc::new(AtomicBool::new(false));
    let probe = fake_probe(master, surveying, stop.clone());
    let job = job_file(if surveying { "busy-job" } else { "job" });
    let output = Command::new(HOST_SIM)
        .args(["probe", "configure", "--job"])
        .arg(&job)
        .args(["--port", &port, "--reply-timeout-ms", "300"])
        .output()
        .unwrap();
    stop.store(true, Ordering::Relaxed);
    let config = probe.join().unwrap();
    std::fs::remove_file(job).ok();
    (output, config)
}

#[test]
fn configure_puts_the_job_on_the_probe() {
    let (output, config) = configure(false);
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        output.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&output.stderr)
    );
    assert_eq!(config.site, Position::from_degrees(30.5, 114.25, 23.0));
    let tie_in = config.tie_in.expect("a tie-in");
    assert!((tie_in.angles().azimuth.to_degrees() - 271.0).abs() < 1e-9);
    // Site, tie-in, two calibrations (identity: unchanged), report.
    assert_eq!(config.version, 2);
    assert_eq!(stdout.matches(": ACK").count(), 5, "{stdout}");
    assert!(
        stdout.contains("report configuration: ACK, configuration version 2"),
        "{stdout}"
    );
}

#[test]
fn a_busy_probe_refuses_and_the_tool_fails() {
    let (output, config) = configure(true);
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(!output.status.success(), "{stdout}");
    assert_eq!(config, ProbeConfig::default());
    assert_eq!(stdout.matches("NAK busy").count(), 4, "{stdout}");
    assert!(String::from_utf8_lossy(&output.stderr).contains("4 of 5 commands"));
}
