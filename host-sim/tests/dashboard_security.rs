//! Nobody drives the probe, or reads the dashboard, from another web page:
//! `host-sim dashboard` on a pty standing in for the probe refuses a
//! foreign Host (DNS rebinding), another site's Origin, and a command
//! without the page's token or with a wrong one, and none of them reaches
//! the probe; the page's own command does. A half-sent request is cut off;
//! connections beyond the cap are closed; a non-loopback address needs
//! --allow-remote, and then every read needs the token.
#![cfg(feature = "dashboard")]

mod common;

mod dashboard_common;

use std::io::{ErrorKind, Read, Write};
use std::net::TcpStream;
use std::time::{Duration, Instant};

use dashboard_common::{raw_request, request, start, start_any};

/// A simulated capture of 5 s (nothing to command: only reads).
fn capture(dir: &std::path::Path) -> std::path::PathBuf {
    dashboard_common::simulated_capture(dir, 5)
}

#[test]
fn a_foreign_host_gets_nothing_of_the_dashboard() {
    let dir = common::scratch("dashboard-security", "host");
    let capture = capture(&dir);
    let d = start(&["--file", common::s(&capture), "--speed", "1"]);
    let port = d.addr.rsplit(':').next().unwrap();
    // What a page on attacker.example sends once its name resolves to
    // 127.0.0.1: its own name, with the token it does not have or with it.
    for path in ["/", "/events", "/uPlot.js", "/dashboard.js", "/nowhere"] {
        let headers = format!("Host: attacker.example:{port}\r\n");
        let (status, body) = raw_request(&d.addr, "GET", path, &headers);
        assert_eq!(status, 421, "{path}: {body}");
        assert!(
            !body.contains("probe-token") && !body.contains("data:"),
            "{body}"
        );
    }
    let headers = format!(
        "Host: attacker.example:{port}\r\nX-Probe-Token: {}\r\n",
        d.token
    );
    let (status, _) = raw_request(&d.addr, "POST", "/api/align", &headers);
    assert_eq!(status, 421);
    // No Host at all (HTTP/1.0) is no name of ours either.
    let (status, _) = raw_request(&d.addr, "GET", "/", "");
    assert_eq!(status, 421);
    // The names a browser on this machine uses are served.
    for host in ["localhost", "127.0.0.1", "[::1]"] {
        let headers = format!("Host: {host}:{port}\r\n");
        let (status, page) = raw_request(&d.addr, "GET", "/", &headers);
        assert_eq!(status, 200, "{host}");
        assert!(page.contains(&d.token));
    }
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn a_request_half_sent_is_closed() {
    let dir = common::scratch("dashboard-security", "slow");
    let capture = capture(&dir);
    let d = start(&["--file", common::s(&capture), "--speed", "1"]);
    let mut stream = TcpStream::connect(&d.addr).unwrap();
    write!(stream, "GET / HTTP/1.1\r\nHost: {}\r\nX-Partial: ", d.addr).unwrap();
    // Generous: only a connection held for ever runs into it.
    stream
        .set_read_timeout(Some(Duration::from_secs(60)))
        .unwrap();
    let started = Instant::now();
    let mut rest = Vec::new();
    let outcome = stream.read_to_end(&mut rest);
    // Ended by the server (end of stream or reset), not by our timeout.
    let closed = match &outcome {
        Ok(_) => true,
        Err(e) => !matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut),
    };
    assert!(
        closed,
        "still open after {:?}: {outcome:?}",
        started.elapsed()
    );
    // Closed without serving the page.
    assert!(
        !String::from_utf8_lossy(&rest).contains("probe-token"),
        "{rest:?}"
    );
    // The server still serves the next one.
    let (status, _) = request(&d, "GET", "/");
    assert_eq!(status, 200);
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn connections_beyond_the_cap_are_closed_and_served_again_once_freed() {
    let dir = common::scratch("dashboard-security", "cap");
    let capture = capture(&dir);
    let d = start(&["--file", common::s(&capture), "--speed", "1"]);
    // The server's cap (dashboard::server::MAX_CONNECTIONS), held open.
    let held: Vec<TcpStream> = (0..32)
        .map(|_| TcpStream::connect(&d.addr).unwrap())
        .collect();
    let mut extra = TcpStream::connect(&d.addr).unwrap();
    extra
        .set_read_timeout(Some(Duration::from_secs(60)))
        .unwrap();
    // Closed at once: the request may not even be written.
    let _ = write!(extra, "GET / HTTP/1.0\r\nHost: {}\r\n\r\n", d.addr);
    let mut answer = Vec::new();
    let outcome = extra.read_to_end(&mut answer);
    let closed = match &outcome {
        Ok(_) => true,
        Err(e) => !matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut),
    };
    assert!(
        closed && answer.is_empty(),
        "{outcome:?}: {}",
        String::from_utf8_lossy(&answer)
    );
    drop(held);
    // Freed as the held ones close: served again.
    let deadline = Instant::now() + Duration::from_secs(30);
    loop {
        let mut probe = TcpStream::connect(&d.addr).unwrap();
        let mut text = String::new();
        let served = write!(probe, "GET /uPlot.css HTTP/1.0\r\nHost: {}\r\n\r\n", d.addr)
            .and_then(|()| probe.read_to_string(&mut text))
            .is_ok_and(|_| text.lines().next().is_some_and(|l| l.contains(" 200 ")));
        if served {
            break;
        }
        assert!(Instant::now() < deadline, "not served again: {text:?}");
        std::thread::sleep(Duration::from_millis(100));
    }
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn a_non_loopback_address_needs_allow_remote_and_then_the_token_for_everything() {
    let dir = common::scratch("dashboard-security", "remote");
    let capture = capture(&dir);
    let run = common::run(&[
        "dashboard",
        "--file",
        common::s(&capture),
        "--bind",
        "0.0.0.0",
        "--http-port",
        "0",
    ]);
    common::refused(&run, "--allow-remote");
    assert!(run.stdout.is_empty(), "{}", run.stdout);

    let d = start_any(&[
        "--file",
        common::s(&capture),
        "--bind",
        "0.0.0.0",
        "--allow-remote",
    ]);
    assert_eq!(d.token.len(), 64, "{}", d.token);
    // Any name (another machine's view of this one), but the token for
    // the page and the data; the public scripts without.
    let host = "Host: probe-laptop.local\r\n";
    let (status, page) = raw_request(&d.addr, "GET", "/", host);
    assert_eq!(status, 403, "{page}");
    let (status, _) = raw_request(&d.addr, "GET", "/events", host);
    assert_eq!(status, 403);
    let (status, _) = raw_request(&d.addr, "GET", "/?token=0123", host);
    assert_eq!(status, 403);
    let (status, page) = raw_request(&d.addr, "GET", &format!("/?token={}", d.token), host);
    assert_eq!(status, 200);
    assert!(page.contains(&d.token));
    let (status, _) = raw_request(&d.addr, "GET", "/uPlot.js", host);
    assert_eq!(status, 200);
    // Commands: the token in the header, not in the address.
    let (status, _) = raw_request(
        &d.addr,
        "POST",
        &format!("/api/align?token={}", d.token),
        host,
    );
    assert_eq!(status, 403);
    let (status, why) = request(&d, "POST", "/api/align");
    assert_eq!(status, 409, "{why}");
    std::fs::remove_dir_all(dir).ok();
}

#[cfg(target_os = "linux")]
#[test]
fn only_the_pages_own_command_reaches_the_probe() {
    use std::sync::atomic::Ordering;

    let probe = dashboard_common::probe::stand_in();
    let d = start(&["--port", &probe.port]);
    let port = d.addr.rsplit(':').next().unwrap();
    let ours = format!("Host: {}\r\n", d.addr);
    let wrong = "0".repeat(64);
    let refused = [
        // Another site's form or script: no token.
        (ours.clone(), 403),
        (format!("{ours}Origin: http://attacker.example\r\n"), 403),
        // A guessed token.
        (format!("{ours}X-Probe-Token: {wrong}\r\n"), 403),
        (format!("{ours}X-Probe-Token: \r\n"), 403),
        // The right token from another site's page (cross-origin).
        (
            format!(
                "{ours}Origin: http://attacker.example\r\nX-Probe-Token: {}\r\n",
                d.token
            ),
            403,
        ),
        // DNS rebinding: a foreign Host, even with the token.
        (
            format!(
                "Host: attacker.example:{port}\r\nX-Probe-Token: {}\r\n",
                d.token
            ),
            421,
        ),
    ];
    for path in ["/api/align", "/api/station", "/api/index/4/30"] {
        for (headers, expected) in &refused {
            let (status, body) = raw_request(&d.addr, "POST", path, headers);
            assert_eq!(status, *expected, "{path} with {headers:?}: {body}");
        }
    }
    // Give a command that slipped through the time to reach the probe.
    std::thread::sleep(Duration::from_millis(1500));
    assert_eq!(probe.commands.load(Ordering::SeqCst), 0);

    // The page's own request, same origin with its token: sent.
    let headers = format!(
        "{ours}Origin: http://{}\r\nX-Probe-Token: {}\r\n",
        d.addr, d.token
    );
    let (status, body) = raw_request(&d.addr, "POST", "/api/align", &headers);
    assert_eq!(status, 202, "{body}");
    let deadline = Instant::now() + Duration::from_secs(30);
    while probe.commands.load(Ordering::SeqCst) == 0 && Instant::now() < deadline {
        std::thread::sleep(Duration::from_millis(50));
    }
    assert_eq!(probe.commands.load(Ordering::SeqCst), 1);
    drop(d);
    probe.stop();
}
