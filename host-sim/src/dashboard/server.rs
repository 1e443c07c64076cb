//! The dashboard's web server: the page and its scripts (embedded, so it
//! works with no network), the data as server-sent events (a page that
//! reconnects sends `Last-Event-ID` and picks up where the stream is), and
//! the probe's commands as POST requests. Every request passes the
//! dashboard's access rules first ([`super::access`]); each connection has
//! [`HEADER_TIMEOUT`] to send its headers, is closed after
//! [`IDLE_TIMEOUT`] with nothing moving, and at most [`MAX_CONNECTIONS`]
//! are served at once.

use std::convert::Infallible;
use std::net::SocketAddr;
use std::sync::mpsc::Sender;
use std::sync::{Arc, Mutex};
use std::time::Duration;

use anyhow::{Context, Result};
use axum::extract::{Path, Request, State};
use axum::http::{header, HeaderMap, StatusCode};
use axum::middleware::{self, Next};
use axum::response::sse::{Event, Sse};
use axum::response::{IntoResponse, Response};
use axum::routing::{get, post};
use axum::Router;
use futures_util::stream::{self, Stream};
use hyper_util::rt::{TokioIo, TokioTimer};
use hyper_util::service::TowerToHyperService;
use mwd_core::protocol::uplink::fields::{INDEX_DWELL_S, INDEX_POSITIONS};
use mwd_core::protocol::uplink::{Command, IndexingProcedure};

use super::access::{Access, Kind};
use super::connection::IdleLimited;
use super::source::{lock, CommandBatch, Shared};
use crate::survey::job::Job;

/// How often a page gets an update.
const UPDATE_INTERVAL: Duration = Duration::from_millis(250);

/// The time a client has to send a request's headers.
pub const HEADER_TIMEOUT: Duration = Duration::from_secs(5);

/// A connection on which nothing moves either way this long is closed (a
/// body that stops coming, a client that stops reading, an unused
/// kept-alive connection). An open page's event stream writes four times a
/// second.
pub const IDLE_TIMEOUT: Duration = Duration::from_secs(10);

/// Connections served at once; more are closed as they come.
pub const MAX_CONNECTIONS: usize = 32;

/// What the request handlers share.
#[derive(Clone)]
pub struct App {
    pub state: Shared,
    /// The probe's command link; `Err(reason)` when there is none (a
    /// replayed file).
    pub commands: Result<Arc<Mutex<Sender<CommandBatch>>>, String>,
    /// The job file `configure` sends, if one was given.
    pub job: Option<Arc<Job>>,
}

const PAGE: &str = include_str!("../../assets/dashboard/index.html");
/// Where the page gets its run's token.
const PAGE_TOKEN_SLOT: &str = "{{PROBE_TOKEN}}";
const SCRIPT: &str = include_str!("../../assets/dashboard/dashboard.js");
const STYLE: &str = include_str!("../../assets/dashboard/dashboard.css");
const UPLOT_JS: &str = include_str!("../../assets/dashboard/vendor/uplot/uPlot.iife.min.js");
const UPLOT_CSS: &str = include_str!("../../assets/dashboard/vendor/uplot/uPlot.min.css");

fn asset(content_type: &'static str, body: &'static str) -> impl IntoResponse {
    ([(header::CONTENT_TYPE, content_type)], body)
}

/// The page with this run's token. Not to be cached (the token changes
/// each run) nor framed by another site's page.
fn page(token: &str) -> impl IntoResponse + Clone {
    (
        [
            (header::CONTENT_TYPE, "text/html; charset=utf-8"),
            (header::CACHE_CONTROL, "no-store"),
            (header::X_FRAME_OPTIONS, "DENY"),
        ],
        PAGE.replace(PAGE_TOKEN_SLOT, token),
    )
}

/// Refuses what the access rules refuse (status and reason, nothing of the
/// dashboard) before any handler sees it, and any request with a body (no
/// endpoint takes one).
async fn guard(State(access): State<Arc<Access>>, request: Request, next: Next) -> Response {
    let kind = Kind::of(request.method(), request.uri().path());
    if let Err(refusal) = access.check(kind, request.headers(), request.uri().query()) {
        return (refusal.status(), refusal.text()).into_response();
    }
    let headers = request.headers();
    let has_body = headers.contains_key(header::TRANSFER_ENCODING)
        || headers
            .get(header::CONTENT_LENGTH)
            .is_some_and(|v| v.as_bytes() != b"0");
    if has_body {
        let refused = (
            StatusCode::PAYLOAD_TOO_LARGE,
            [(header::CONNECTION, "close")],
            "the dashboard's requests carry no body",
        );
        return refused.into_response();
    }
    next.run(request).await
}

pub fn router(app: App, access: Arc<Access>) -> Router {
    let page = page(access.token());
    Router::new()
        .route(
            "/",
            get(move || {
                let page = page.clone();
                async move { page }
            }),
        )
        .route(
            "/dashboard.js",
            get(|| async { asset("text/javascript; charset=utf-8", SCRIPT) }),
        )
        .route(
            "/dashboard.css",
            get(|| async { asset("text/css; charset=utf-8", STYLE) }),
        )
        .route(
            "/uPlot.js",
            get(|| async { asset("text/javascript; charset=utf-8", UPLOT_JS) }),
        )
        .route(
            "/uPlot.css",
            get(|| async { asset("text/css; charset=utf-8", UPLOT_CSS) }),
        )
        .route("/events", get(events))
        .route("/api/align", post(align))
        .route("/api/station", post(station))
        .route("/api/configure", post(configure))
        .route("/api/index/{positions}/{dwell_s}", post(index))
        .fallback(|| async { (StatusCode::NOT_FOUND, "not found") })
        .with_state(app)
        .layer(middleware::from_fn_with_state(access, guard))
}

/// The update stream: at once everything the page lacks, then what is new
/// every [`UPDATE_INTERVAL`].
async fn events(
    State(app): State<App>,
    headers: HeaderMap,
) -> Sse<impl Stream<Item = Result<Event, Infallible>>> {
    let last_id = headers
        .get("last-event-id")
        .and_then(|v| v.to_str().ok())
        .map(str::to_string);
    let interval = tokio::time::interval(UPDATE_INTERVAL);
    let updates = stream::unfold(
        (app.state, last_id, interval),
        |(state, last_id, mut interval)| async move {
            interval.tick().await;
            let (data, id) = {
                let s = lock(&state);
                (s.update_json(last_id.as_deref()), s.event_id())
            };
            let event = Event::default().id(id.clone()).data(data);
            Some((Ok(event), (state, Some(id), interval)))
        },
    );
    Sse::new(updates)
}

/// Queues commands for the probe (the access rules have passed the
/// request: it carries the token): 202, or 409 with the reason when there
/// is no command link.
fn send(app: &App, batch: CommandBatch) -> (StatusCode, String) {
    match &app.commands {
        Err(reason) => (StatusCode::CONFLICT, reason.clone()),
        Ok(sender) => {
            let sender = sender.lock().unwrap_or_else(|p| p.into_inner());
            match sender.send(batch) {
                Ok(()) => (StatusCode::ACCEPTED, "sent".into()),
                Err(_) => (
                    StatusCode::SERVICE_UNAVAILABLE,
                    "the command link has stopped".into(),
                ),
            }
        }
    }
}

async fn align(State(app): State<App>) -> (StatusCode, String) {
    send(&app, vec![("re-align".into(), Command::Realign)])
}

async fn station(State(app): State<App>) -> (StatusCode, String) {
    send(&app, vec![("take a station".into(), Command::TakeStation)])
}

async fn configure(State(app): State<App>) -> (StatusCode, String) {
    let Some(job) = app.job.clone() else {
        return (
            StatusCode::CONFLICT,
            "no job file: start the dashboard with --job JOB.json".into(),
        );
    };
    let mut batch = job.commands();
    batch.push(("report configuration".into(), Command::ReportConfig));
    send(&app, batch)
}

async fn index(
    State(app): State<App>,
    Path((positions, dwell_s)): Path<(u8, u16)>,
) -> (StatusCode, String) {
    let (p_lo, p_hi) = INDEX_POSITIONS;
    let (d_lo, d_hi) = INDEX_DWELL_S;
    if !(p_lo..=p_hi).contains(&positions) || !(d_lo..=d_hi).contains(&dwell_s) {
        return (
            StatusCode::BAD_REQUEST,
            format!(
                "toolface indexing takes {p_lo} to {p_hi} positions and {d_lo} to {d_hi} s \
                 per position, not {positions} and {dwell_s}"
            ),
        );
    }
    send(
        &app,
        vec![(
            format!("toolface indexing, {positions} positions of {dwell_s} s"),
            Command::IndexToolface(IndexingProcedure { positions, dwell_s }),
        )],
    )
}

/// Serves `app` on `bind` until the process ends, with `token` for the
/// page and its commands; `remote`: other machines may connect (any Host,
/// the token for every read; see [`super::access`]). `listening` gets the
/// access rules, whose address is the one bound (a port 0 becomes a free
/// one).
pub fn serve(
    bind: SocketAddr,
    remote: bool,
    app: App,
    listening: impl FnOnce(SocketAddr, &Access),
) -> Result<()> {
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .context("starting the web server's runtime")?;
    runtime.block_on(async move {
        let listener = tokio::net::TcpListener::bind(bind)
            .await
            .with_context(|| format!("binding {bind}"))?;
        let bound = listener.local_addr().context("the bound address")?;
        let access = Arc::new(Access::new(super::access::new_token(), bound, remote));
        listening(bound, &access);
        let router = router(app, access);
        let slots = Arc::new(tokio::sync::Semaphore::new(MAX_CONNECTIONS));
        loop {
            let stream = match listener.accept().await {
                Ok((stream, _)) => stream,
                // Out of file descriptors and the like: try again shortly.
                Err(_) => {
                    tokio::time::sleep(Duration::from_millis(50)).await;
                    continue;
                }
            };
            // Full: this one is closed at once.
            let Ok(slot) = Arc::clone(&slots).try_acquire_owned() else {
                continue;
            };
            let service = TowerToHyperService::new(router.clone());
            tokio::spawn(async move {
                let io = TokioIo::new(IdleLimited::new(stream, IDLE_TIMEOUT));
                // A client that breaks off, or runs out of time, ends here.
                let _ = hyper::server::conn::http1::Builder::new()
                    .timer(TokioTimer::new())
                    .header_read_timeout(HEADER_TIMEOUT)
                    .serve_connection(io, service)
                    .await;
                drop(slot);
            });
        }
    })
}
