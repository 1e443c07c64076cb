//! The dashboard's web server: the page and its scripts (embedded, so it
//! works with no network), the data as server-sent events (a page that
//! reconnects sends `Last-Event-ID` and picks up where the stream is), and
//! the probe's commands as POST requests.

use std::convert::Infallible;
use std::net::SocketAddr;
use std::sync::mpsc::Sender;
use std::sync::{Arc, Mutex};
use std::time::Duration;

use anyhow::{Context, Result};
use axum::extract::{Path, State};
use axum::http::{header, HeaderMap, StatusCode};
use axum::response::sse::{Event, Sse};
use axum::response::IntoResponse;
use axum::routing::{get, post};
use axum::Router;
use futures_util::stream::{self, Stream};
use mwd_core::protocol::uplink::fields::{INDEX_DWELL_S, INDEX_POSITIONS};
use mwd_core::protocol::uplink::{Command, IndexingProcedure};

use super::source::{lock, CommandBatch, Shared};
use crate::survey::job::Job;

/// How often a page gets an update.
const UPDATE_INTERVAL: Duration = Duration::from_millis(250);

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
const SCRIPT: &str = include_str!("../../assets/dashboard/dashboard.js");
const STYLE: &str = include_str!("../../assets/dashboard/dashboard.css");
const UPLOT_JS: &str = include_str!("../../assets/dashboard/vendor/uplot/uPlot.iife.min.js");
const UPLOT_CSS: &str = include_str!("../../assets/dashboard/vendor/uplot/uPlot.min.css");

fn asset(content_type: &'static str, body: &'static str) -> impl IntoResponse {
    ([(header::CONTENT_TYPE, content_type)], body)
}

pub fn router(app: App) -> Router {
    Router::new()
        .route(
            "/",
            get(|| async { asset("text/html; charset=utf-8", PAGE) }),
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
        .with_state(app)
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

/// The header the page sends with every command. A request with a custom
/// header needs a CORS preflight, which this server does not grant: so
/// another site open in the same browser cannot command the probe.
pub const COMMAND_HEADER: &str = "x-mwd-dashboard";

/// Queues commands for the probe: 202, 403 without the page's header, or
/// 409 with the reason when there is no command link.
fn send(app: &App, headers: &HeaderMap, batch: CommandBatch) -> (StatusCode, String) {
    if !headers.contains_key(COMMAND_HEADER) {
        return (
            StatusCode::FORBIDDEN,
            format!("commands are taken from the dashboard's page only (header {COMMAND_HEADER})"),
        );
    }
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

async fn align(State(app): State<App>, headers: HeaderMap) -> (StatusCode, String) {
    send(&app, &headers, vec![("re-align".into(), Command::Realign)])
}

async fn station(State(app): State<App>, headers: HeaderMap) -> (StatusCode, String) {
    send(
        &app,
        &headers,
        vec![("take a station".into(), Command::TakeStation)],
    )
}

async fn configure(State(app): State<App>, headers: HeaderMap) -> (StatusCode, String) {
    let Some(job) = app.job.clone() else {
        return (
            StatusCode::CONFLICT,
            "no job file: start the dashboard with --job JOB.json".into(),
        );
    };
    let mut batch = job.commands();
    batch.push(("report configuration".into(), Command::ReportConfig));
    send(&app, &headers, batch)
}

async fn index(
    State(app): State<App>,
    headers: HeaderMap,
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
        &headers,
        vec![(
            format!("toolface indexing, {positions} positions of {dwell_s} s"),
            Command::IndexToolface(IndexingProcedure { positions, dwell_s }),
        )],
    )
}

/// Serves `app` on `bind` until the process ends; `listening` gets the
/// address bound (a port 0 becomes a free one).
pub fn serve(bind: SocketAddr, app: App, listening: impl FnOnce(SocketAddr)) -> Result<()> {
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .context("starting the web server's runtime")?;
    runtime.block_on(async move {
        let listener = tokio::net::TcpListener::bind(bind)
            .await
            .with_context(|| format!("binding {bind}"))?;
        listening(listener.local_addr().context("the bound address")?);
        axum::serve(listener, router(app))
            .await
            .context("serving the dashboard")
    })
}
