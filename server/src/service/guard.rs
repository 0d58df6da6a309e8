//! Admission for every request, in one middleware: load shedding in front of
//! a global concurrency limit, a timeout, a body limit, in-flight tracking
//! for the load monitor, error logging and request metrics.
//!
//! One `from_fn` rather than a tower layer per concern: axum clones the route
//! stack for every request and every layer nests the response future, which
//! is then moved around (memmove was 9 % of a cached batch's CPU under perf).

use super::admission::Admit;
use super::error::{AppError, LoggedError};
use super::load::InflightGuard;
use super::metrics::Route;
use super::AppState;
use axum::body::{Body, Bytes, HttpBody};
use axum::extract::{Request, State};
use axum::http::{header, HeaderValue, Method};
use axum::middleware::Next;
use axum::response::{IntoResponse, Response};
use std::pin::Pin;
use std::task::{Context, Poll};
use std::time::Instant;
use utoipa::openapi::header::HeaderBuilder;
use utoipa::openapi::schema::{Object, Ref, Type};
use utoipa::openapi::{Content, OpenApi, ResponseBuilder};

/// How long an upload may take to arrive (the ingest runs after the answer).
const UPLOAD_TIMEOUT: std::time::Duration = std::time::Duration::from_secs(30 * 60);

/// Room for an upload's multipart boundaries and text fields.
const UPLOAD_FRAMING_BYTES: u64 = 256 * 1024;

/// Routes that serve data and so count as load; operations routes do not.
fn is_data_route(route: &str) -> bool {
    !matches!(
        route,
        "/healthz" | "/readyz" | "/metrics" | "/api/openapi.json"
    )
}

pub async fn admit(State(state): State<AppState>, request: Request, next: Next) -> Response {
    let started = Instant::now();
    let label = Route::of(&request);
    let route = label.as_str();
    let limits = &state.config().limits;
    let upload = route == "/api/models" && request.method() == Method::POST;
    // The multipart framing around the file is allowed beside the limit.
    let upload_limit = state.config().uploads.limit_bytes + UPLOAD_FRAMING_BYTES;
    // A IIIF annotation import is the one other body over the usual limit.
    let body_limit = if route == super::iiif::import::PATH && request.method() == Method::POST {
        super::iiif::import::MAX_IMPORT_BYTES
    } else if matches!(
        route,
        super::tours::ADMIN_PATH | super::tours::ADMIN_ONE_PATH
    ) && (request.method() == Method::POST || request.method() == Method::PUT)
    {
        // A tour's texts in a dozen languages outgrow the usual limit.
        super::tours::input::MAX_TOUR_BYTES
    } else if route == super::texts::ADMIN_PATH && request.method() == Method::PUT {
        // Twenty languages' descriptions outgrow it too.
        super::texts::input::MAX_TEXTS_BYTES
    } else {
        limits.max_body_bytes
    };
    // A new visit during a surge: refused before anything else is spent on it.
    let admit = if route == "/api/models/{slug}" && request.method() == Method::GET {
        state.admission().admit()
    } else {
        Admit::Yes
    };
    let mut response = match admit {
        Admit::Later(retry_after) => AppError::Busy { retry_after }.into_response(),
        Admit::Yes => match state.permits().clone().try_acquire_owned() {
            // All permits taken: shed rather than queue, so latency stays bounded.
            Err(_) => AppError::Overloaded {
                retry_after: limits.shed_retry_after,
            }
            .into_response(),
            Ok(_permit) if !upload && body_too_large(&request, body_limit) => {
                discard_body(request).await;
                AppError::PayloadTooLarge.into_response()
            }
            // An upload is counted as it streams (413 past the limit); a
            // declared length already over it is refused at once.
            Ok(_permit) if upload && declared_over(&request, upload_limit) => {
                AppError::PayloadTooLarge.into_response()
            }
            Ok(_permit) => {
                let inflight = is_data_route(route).then(|| state.load().begin());
                let timeout = if upload {
                    UPLOAD_TIMEOUT
                } else {
                    limits.timeout
                };
                match tokio::time::timeout(timeout, next.run(request)).await {
                    // The request stays in flight for the load monitor until its
                    // body has gone out: with a crowd, sending is the load, and a
                    // count that ended when the handler returned never saw it.
                    // (The concurrency permit is released now, so a client that
                    // reads slowly cannot hold the service's capacity.)
                    Ok(response) => counted(response, inflight),
                    Err(_) => AppError::Timeout.into_response(),
                }
            }
        },
    };
    if let Some(LoggedError(err)) = response.extensions().get::<LoggedError>() {
        // Refusals under load are expected, and a log line each would add
        // to the load: they are counted in the metrics instead.
        let refused = matches!(**err, AppError::Busy { .. } | AppError::Overloaded { .. });
        if response.status().is_server_error() && !refused {
            tracing::warn!(error = %err, status = %response.status(), route, "request failed");
        } else {
            tracing::debug!(error = %err, status = %response.status(), route, "request refused");
        }
    }
    response
        .headers_mut()
        .entry(header::X_CONTENT_TYPE_OPTIONS)
        .or_insert(HeaderValue::from_static("nosniff"));
    let status = response.status().as_u16();
    state.metrics().observe(label, status, started.elapsed());
    response
}

/// Describes on every operation the answers this guard, and the panic
/// catcher around it ([`super::layers`]), may give instead of the handler's.
pub fn describe_refusals(description: &mut OpenApi) {
    let refusals = [
        (
            "413",
            "Request body over the limit (`payload_too_large`)",
            false,
        ),
        (
            "500",
            "Internal error (`internal`); the detail is in the server's log",
            false,
        ),
        (
            "503",
            "Server overloaded: the concurrency limit is full (`overloaded`)",
            true,
        ),
        (
            "504",
            "The handler ran past the request timeout (`timeout`)",
            false,
        ),
    ];
    for item in description.paths.paths.values_mut() {
        for operation in [
            &mut item.get,
            &mut item.head,
            &mut item.post,
            &mut item.put,
            &mut item.delete,
        ]
        .into_iter()
        .flatten()
        {
            for (status, text, retry_after) in refusals {
                let mut response = ResponseBuilder::new().description(text).content(
                    "application/json",
                    Content::new(Some(Ref::from_schema_name("Error"))),
                );
                if retry_after {
                    let header = HeaderBuilder::new()
                        .schema(Some(Object::with_type(Type::Integer)))
                        .description(Some("Seconds to wait before asking again"))
                        .build();
                    response = response.header("Retry-After", header);
                }
                operation
                    .responses
                    .responses
                    .entry(status.to_owned())
                    .or_insert_with(|| response.build().into());
            }
        }
    }
}

/// A `Content-Length` over `max`.
fn declared_over(request: &Request, max: u64) -> bool {
    request
        .headers()
        .get(header::CONTENT_LENGTH)
        .and_then(|v| v.to_str().ok())
        .is_some_and(|v| v.parse::<u64>().map_or(true, |n| n > max))
}

/// No route takes a body: anything declared larger than the limit, or
/// streamed without a length, is refused before a handler runs.
fn body_too_large(request: &Request, max: usize) -> bool {
    let headers = request.headers();
    let declared = headers
        .get(header::CONTENT_LENGTH)
        .and_then(|v| v.to_str().ok())
        .map(|v| v.parse::<u64>().map_or(true, |n| n > max as u64));
    declared.unwrap_or_else(|| headers.contains_key(header::TRANSFER_ENCODING))
}

/// Bodies up to this size are read and thrown away before a 413 is sent.
const DISCARD_MAX_BYTES: u64 = 4 << 20;
/// How long a refused body may take to be discarded.
const DISCARD_TIME: std::time::Duration = std::time::Duration::from_secs(2);

/// Reads a refused body to its end (up to [`DISCARD_MAX_BYTES`] and
/// [`DISCARD_TIME`]) so the client, still writing it, reads the 413 instead of
/// a reset connection: hyper closes a connection whose body was left unread,
/// and a browser sending a 1 MiB tour then reports a network error, not the
/// limit. (nginx's lingering close does the same.) Past either bound the
/// connection is simply closed.
async fn discard_body(request: Request) {
    use http_body_util::BodyExt;
    if declared_over(&request, DISCARD_MAX_BYTES) || !has_length(&request) {
        return;
    }
    let mut body = request.into_body();
    let _ = tokio::time::timeout(DISCARD_TIME, async {
        while let Some(Ok(_)) = body.frame().await {}
    })
    .await;
}

fn has_length(request: &Request) -> bool {
    request.headers().contains_key(header::CONTENT_LENGTH)
}

/// `response`, its request counted in flight until its body is sent.
pub(super) fn counted(response: Response, inflight: Option<InflightGuard>) -> Response {
    response.map(|body| {
        Body::new(Tracked {
            body,
            _inflight: inflight,
        })
    })
}

/// A response body that keeps its request counted in flight until the body
/// is sent or dropped (client gone). Size hints pass through, so
/// `Content-Length` is kept.
struct Tracked {
    body: Body,
    _inflight: Option<InflightGuard>,
}

impl HttpBody for Tracked {
    type Data = Bytes;
    type Error = axum::Error;

    fn poll_frame(
        mut self: Pin<&mut Self>,
        cx: &mut Context<'_>,
    ) -> Poll<Option<Result<http_body::Frame<Bytes>, axum::Error>>> {
        Pin::new(&mut self.body).poll_frame(cx)
    }

    fn is_end_stream(&self) -> bool {
        self.body.is_end_stream()
    }

    fn size_hint(&self) -> http_body::SizeHint {
        self.body.size_hint()
    }
}
