//! The stack around every route, outermost first: panics become 500s,
//! tracing, admission ([`super::guard`]: load shedding, concurrency limit,
//! timeout, body limit, metrics), CORS and compression.

use super::error::AppError;
use super::visitor::{self, ClientAddr};
use super::{guard, AppState};
use axum::http::{header, HeaderName, HeaderValue, Method};
use axum::middleware::from_fn_with_state;
use axum::response::{IntoResponse, Response};
use axum::Router;
use std::any::Any;
use std::time::Duration;
use tower::ServiceBuilder;
use tower_http::catch_panic::CatchPanicLayer;
use tower_http::compression::predicate::{DefaultPredicate, NotForContentType, Predicate};
use tower_http::compression::CompressionLayer;
use tower_http::cors::{AllowOrigin, Any as AnyOrigin, CorsLayer};
use tower_http::trace::{DefaultOnFailure, TraceLayer};
use tracing::Level;

#[derive(Clone, Debug, PartialEq)]
pub struct RequestLimits {
    /// Longest a handler may run; then 504.
    pub timeout: Duration,
    /// Requests handled at once; more are shed with 503 and `Retry-After`.
    pub max_concurrency: usize,
    pub max_body_bytes: usize,
    /// `Retry-After` sent when shedding.
    pub shed_retry_after: Duration,
}

impl Default for RequestLimits {
    fn default() -> Self {
        RequestLimits {
            timeout: Duration::from_secs(10),
            max_concurrency: 1024,
            // The study's view batches are the largest bodies (200 events).
            max_body_bytes: 64 * 1024,
            shed_retry_after: Duration::from_secs(2),
        }
    }
}

/// Wraps every route of `router`.
pub fn apply(router: Router<AppState>, state: &AppState) -> Router<AppState> {
    router.layer(
        ServiceBuilder::new()
            // One `Vary` line, whatever the layers below added.
            .layer(axum::middleware::map_response(cache_merge_vary))
            .layer(CatchPanicLayer::custom(panic_response))
            // Who the visitor is, behind a trusted proxy too.
            .layer(from_fn_with_state(state.clone(), visitor::mark_client))
            // Error responses are logged once, with their cause, by the guard.
            .layer(
                TraceLayer::new_for_http()
                    .make_span_with(request_span)
                    .on_failure(DefaultOnFailure::new().level(Level::DEBUG)),
            )
            .layer(from_fn_with_state(state.clone(), guard::admit))
            // The guard limits bodies (64 KiB; 4 MiB for a IIIF annotation
            // import; an upload's own limit, counted as it streams), so axum's
            // extractors need no limit of their own.
            .layer(axum::extract::DefaultBodyLimit::disable())
            .layer(cors(&state.config().cors_origins))
            // Payloads are entropy-coded already: compress JSON and HTML only.
            .layer(
                CompressionLayer::new().compress_when(
                    DefaultPredicate::new()
                        .and(NotForContentType::const_new("application/octet-stream")),
                ),
            ),
    )
}

async fn cache_merge_vary<B>(response: axum::http::Response<B>) -> axum::http::Response<B> {
    super::cache_headers::merge_vary(response)
}

fn request_span<B>(request: &axum::http::Request<B>) -> tracing::Span {
    let client = request.extensions().get::<ClientAddr>().map(|c| c.0);
    tracing::debug_span!(
        "request",
        method = %request.method(),
        uri = %request.uri(),
        client = ?client,
    )
}

fn panic_response(panic: Box<dyn Any + Send + 'static>) -> Response {
    let detail = panic
        .downcast_ref::<String>()
        .cloned()
        .or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()))
        .unwrap_or_else(|| "panic".into());
    tracing::error!(%detail, "handler panicked");
    AppError::Internal(detail).into_response()
}

fn cors(origins: &[String]) -> CorsLayer {
    let layer = CorsLayer::new()
        .allow_methods([Method::GET, Method::HEAD])
        .allow_headers([
            header::AUTHORIZATION,
            header::IF_NONE_MATCH,
            HeaderName::from_static("sec-ch-ua-mobile"),
        ])
        .expose_headers([header::ETAG, header::RETRY_AFTER, header::CONTENT_LENGTH])
        .max_age(Duration::from_secs(3600));
    let origins: Vec<HeaderValue> = origins
        .iter()
        .filter_map(|o| HeaderValue::from_str(o).ok())
        .collect();
    if origins.is_empty() {
        layer.allow_origin(AnyOrigin)
    } else {
        layer.allow_origin(AllowOrigin::list(origins))
    }
}
