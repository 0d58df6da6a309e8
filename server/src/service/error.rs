//! One error type for every handler: a stable JSON body and the right status
//! for clients, the internal cause for the log (axum `examples/error-handling`).

use super::cap::{CapReason, LevelCap};
use crate::storage::StorageError;
use axum::http::{header, HeaderValue, StatusCode};
use axum::response::{IntoResponse, Response};
use axum::Json;
use serde::Serialize;
use std::sync::Arc;
use std::time::Duration;
use utoipa::ToSchema;

/// How long clients should wait after a 503 caused by the database.
const DATABASE_RETRY_AFTER: Duration = Duration::from_secs(5);

#[derive(Debug, thiserror::Error)]
pub enum AppError {
    #[error("bad request: {0}")]
    BadRequest(String),
    #[error("invalid or expired token")]
    InvalidToken,
    /// The route needs a token (`Authorization: Bearer …`) and none was sent.
    #[error("this route needs a curator token (Authorization: Bearer …)")]
    TokenRequired,
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
    /// A body within the size limit that holds more than a route takes
    /// (an annotation import's items); the message says which limit.
    #[error("{0}")]
    OverLimit(String),
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
    /// No study is open to this visitor: none runs, or the invitation is
    /// missing, unknown or expired.
    #[error("{0}")]
    StudyClosed(String),
    /// The request contradicts what is stored (an answer given differently).
    #[error("{0}")]
    Conflict(String),
    /// Well-formed, but not acceptable (a value out of range, too early).
    #[error("{0}")]
    Unprocessable(String),
    /// The model's policy does not allow this (a download).
    #[error("{0}")]
    NotAllowed(String),
    /// This session has used its requests.
    #[error("{0}")]
    TooManyRequests(String),
    /// A variant of a standard this service does not serve (oEmbed's XML).
    #[error("{0}")]
    NotImplemented(String),
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
            AppError::InvalidToken | AppError::TokenRequired => StatusCode::UNAUTHORIZED,
            AppError::NotFound(_) => StatusCode::NOT_FOUND,
            AppError::LevelCapped { cap, .. } if cap.reason == Some(CapReason::Load) => {
                StatusCode::TOO_MANY_REQUESTS
            }
            AppError::LevelCapped { .. } => StatusCode::FORBIDDEN,
            AppError::Storage(e) if e.is_unavailable() => StatusCode::SERVICE_UNAVAILABLE,
            AppError::Storage(_) | AppError::Internal(_) => StatusCode::INTERNAL_SERVER_ERROR,
            AppError::PayloadTooLarge | AppError::OverLimit(_) => StatusCode::PAYLOAD_TOO_LARGE,
            AppError::Overloaded { .. } | AppError::Busy { .. } => StatusCode::SERVICE_UNAVAILABLE,
            AppError::Timeout => StatusCode::GATEWAY_TIMEOUT,
            // The stored state conflicts with this build; nothing a client can retry.
            AppError::StaleFormat { .. } => StatusCode::CONFLICT,
            AppError::StudyClosed(_) => StatusCode::FORBIDDEN,
            AppError::Conflict(_) => StatusCode::CONFLICT,
            AppError::Unprocessable(_) => StatusCode::UNPROCESSABLE_ENTITY,
            AppError::TooManyRequests(_) => StatusCode::TOO_MANY_REQUESTS,
            AppError::NotAllowed(_) => StatusCode::FORBIDDEN,
            AppError::NotImplemented(_) => StatusCode::NOT_IMPLEMENTED,
        }
    }

    fn code(&self) -> ErrorCode {
        match self {
            AppError::BadRequest(_) => ErrorCode::BadRequest,
            AppError::InvalidToken => ErrorCode::InvalidToken,
            AppError::TokenRequired => ErrorCode::TokenRequired,
            AppError::NotFound(_) => ErrorCode::NotFound,
            AppError::LevelCapped { .. } => ErrorCode::LevelCapped,
            AppError::Storage(e) if e.is_unavailable() => ErrorCode::DatabaseUnavailable,
            AppError::Storage(_) | AppError::Internal(_) => ErrorCode::Internal,
            AppError::PayloadTooLarge | AppError::OverLimit(_) => ErrorCode::PayloadTooLarge,
            AppError::Overloaded { .. } => ErrorCode::Overloaded,
            AppError::Busy { .. } => ErrorCode::Busy,
            AppError::Timeout => ErrorCode::Timeout,
            AppError::StaleFormat { .. } => ErrorCode::StaleFormat,
            AppError::StudyClosed(_) => ErrorCode::StudyClosed,
            AppError::Conflict(_) => ErrorCode::Conflict,
            AppError::Unprocessable(_) => ErrorCode::Unprocessable,
            AppError::TooManyRequests(_) => ErrorCode::TooManyRequests,
            AppError::NotAllowed(_) => ErrorCode::NotAllowed,
            AppError::NotImplemented(_) => ErrorCode::NotImplemented,
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

    fn body(&self) -> Response {
        let retry_after_s = self.retry_after().map(|d| d.as_secs().max(1));
        match self {
            AppError::LevelCapped { requested, cap, .. } => Json(LevelCappedBody {
                error: LevelCappedCode::LevelCapped,
                requested: *requested,
                cap: cap.level,
                reason: cap.reason,
                retry_after_s,
            })
            .into_response(),
            // Internal detail stays in the log.
            AppError::Storage(_) | AppError::Internal(_) => Json(ErrorBody {
                error: self.code(),
                message: None,
                retry_after_s,
            })
            .into_response(),
            _ => Json(ErrorBody {
                error: self.code(),
                message: Some(self.to_string()),
                retry_after_s,
            })
            .into_response(),
        }
    }
}

/// What went wrong, for clients to branch on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum ErrorCode {
    BadRequest,
    InvalidToken,
    TokenRequired,
    NotFound,
    LevelCapped,
    DatabaseUnavailable,
    PayloadTooLarge,
    Overloaded,
    Busy,
    StaleFormat,
    StudyClosed,
    Conflict,
    Unprocessable,
    TooManyRequests,
    NotAllowed,
    NotImplemented,
    Timeout,
    /// The instance is shutting down (`/readyz` only): send requests elsewhere.
    ShuttingDown,
    Internal,
}

/// The body of every error response but a level cap's.
#[derive(Serialize, ToSchema)]
#[schema(as = Error)]
pub struct ErrorBody {
    pub error: ErrorCode,
    /// What to tell a person; absent when the detail is internal.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub message: Option<String>,
    /// Seconds to wait before asking again, as in `Retry-After`.
    pub retry_after_s: Option<u64>,
}

#[derive(Serialize, ToSchema)]
#[serde(rename_all = "snake_case")]
enum LevelCappedCode {
    LevelCapped,
}

/// A batch above the visitor's level cap (403 or 429).
#[derive(Serialize, ToSchema)]
#[schema(as = LevelCapped)]
pub struct LevelCappedBody {
    error: LevelCappedCode,
    /// The batch asked for.
    requested: u32,
    /// Highest level this visitor may reach now.
    cap: u32,
    reason: Option<CapReason>,
    retry_after_s: Option<u64>,
}

impl IntoResponse for AppError {
    fn into_response(self) -> Response {
        let mut response = self.body();
        *response.status_mut() = self.status();
        let headers = response.headers_mut();
        headers.insert(header::CACHE_CONTROL, HeaderValue::from_static("no-store"));
        if let Some(after) = self.retry_after() {
            headers.insert(
                header::RETRY_AFTER,
                HeaderValue::from(after.as_secs().max(1)),
            );
        }
        if matches!(self, AppError::InvalidToken | AppError::TokenRequired) {
            headers.insert(header::WWW_AUTHENTICATE, HeaderValue::from_static("Bearer"));
        }
        response
            .extensions_mut()
            .insert(LoggedError(Arc::new(self)));
        response
    }
}
