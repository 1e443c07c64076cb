//! `host-sim probe station | survey` on a pty pair against a stand-in probe
//! that answers the survey commands as the firmware's uplink service does
//! (`firmware/src/app/uplink_service.rs`): a station taken on request
//! follows its ACK in the same write, a moving probe NAKs "not still", an
//! aligning one "not ready"; telemetry streams in between.
#![cfg(target_os = "linux")]

use mwd_core::protocol::frame::station_flags;
use mwd_core::protocol::uplink::reply::encode_reply;
use mwd_core::protocol::uplink::{
    decode_command, Command as Uplink, NakReason, Reply, ReplyStatus,
};
use mwd_core::protocol::{example, FrameEncoder, Payload, MAX_WIRE_LEN};
use std::fs::File;
use std::io::{Read, Write};
use std::os::fd::AsFd;
use std::process::{Command, Output};
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

/// The reply (and the station after it, when taken) to one command of a
/// probe that navigates when `still`, or is moving.
fn answer(command: &Uplink, seq: u16, still: bool, downlink: &mut FrameEncoder) -> Vec<u8> {
    let mut reply = Reply::ack(0, seq, command.kind() as u8, 0);
    let mut station = None;
    match command {
        Uplink::TakeStation if still => {
            let Payload::Station(mut s) = example::station_survey() else {
                unreachable!("the example is a station")
            };
            s.flags |= station_flags::REQUESTED;
            station = Some(Payload::Station(s));
        }
        Uplink::TakeStation => reply.status = ReplyStatus::Nak(NakReason::NotStill),
        _ => reply.status = ReplyStatus::Nak(NakReason::NotReady),
    }
    let mut out = [0u8; MAX_WIRE_LEN];
    let n = encode_reply(downlink.next_seq(), &reply, &mut out).unwrap();
    let _ = downlink.encode(&example::boot_event(), &mut [0u8; 64]);
    let mut wire = out[..n].to_vec();
    if let Some(station) = station {
        let n = downlink.encode(&station, &mut out).unwrap();
        wire.extend(&out[..n]);
    }
    wire
}

fn fake_probe(mut master: File, still: bool, stop: Arc<AtomicBool>) -> std::thread::JoinHandle<()> {
    std::thread::spawn(move || {
        rustix::fs::fcntl_setfl(master.as_fd(), rustix::fs::OFlags::NONBLOCK).unwrap();
        let mut downlink = FrameEncoder::new();
        let mut chunk = Vec::new();
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
                let decoded = cobs::decode_in_place(&mut chunk)
                    .ok()
                    .and_then(|len| decode_command(&chunk[..len]).ok());
                chunk.clear();
                if let Some(received) = decoded {
                    let wire = answer(&received.command, received.seq, still, &mut downlink);
                    master.write_all(&wire).unwrap();
                }
            }
        }
    })
}

fn run(action: &str, still: bool) -> (Output, String) {
    let (master, port) = pty_pair();
    let stop = Arc::new(AtomicBool::new(false));
    let probe = fake_probe(master, still, stop.clone());
    let output = Command::new(HOST_SIM)
        .args([
            "probe",
            action,
            "--port",
            &port,
            "--reply-timeout-ms",
            "500",
        ])
        .output()
        .unwrap();
    stop.store(true, Ordering::Relaxed);
    probe.join().unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout).into_owned();
    (output, stdout)
}

#[test]
fn a_station_taken_on_request_is_printed_after_its_ack() {
    let (output, stdout) = run("station", true);
    assert!(output.status.success(), "{stdout}");
    assert!(stdout.contains("take a station: ACK"), "{stdout}");
    let station = stdout.lines().nth(1).unwrap_or_default();
    assert!(
        station.contains("station ") && station.contains("requested"),
        "{stdout}"
    );
}

#[test]
fn refusals_print_their_reason_and_the_tool_fails() {
    let (output, stdout) = run("station", false);
    assert!(!output.status.success(), "{stdout}");
    assert!(stdout.contains("take a station: NAK not still"), "{stdout}");
    let (output, stdout) = run("survey", true);
    assert!(!output.status.success(), "{stdout}");
    assert!(
        stdout.contains("start surveying: NAK not ready"),
        "{stdout}"
    );
}
