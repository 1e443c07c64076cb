use super::*;
use axum::http::HeaderValue;

const PORT: u16 = 8080;

fn local() -> Access {
    Access::new(
        "ab".repeat(32),
        SocketAddr::from(([127, 0, 0, 1], PORT)),
        false,
    )
}

fn remote() -> Access {
    Access::new(
        "ab".repeat(32),
        SocketAddr::from(([0, 0, 0, 0], PORT)),
        true,
    )
}

fn headers(pairs: &[(&'static str, &str)]) -> HeaderMap {
    let mut map = HeaderMap::new();
    for (name, value) in pairs {
        map.insert(*name, HeaderValue::from_str(value).unwrap());
    }
    map
}

#[test]
fn tokens_are_long_random_and_differ() {
    let (a, b) = (new_token(), new_token());
    assert_eq!(a.len(), 64);
    assert!(a.bytes().all(|c| c.is_ascii_hexdigit()));
    assert_ne!(a, b);
}

#[test]
fn a_local_dashboard_answers_only_to_its_own_names() {
    let access = local();
    for host in [
        "localhost:8080",
        "127.0.0.1:8080",
        "[::1]:8080",
        "LocalHost:8080",
    ] {
        let h = headers(&[("host", host)]);
        assert_eq!(access.check(Kind::Read, &h, None), Ok(()), "{host}");
    }
    // A rebound name, another port, no port, no Host at all.
    for host in [
        "attacker.example:8080",
        "127.0.0.1:9000",
        "localhost",
        "127.0.0.1.nip.io:8080",
    ] {
        let h = headers(&[("host", host)]);
        for kind in [Kind::Read, Kind::PublicAsset, Kind::Command] {
            assert_eq!(
                access.check(kind, &h, None),
                Err(Refusal::ForeignHost),
                "{host}"
            );
        }
    }
    assert_eq!(
        access.check(Kind::Read, &HeaderMap::new(), None),
        Err(Refusal::ForeignHost)
    );
    assert_eq!(
        Refusal::ForeignHost.status(),
        StatusCode::MISDIRECTED_REQUEST
    );
}

#[test]
fn the_bound_address_and_the_default_port_are_names_too() {
    let access = Access::new("t".into(), SocketAddr::from(([127, 0, 0, 2], 80)), false);
    for host in ["127.0.0.2:80", "127.0.0.2", "localhost"] {
        let h = headers(&[("host", host)]);
        assert_eq!(access.check(Kind::Read, &h, None), Ok(()), "{host}");
    }
}

#[test]
fn another_sites_origin_is_refused() {
    let access = local();
    let token = access.token().to_string();
    for origin in [
        "http://attacker.example",
        "null",
        "http://127.0.0.1:9000",
        "https://127.0.0.1:8080",
    ] {
        let h = headers(&[
            ("host", "127.0.0.1:8080"),
            ("origin", origin),
            (TOKEN_HEADER, &token),
        ]);
        assert_eq!(
            access.check(Kind::Command, &h, None),
            Err(Refusal::CrossOrigin),
            "{origin}"
        );
        assert_eq!(
            access.check(Kind::Read, &h, None),
            Err(Refusal::CrossOrigin),
            "{origin}"
        );
    }
    let h = headers(&[
        ("host", "127.0.0.1:8080"),
        ("origin", "http://127.0.0.1:8080"),
        (TOKEN_HEADER, &token),
    ]);
    assert_eq!(access.check(Kind::Command, &h, None), Ok(()));
}

#[test]
fn commands_need_the_token_in_the_header() {
    let access = local();
    let token = access.token().to_string();
    let host = ("host", "127.0.0.1:8080");
    assert_eq!(
        access.check(Kind::Command, &headers(&[host]), None),
        Err(Refusal::Token)
    );
    let wrong = "cd".repeat(32);
    let h = headers(&[host, (TOKEN_HEADER, &wrong)]);
    assert_eq!(access.check(Kind::Command, &h, None), Err(Refusal::Token));
    let short = &token[..10];
    let h = headers(&[host, (TOKEN_HEADER, short)]);
    assert_eq!(access.check(Kind::Command, &h, None), Err(Refusal::Token));
    // Not in the query: a link or a form could carry it there.
    let query = format!("token={token}");
    assert_eq!(
        access.check(Kind::Command, &headers(&[host]), Some(&query)),
        Err(Refusal::Token)
    );
    let h = headers(&[host, (TOKEN_HEADER, &token)]);
    assert_eq!(access.check(Kind::Command, &h, None), Ok(()));
    // Reads on a local dashboard need no token.
    assert_eq!(access.check(Kind::Read, &headers(&[host]), None), Ok(()));
}

#[test]
fn a_remote_dashboard_takes_any_host_but_wants_the_token_for_every_read() {
    let access = remote();
    let token = access.token().to_string();
    let host = ("host", "probe-laptop.local:8080");
    assert_eq!(
        access.check(Kind::PublicAsset, &headers(&[host]), None),
        Ok(())
    );
    assert_eq!(
        access.check(Kind::Read, &headers(&[host]), None),
        Err(Refusal::Token)
    );
    assert_eq!(
        access.check(Kind::Read, &headers(&[host]), Some("token=wrong")),
        Err(Refusal::Token)
    );
    let query = format!("x=1&token={token}");
    assert_eq!(
        access.check(Kind::Read, &headers(&[host]), Some(&query)),
        Ok(())
    );
    let h = headers(&[host, (TOKEN_HEADER, &token)]);
    assert_eq!(access.check(Kind::Read, &h, None), Ok(()));
    assert_eq!(access.check(Kind::Command, &h, None), Ok(()));
    assert_eq!(
        access.check(Kind::Command, &headers(&[host]), Some(&query)),
        Err(Refusal::Token)
    );
}

#[test]
fn requests_are_told_apart_by_method_and_path() {
    assert_eq!(Kind::of(&Method::GET, "/uPlot.js"), Kind::PublicAsset);
    assert_eq!(Kind::of(&Method::GET, "/"), Kind::Read);
    assert_eq!(Kind::of(&Method::GET, "/events"), Kind::Read);
    assert_eq!(Kind::of(&Method::POST, "/uPlot.js"), Kind::Command);
    assert_eq!(Kind::of(&Method::PUT, "/api/align"), Kind::Command);
}
