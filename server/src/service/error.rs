//! One error type for every handler: a stable JSON body and the right status
//! for clients, the internal cause for the log (axum `examples/error-handling`).

use super::cap::{CapReason, LevelCap};
use crate::storage::StorageError;
use axum::http::{header, HeaderValue, StatusCode};
use axum::response::{IntoResponse, Response};
use axum::Json;
use serde_json::json;
use std::sync::Arc;
use std::time::Duration;

/// How long clients should wait after a 503 caused by the database.
const DATABASE_RETRY_AFTER: Duration = Duration::from_secs(5);

#[derive(Debug, thiserror::Error)]
pub enum AppError {
    #[error("bad request: {0}")]
    BadRequest(String),
    #[error("invalid or expired token")]
    InvalidToken,
    #[error("{0} not found")]
    NotFound(&'static str),
    /// The batch is above this visitor's level cap.
    #[error("level {requested} is above the cap {cap:?}")]
    LevelCapped {
        requested: u32,
        cap: LevelCap,
        retry_after: Duration,
    },
    #[error(transparent)]
    Storage(Arc<StorageError>),
    #[error("request body too large")]
    PayloadTooLarge,
    #[error("service overloaded")]
    Overloaded { retry_after: Duration },
    /// Too many new visitors at once ([`super::admission`]): come back later.
    #[error("too many new visitors at once; try again after Retry-After")]
    Busy { retry_after: Duration },
    #[error("request timed out")]
    Timeout,
    /// The model's payloads are in a stream format this build cannot
    /// decode (stored by an older Vitrine): it must be ingested again.
    #[error(
        "model '{slug}' is stored in stream format {stored}; this server reads format {reads}: \
         ingest it again (vitrine ingest) to show it"
    )]
    StaleFormat { slug: String, stored: u8, reads: u8 },
    #[error("internal error: {0}")]
    Internal(String),
}

impl From<StorageError> for AppError {
    fn from(e: StorageError) -> Self {
        AppError::Storage(Arc::new(e))
    }
}

impl From<Arc<StorageError>> for AppError {
    fn from(e: Arc<StorageError>) -> Self {
        AppError::Storage(e)
    }
}

/// The error behind a response, logged by [`super::guard`].
#[derive(Clone, Debug)]
pub struct LoggedError(pub Arc<AppError>);

impl AppError {
    pub fn status(&self) -> StatusCode {
        match self {
            AppError::BadRequest(_) => StatusCode::BAD_REQUEST,
            AppError::InvalidToken => StatusCode::UNAUTHORIZED,
            AppError::NotFound(_) => StatusCode::NOT_FOUND,
            AppError::LevelCapped { cap, .. } if cap.reason == Some(CapReason::Load) => {
                StatusCode::TOO_MANY_REQUESTS
            }
            AppError::LevelCapped { .. } => StatusCode::FORBIDDEN,
            AppError::Storage(e) if e.is_unavailable() => StatusCode::SERVICE_UNAVAILABLE,
            AppError::Storage(_) | AppError::Internal(_) => StatusCode::INTERNAL_SERVER_ERROR,
            AppError::PayloadTooLarge => StatusCode::PAYLOAD_TOO_LARGE,
            AppError::Overloaded { .. } | AppError::Busy { .. } => StatusCode::SERVICE_UNAVAILABLE,
            AppError::Timeout => StatusCode::GATEWAY_TIMEOUT,
            // The stored state conflicts with this build; nothing a client can retry.
            AppError::StaleFormat { .. } => StatusCode::CONFLICT,
        }
    }

    fn code(&self) -> &'static str {
        match self {
            AppError::BadRequest(_) => "bad_request",
            AppError::InvalidToken => "invalid_token",
            AppError::NotFound(_) => "not_found",
            AppError::LevelCapped { .. } => "level_capped",
            AppError::Storage(e) if e.is_unavailable() => "database_unavailable",
            AppError::Storage(_) | AppError::Internal(_) => "internal",
            AppError::PayloadTooLarge => "payload_too_large",
            AppError::Overloaded { .. } => "overloaded",
            AppError::Busy { .. } => "busy",
            AppError::Timeout => "timeout",
            AppError::StaleFormat { .. } => "stale_format",
        }
    }

    fn retry_after(&self) -> Option<Duration> {
        match self {
            AppError::LevelCapped {
                cap, retry_after, ..
            } if cap.reason == Some(CapReason::Load) => Some(*retry_after),
            AppError::Storage(e) if e.is_unavailable() => Some(DATABASE_RETRY_AFTER),
            AppError::Overloaded { retry_after } | AppError::Busy { retry_after } => {
                Some(*retry_after)
            }
            _ => None,
        }
    }

    fn body(&self) -> serde_json::Value {
        let retry_after_s = self.retry_after().map(|d| d.as_secs().max(1));
        match self {
            AppError::LevelCapped { requested, cap, .. } => json!({
                "error": self.code(),
                "requested": requested,
                "cap": cap.level,
                "reason": cap.reason,
                "retry_after_s": retry_after_s,
            }),
            // Internal detail stays in the log.
            AppError::Storage(_) | AppError::Internal(_) => json!({
                "error": self.code(),
                "retry_after_s": retry_after_s,
            }),
            _ => {
                json!({ "error": self.code(), "message": self.to_string(), "retry_after_s": retry_after_s })
            }
        }
    }
}

impl IntoResponse for AppError {
    fn into_response(self) -> Response {
        let mut response = (self.status(), Json(self.body())).into_response();
        let headers = response.headers_mut();
        headers.insert(header::CACHE_CONTROL, HeaderValue::from_static("no-store"));
        if let Some(after) = self.retry_after() {
            headers.insert(
                header::RETRY_AFTER,
                HeaderValue::from(after.as_secs().max(1)),
            );
        }
        if matches!(self, AppError::InvalidToken) {
            headers.insert(header::WWW_AUTHENTICATE, HeaderValue::from_static("Bearer"));
        }
        response
            .extensions_mut()
            .insert(LoggedError(Arc::new(self)));
        response
    }
}
