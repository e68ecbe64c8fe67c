//! The HTTP routes (docs/viewer.md): the embedded page, the run's overview, frames, timeline and robot panel,
//! and for live runs a server-sent event stream of the newest frame. One small runtime thread serves them; the
//! run itself never waits for it, since everything is read back from the record files.

use std::sync::{Arc, Mutex, MutexGuard, PoisonError};
use std::time::Duration;

use axum::Router;
use axum::extract::{Path, Query, Request, State};
use axum::http::{HeaderValue, StatusCode, header};
use axum::middleware::{self, Next};
use axum::response::sse::{Event, KeepAlive, Sse};
use axum::response::{IntoResponse, Response};
use axum::routing::get;
use base64::Engine;
use serde::Deserialize;
use serde_json::json;

use crate::page;
use crate::run::{Refusal, RunRecord};

/// How often a live stream looks for a newer tick: the display rate of `swarm run --view`.
const LIVE_PERIOD: Duration = Duration::from_millis(100);

/// What every route shares.
#[derive(Clone)]
pub struct Shared {
    record: Arc<Mutex<RunRecord>>,
    /// The `Host` header values a request may carry (empty: any), so that a web page elsewhere cannot read the
    /// run through a name that resolves to this machine.
    allowed_hosts: Arc<Vec<String>>,
}

impl Shared {
    /// The routes' state over `record`.
    pub fn new(record: RunRecord, allowed_hosts: Vec<String>) -> Self {
        Self {
            record: Arc::new(Mutex::new(record)),
            allowed_hosts: Arc::new(allowed_hosts),
        }
    }

    /// The record with everything written so far read in.
    fn fresh(&self) -> MutexGuard<'_, RunRecord> {
        let mut record = self.record.lock().unwrap_or_else(PoisonError::into_inner);
        record.refresh();
        record
    }
}

/// Every route.
pub fn routes(shared: Shared) -> Router {
    Router::new()
        .route("/", get(|| async { page::INDEX.respond() }))
        .route("/viewer.js", get(|| async { page::SCRIPT.respond() }))
        .route("/viewer.css", get(|| async { page::STYLE.respond() }))
        .route("/api/run", get(run))
        .route("/api/floor.png", get(floor))
        .route("/api/frames", get(frames))
        .route("/api/objects", get(objects))
        .route("/api/pheromone", get(pheromone))
        .route("/api/timeline", get(timeline))
        .route("/api/robot/{index}", get(robot))
        .route("/api/live", get(live))
        .layer(middleware::from_fn_with_state(shared.clone(), known_host))
        .with_state(shared)
}

async fn known_host(State(shared): State<Shared>, request: Request, next: Next) -> Response {
    let host = request
        .headers()
        .get(header::HOST)
        .and_then(|h| h.to_str().ok())
        .unwrap_or_default();
    if !shared.allowed_hosts.is_empty() && !shared.allowed_hosts.iter().any(|h| h == host) {
        return (
            StatusCode::FORBIDDEN,
            format!("host `{host}` is not this viewer's address"),
        )
            .into_response();
    }
    let mut response = next.run(request).await;
    response
        .headers_mut()
        .insert(header::CACHE_CONTROL, HeaderValue::from_static("no-store"));
    response
}

fn refused(refusal: Refusal) -> Response {
    let (status, text) = match refusal {
        Refusal::BadRequest(text) => (StatusCode::BAD_REQUEST, text),
        Refusal::NotFound(text) => (StatusCode::NOT_FOUND, text),
        Refusal::Unavailable(text) => (StatusCode::SERVICE_UNAVAILABLE, text),
    };
    (status, text).into_response()
}

async fn run(State(shared): State<Shared>) -> Response {
    axum::Json(shared.fresh().overview()).into_response()
}

async fn floor(State(shared): State<Shared>) -> Response {
    let path = shared.fresh().floor_image();
    match path.map(std::fs::read) {
        Some(Ok(bytes)) => ([(header::CONTENT_TYPE, "image/png")], bytes).into_response(),
        _ => (StatusCode::NOT_FOUND, "this run has no floor image").into_response(),
    }
}

/// `/api/frames` parameters.
#[derive(Deserialize)]
struct FramesQuery {
    from: u64,
    #[serde(default = "one")]
    count: u64,
    #[serde(default = "one")]
    stride: u64,
}

fn one() -> u64 {
    1
}

async fn frames(State(shared): State<Shared>, Query(query): Query<FramesQuery>) -> Response {
    match shared.fresh().frames(query.from, query.count, query.stride) {
        Ok(body) => ([(header::CONTENT_TYPE, "application/octet-stream")], body).into_response(),
        Err(refusal) => refused(refusal),
    }
}

/// `/api/pheromone` and `/api/objects` parameters.
#[derive(Deserialize)]
struct TickQuery {
    tick: u64,
}

async fn objects(State(shared): State<Shared>, Query(query): Query<TickQuery>) -> Response {
    axum::Json(shared.fresh().objects(query.tick)).into_response()
}

async fn pheromone(State(shared): State<Shared>, Query(query): Query<TickQuery>) -> Response {
    match shared.fresh().pheromone(query.tick) {
        Ok(Some(frame)) => {
            ([(header::CONTENT_TYPE, "application/octet-stream")], frame).into_response()
        }
        Ok(None) => StatusCode::NO_CONTENT.into_response(),
        Err(refusal) => refused(refusal),
    }
}

async fn timeline(State(shared): State<Shared>) -> Response {
    axum::Json(shared.fresh().timeline()).into_response()
}

/// `/api/robot/{index}` parameters.
#[derive(Deserialize)]
struct RobotQuery {
    at: u64,
}

async fn robot(
    State(shared): State<Shared>,
    Path(index): Path<usize>,
    Query(query): Query<RobotQuery>,
) -> Response {
    match shared.fresh().robot(index, query.at) {
        Ok(value) => axum::Json(value).into_response(),
        Err(refusal) => refused(refusal),
    }
}

/// Where one live stream stands.
struct LiveStream {
    shared: Shared,
    sent: Option<u64>,
    done: bool,
}

async fn live(State(shared): State<Shared>) -> Response {
    if !shared.fresh().live() {
        return (
            StatusCode::NOT_FOUND,
            "this viewer replays a finished run; nothing is live",
        )
            .into_response();
    }
    let start = LiveStream {
        shared,
        sent: None,
        done: false,
    };
    let stream = futures_util::stream::unfold(start, |mut stream| async move {
        if stream.done {
            return None;
        }
        loop {
            let event = stream.next_event();
            if let Some(event) = event {
                return Some((Ok::<Event, std::convert::Infallible>(event), stream));
            }
            tokio::time::sleep(LIVE_PERIOD).await;
        }
    });
    Sse::new(stream)
        .keep_alive(KeepAlive::default())
        .into_response()
}

impl LiveStream {
    /// The event to send now: a newer frame, or the run's end; `None` while nothing changed.
    fn next_event(&mut self) -> Option<Event> {
        let record = self.shared.fresh();
        let finished = record.finished();
        let last = record.last_tick();
        let newer = last.filter(|&l| self.sent.is_none_or(|s| l > s));
        if newer.is_none() && !finished {
            return None;
        }
        let frame = newer
            .or(self.sent)
            .and_then(|tick| record.frames(tick, 1, 1).ok())
            .map(|body| base64::engine::general_purpose::STANDARD.encode(body));
        drop(record);
        if let Some(tick) = newer {
            self.sent = Some(tick);
        }
        self.done = finished && newer.is_none();
        let data = json!({"last": self.sent, "finished": self.done, "frame": frame});
        Some(Event::default().event("frame").data(data.to_string()))
    }
}
