//! Operations routes: liveness, readiness, metrics, the OpenAPI description.

use super::error::AppError;
use super::{metrics, AppState};
use axum::extract::State;
use axum::http::{header, HeaderValue, StatusCode};
use axum::response::{IntoResponse, Response};
use axum::routing::get;
use axum::{Json, Router};
use serde_json::json;
use std::time::Duration;

/// Hand-written rather than derived (utoipa): the API is small, and a test
/// checks that every route in [`super::ROUTES`] is described.
pub const OPENAPI: &str = include_str!("../../openapi.json");

/// `/readyz` gives up on the database after this long.
const READY_TIMEOUT: Duration = Duration::from_secs(2);

pub fn routes() -> Router<AppState> {
    Router::new()
        .route(
            "/healthz",
            get(|| async { Json(json!({ "status": "ok" })) }),
        )
        .route("/readyz", get(ready))
        .route("/metrics", get(prometheus))
        .route("/api/openapi.json", get(openapi))
}

/// Ready when the database answers: a load balancer stops sending data
/// requests while it is away, and health checks keep the process alive.
async fn ready(State(state): State<AppState>) -> Response {
    match tokio::time::timeout(READY_TIMEOUT, state.storage().ping()).await {
        Ok(Ok(())) => Json(json!({ "status": "ready", "database": state.storage().backend() }))
            .into_response(),
        Ok(Err(e)) => AppError::from(e).into_response(),
        Err(_) => {
            let body = json!({ "error": "database_unavailable", "retry_after_s": 5 });
            (
                StatusCode::SERVICE_UNAVAILABLE,
                [(header::RETRY_AFTER, "5")],
                Json(body),
            )
                .into_response()
        }
    }
}

async fn prometheus(State(state): State<AppState>) -> Response {
    let content_type = HeaderValue::from_static("text/plain; version=0.0.4; charset=utf-8");
    (
        [(header::CONTENT_TYPE, content_type)],
        metrics::render(&state),
    )
        .into_response()
}

async fn openapi() -> Response {
    (
        [(
            header::CONTENT_TYPE,
            HeaderValue::from_static("application/json"),
        )],
        OPENAPI,
    )
        .into_response()
}
