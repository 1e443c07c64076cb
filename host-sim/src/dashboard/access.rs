//! Who may use the dashboard: the rules every request passes before a
//! handler sees it, so that no web page the user opens can read the probe's
//! data through a rebound name or drive the probe.
//!
//! - **Host**: served on a loopback address, the dashboard answers only to
//!   the names a browser on this machine uses for it (`localhost`,
//!   `127.0.0.1`, `[::1]` and the address bound, each with the port): a
//!   page whose own name was rebound to 127.0.0.1 (DNS rebinding) sends its
//!   own name and is refused (421) with nothing of the dashboard.
//! - **Origin**: a request that carries an `Origin` must come from the
//!   page this server served (`http://` and the request's Host): another
//!   site's script is refused (403).
//! - **Token**: each run draws a random token that only the served page
//!   holds (in its `<meta name="probe-token">`). Every command to the
//!   probe must carry it in the `X-Probe-Token` header (403 without it or
//!   with a wrong one, and nothing is sent). A custom header also makes a
//!   browser ask first (CORS preflight), which this server never grants.
//! - **Remote** (`--allow-remote`, a non-loopback address): other machines
//!   reach the dashboard by names this one cannot know, so any Host is
//!   taken, but every request except the page's public scripts and style
//!   must carry the token (`X-Probe-Token`, or `?token=` for the page and
//!   the event stream, which a browser cannot give a header), and commands
//!   still only in the header.

use std::fmt::Write;
use std::net::{IpAddr, SocketAddr};

use axum::http::{header, HeaderMap, Method, StatusCode};

/// The header that carries the token.
pub const TOKEN_HEADER: &str = "x-probe-token";

/// The query parameter that carries the token where no header can (the
/// page's address, the event stream).
pub const TOKEN_QUERY: &str = "token";

/// Bytes of randomness in a token (shown as twice as many hex digits).
const TOKEN_BYTES: usize = 32;

/// A new token from the operating system's random source: 64 hex digits.
pub fn new_token() -> String {
    let bytes: [u8; TOKEN_BYTES] = rand::random();
    bytes.iter().fold(String::new(), |mut text, b| {
        let _ = write!(text, "{b:02x}");
        text
    })
}

/// Why a request is refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Refusal {
    /// The Host is not a name of this dashboard (a rebound name).
    ForeignHost,
    /// The Origin is another site's.
    CrossOrigin,
    /// The token is missing or wrong.
    Token,
}

impl Refusal {
    pub fn status(self) -> StatusCode {
        match self {
            Refusal::ForeignHost => StatusCode::MISDIRECTED_REQUEST,
            Refusal::CrossOrigin | Refusal::Token => StatusCode::FORBIDDEN,
        }
    }

    pub fn text(self) -> &'static str {
        match self {
            Refusal::ForeignHost => {
                "this dashboard answers only to the address it serves on (localhost)"
            }
            Refusal::CrossOrigin => "requests from another site's pages are refused",
            Refusal::Token => {
                "this request needs the dashboard's access token (the page served by this \
                 dashboard sends it; with --allow-remote, the token printed at its start)"
            }
        }
    }
}

/// What a request is, for the rules.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// The page's scripts and style: the same for everyone, no data.
    PublicAsset,
    /// The page itself, the event stream: reads.
    Read,
    /// A command to the probe.
    Command,
}

impl Kind {
    pub fn of(method: &Method, path: &str) -> Kind {
        const PUBLIC: [&str; 4] = ["/dashboard.js", "/dashboard.css", "/uPlot.js", "/uPlot.css"];
        if method != Method::GET && method != Method::HEAD {
            Kind::Command
        } else if PUBLIC.contains(&path) {
            Kind::PublicAsset
        } else {
            Kind::Read
        }
    }
}

/// The rules of one running dashboard.
#[derive(Debug, Clone)]
pub struct Access {
    token: String,
    /// `host:port` names a local browser may use; empty when remote.
    local_hosts: Vec<String>,
}

impl Access {
    /// The rules for a dashboard bound to `bound` with `token`; `remote`:
    /// other machines may connect (any Host; the token for every read).
    pub fn new(token: String, bound: SocketAddr, remote: bool) -> Self {
        let port = bound.port();
        let local_hosts = if remote {
            Vec::new()
        } else {
            let bound_name = match bound.ip() {
                IpAddr::V4(ip) => ip.to_string(),
                IpAddr::V6(ip) => format!("[{ip}]"),
            };
            let mut names = vec!["localhost".to_string(), "127.0.0.1".into(), "[::1]".into()];
            if !names.contains(&bound_name) {
                names.push(bound_name);
            }
            let mut hosts: Vec<String> = names.iter().map(|n| format!("{n}:{port}")).collect();
            // A browser leaves out the default port.
            if port == 80 {
                hosts.extend(names);
            }
            hosts
        };
        Self { token, local_hosts }
    }

    pub fn token(&self) -> &str {
        &self.token
    }

    pub fn remote(&self) -> bool {
        self.local_hosts.is_empty()
    }

    /// `Ok` if a request of `kind` with these headers and query may be
    /// served.
    pub fn check(
        &self,
        kind: Kind,
        headers: &HeaderMap,
        query: Option<&str>,
    ) -> Result<(), Refusal> {
        let host = headers
            .get(header::HOST)
            .and_then(|v| v.to_str().ok())
            .map(str::to_ascii_lowercase);
        if !self.remote() {
            match &host {
                Some(h) if self.local_hosts.contains(h) => {}
                _ => return Err(Refusal::ForeignHost),
            }
        }
        if let Some(origin) = headers.get(header::ORIGIN) {
            let ours = host.as_ref().map(|h| format!("http://{h}"));
            let origin = origin.to_str().ok().map(str::to_ascii_lowercase);
            if origin.is_none() || origin != ours {
                return Err(Refusal::CrossOrigin);
            }
        }
        let header_token = headers.get(TOKEN_HEADER).and_then(|v| v.to_str().ok());
        let query_token = query.and_then(|q| {
            q.split('&')
                .filter_map(|pair| pair.split_once('='))
                .find(|(key, _)| *key == TOKEN_QUERY)
                .map(|(_, value)| value)
        });
        let needed = match kind {
            Kind::PublicAsset => None,
            Kind::Read if self.remote() => Some(header_token.or(query_token)),
            Kind::Read => None,
            // Commands only in the header: a form or a link cannot set it.
            Kind::Command => Some(header_token),
        };
        match needed {
            None => Ok(()),
            Some(Some(given)) if same_secret(given, &self.token) => Ok(()),
            Some(_) => Err(Refusal::Token),
        }
    }
}

/// Compares in a time that does not depend on where the texts differ.
fn same_secret(given: &str, token: &str) -> bool {
    given.len() == token.len()
        && given
            .bytes()
            .zip(token.bytes())
            .fold(0u8, |diff, (a, b)| diff | (a ^ b))
            == 0
}

#[cfg(test)]
#[path = "access_tests.rs"]
mod tests;
