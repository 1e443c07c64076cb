//! What the dashboard's test files share (with `common`, which each
//! declares too): a capture, the binary serving it on a free port, HTTP requests as raw text (so that any Host, Origin or token can
//! be sent), the event stream followed, and a stand-in probe on a pty.
#![allow(dead_code)] // each test file uses its own part of it

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use serde_json::Value;

/// A capture of `seconds` simulated by `host-sim simulate` in `dir`.
pub fn simulated_capture(dir: &Path, seconds: u32) -> PathBuf {
    let out = dir.join("run.bin");
    let run = crate::common::run(&[
        "simulate",
        "--duration",
        &seconds.to_string(),
        "-o",
        crate::common::s(&out),
    ]);
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    out
}

/// A running dashboard, killed when dropped.
pub struct Dashboard {
    pub child: Child,
    /// `127.0.0.1:PORT` to connect to.
    pub addr: String,
    /// The run's access token, as the page holds it.
    pub token: String,
}

impl Drop for Dashboard {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// `host-sim dashboard ARGS --http-port 0` on loopback, once it serves.
pub fn start(args: &[&str]) -> Dashboard {
    let d = start_any(args);
    assert!(d.addr.starts_with("127.0.0.1:"), "{}", d.addr);
    d
}

/// `host-sim dashboard ARGS --http-port 0`, whatever it binds: the
/// address to connect to (loopback, with the port bound) and the token
/// (from the URL printed, or else from the page).
pub fn start_any(args: &[&str]) -> Dashboard {
    let mut child = Command::new(env!("CARGO_BIN_EXE_host-sim"))
        .arg("dashboard")
        .args(args)
        .args(["--http-port", "0"])
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .expect("host-sim runs");
    let mut line = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut line)
        .unwrap();
    let url = line
        .split("http://")
        .nth(1)
        .and_then(|rest| rest.split(' ').next())
        .unwrap_or_else(|| panic!("no URL in {line:?}"));
    let (bound, query) = url.split_once('/').unwrap();
    let port = bound.rsplit(':').next().unwrap();
    let addr = if bound.starts_with("127.") {
        bound.to_string()
    } else {
        format!("127.0.0.1:{port}")
    };
    let mut d = Dashboard {
        child,
        addr,
        token: String::new(),
    };
    d.token = match query.strip_prefix("?token=") {
        Some(token) => token.to_string(),
        None => page_token(&d.addr),
    };
    d
}

/// The token in the page's `<meta name="probe-token">`.
pub fn page_token(addr: &str) -> String {
    let (status, page) = raw_request(addr, "GET", "/", &format!("Host: {addr}\r\n"));
    assert_eq!(status, 200, "{page}");
    let tail = page
        .split("name=\"probe-token\" content=\"")
        .nth(1)
        .expect("a token in the page");
    tail.split('"').next().unwrap().to_string()
}

/// One HTTP/1.0 request (no chunked encoding to undo) as the page sends
/// it: its Host and its token. Status and body.
pub fn request(d: &Dashboard, method: &str, path: &str) -> (u16, String) {
    let headers = format!("Host: {}\r\nX-Probe-Token: {}\r\n", d.addr, d.token);
    raw_request(&d.addr, method, path, &headers)
}

/// One HTTP/1.0 request with exactly these header lines: status and body.
pub fn raw_request(addr: &str, method: &str, path: &str, headers: &str) -> (u16, String) {
    let mut stream = TcpStream::connect(addr).unwrap();
    write!(stream, "{method} {path} HTTP/1.0\r\n{headers}\r\n").unwrap();
    let mut response = String::new();
    stream.read_to_string(&mut response).unwrap();
    let (head, body) = response.split_once("\r\n\r\n").unwrap();
    let status = head.split(' ').nth(1).unwrap().parse().unwrap();
    (status, body.to_string())
}

/// Reads the event stream until `done` says so (or 30 s): the last event's
/// id and data.
pub fn follow(addr: &str, last_id: Option<&str>, done: impl Fn(&Value) -> bool) -> (String, Value) {
    let mut stream = TcpStream::connect(addr).unwrap();
    stream
        .set_read_timeout(Some(Duration::from_secs(10)))
        .unwrap();
    let resume = last_id.map_or(String::new(), |id| format!("Last-Event-ID: {id}\r\n"));
    write!(
        stream,
        "GET /events HTTP/1.0\r\nHost: {addr}\r\n{resume}\r\n"
    )
    .unwrap();
    let started = Instant::now();
    let mut id = String::new();
    for line in BufReader::new(stream).lines() {
        let line = line.unwrap();
        if let Some(rest) = line.strip_prefix("id:") {
            id = rest.trim().to_string();
        } else if let Some(data) = line.strip_prefix("data:") {
            let update: Value = serde_json::from_str(data).unwrap();
            if done(&update) || started.elapsed() > Duration::from_secs(30) {
                return (id, update);
            }
        }
    }
    panic!("the event stream ended");
}

#[cfg(target_os = "linux")]
pub mod probe {
    use super::*;
    use mwd_core::protocol::uplink::reply::encode_reply;
    use mwd_core::protocol::uplink::{decode_command, Reply};
    use mwd_core::protocol::{example, FrameEncoder, MAX_WIRE_LEN};
    use rustix::pty::{grantpt, openpt, ptsname, unlockpt, OpenptFlags};
    use std::fs::File;
    use std::os::fd::AsFd;
    use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
    use std::sync::Arc;

    /// A stand-in probe on a pty.
    pub struct StandIn {
        /// The pty's path, for `--port`.
        pub port: String,
        /// Commands it has received (each answered with an ACK).
        pub commands: Arc<AtomicUsize>,
        stop: Arc<AtomicBool>,
        thread: std::thread::JoinHandle<Vec<u8>>,
    }

    impl StandIn {
        /// Stops it: every byte it sent.
        pub fn stop(self) -> Vec<u8> {
            self.stop.store(true, Ordering::Relaxed);
            self.thread.join().unwrap()
        }
    }

    /// Raw-sample frames every few ms, an ACK to every command.
    pub fn stand_in() -> StandIn {
        let master = openpt(OpenptFlags::RDWR | OpenptFlags::NOCTTY).unwrap();
        grantpt(&master).unwrap();
        unlockpt(&master).unwrap();
        let port = ptsname(&master, Vec::new()).unwrap().into_string().unwrap();
        let mut master = File::from(master);
        let stop = Arc::new(AtomicBool::new(false));
        let commands = Arc::new(AtomicUsize::new(0));
        let (stopped, received) = (Arc::clone(&stop), Arc::clone(&commands));
        let thread = std::thread::spawn(move || {
            rustix::fs::fcntl_setfl(master.as_fd(), rustix::fs::OFlags::NONBLOCK).unwrap();
            let mut downlink = FrameEncoder::new();
            let (mut sent, mut chunk) = (Vec::new(), Vec::new());
            let (mut buf, mut out) = ([0u8; 256], [0u8; MAX_WIRE_LEN]);
            while !stopped.load(Ordering::Relaxed) {
                let n = downlink.encode(&example::raw_sample(), &mut out).unwrap();
                // Until the dashboard opens the port, nobody reads: not sent.
                if master.write_all(&out[..n]).is_ok() {
                    sent.extend_from_slice(&out[..n]);
                }
                std::thread::sleep(Duration::from_millis(5));
                let got = master.read(&mut buf).unwrap_or(0);
                for b in &buf[..got] {
                    if *b != 0 {
                        chunk.push(*b);
                        continue;
                    }
                    let command = cobs::decode_in_place(&mut chunk)
                        .ok()
                        .and_then(|len| decode_command(&chunk[..len]).ok());
                    chunk.clear();
                    if let Some(c) = command {
                        received.fetch_add(1, Ordering::SeqCst);
                        let reply = Reply::ack(0, c.seq, c.command.kind() as u8, 3);
                        let n = encode_reply(downlink.next_seq(), &reply, &mut out).unwrap();
                        master.write_all(&out[..n]).unwrap();
                        sent.extend_from_slice(&out[..n]);
                    }
                }
            }
            sent
        });
        StandIn {
            port,
            commands,
            stop,
            thread,
        }
    }
}
