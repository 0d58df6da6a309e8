//! Operations routes: liveness, readiness, metrics, the OpenAPI description.

use super::error::{AppError, ErrorBody, ErrorCode};
use super::{metrics, AppState};
use axum::extract::State;
use axum::http::{header, HeaderValue, StatusCode};
use axum::response::{IntoResponse, Response};
use axum::Json;
use serde::Serialize;
use std::time::Duration;
use utoipa::ToSchema;

/// `/readyz` gives up on the database after this long.
const READY_TIMEOUT: Duration = Duration::from_secs(2);

/// What `/readyz` answers after a timeout.
const READY_RETRY_AFTER_S: u64 = 5;

#[derive(Serialize, ToSchema)]
#[serde(rename_all = "lowercase")]
enum Liveness {
    Ok,
}

#[derive(Serialize, ToSchema)]
pub struct Health {
    status: Liveness,
}

#[derive(Serialize, ToSchema)]
#[serde(rename_all = "lowercase")]
enum Readiness {
    Ready,
}

#[derive(Serialize, ToSchema)]
pub struct Ready {
    status: Readiness,
    /// The storage backend: `sqlite` or `postgres`.
    database: &'static str,
}

/// Liveness: the process answers.
#[utoipa::path(
    get,
    path = "/healthz",
    responses((status = 200, description = "Alive", body = Health))
)]
pub async fn healthz() -> Json<Health> {
    Json(Health {
        status: Liveness::Ok,
    })
}

/// Readiness: the database answers, and the instance is not shutting down.
///
/// A load balancer stops sending data requests while it is away, and health
/// checks keep the process alive. After SIGTERM it answers 503
/// `shutting_down` while open requests finish.
#[utoipa::path(
    get,
    path = "/readyz",
    responses(
        (status = 200, description = "Ready", body = Ready),
        (status = 503, description = "Database unavailable, or shutting down", body = ErrorBody,
            headers(("Retry-After" = u64, description = "Seconds to wait before asking again"))),
    )
)]
pub async fn readyz(State(state): State<AppState>) -> Response {
    if state.is_draining() {
        let body = ErrorBody {
            error: ErrorCode::ShuttingDown,
            message: Some("shutting down".into()),
            retry_after_s: Some(READY_RETRY_AFTER_S),
        };
        return (
            StatusCode::SERVICE_UNAVAILABLE,
            [
                (header::RETRY_AFTER, HeaderValue::from(READY_RETRY_AFTER_S)),
                (header::CACHE_CONTROL, HeaderValue::from_static("no-store")),
            ],
            Json(body),
        )
            .into_response();
    }
    match tokio::time::timeout(READY_TIMEOUT, state.storage().ping()).await {
        Ok(Ok(())) => Json(Ready {
            status: Readiness::Ready,
            database: state.storage().backend(),
        })
        .into_response(),
        Ok(Err(e)) => AppError::from(e).into_response(),
        Err(_) => {
            let body = ErrorBody {
                error: ErrorCode::DatabaseUnavailable,
                message: None,
                retry_after_s: Some(READY_RETRY_AFTER_S),
            };
            (
                StatusCode::SERVICE_UNAVAILABLE,
                [(header::RETRY_AFTER, HeaderValue::from(READY_RETRY_AFTER_S))],
                Json(body),
            )
                .into_response()
        }
    }
}

/// Prometheus metrics: requests, latencies, cache hits, load pressure, caps.
#[utoipa::path(
    get,
    path = "/metrics",
    responses(
        (status = 200, description = "Text exposition format", body = String,
            content_type = "text/plain"),
    )
)]
pub async fn prometheus(State(state): State<AppState>) -> Response {
    let content_type = HeaderValue::from_static("text/plain; version=0.0.4; charset=utf-8");
    (
        [(header::CONTENT_TYPE, content_type)],
        metrics::render(&state),
    )
        .into_response()
}
