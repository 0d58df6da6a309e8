//! `/api/models/{slug}/thumbnail`: the picture rendered at ingest
//! (`ingest::curation`), with a strong ETag (its SHA-256) and 304 on
//! `If-None-Match`.

use crate::service::error::{AppError, ErrorBody};
use crate::service::payload::{not_modified, not_modified_response, Binary, Conditional};
use crate::service::servable::{ServableModel, SlugParam};
use crate::service::AppState;
use axum::extract::State;
use axum::http::{header, HeaderMap, HeaderValue};
use axum::response::{IntoResponse, Response};

/// Revalidated each time: the unversioned URL shows the newest version's
/// picture (the list's `?v=` URLs change with the version).
const CACHE_CONTROL: &str = "no-cache";

/// The URL the list and the manifest give for a version's thumbnail.
pub fn url(slug: &str, version: u32) -> String {
    format!("/api/models/{slug}/thumbnail?v={version}")
}

/// The model's thumbnail (PNG, 512 × 512).
#[utoipa::path(
    get,
    path = "/api/models/{slug}/thumbnail",
    params(SlugParam, Conditional),
    responses(
        (status = 200, description = "PNG", body = Binary, content_type = "image/png",
            headers(("ETag" = String, description = "Strong: the image's SHA-256"))),
        (status = 304, description = "Not modified"),
        (status = 400, description = "Malformed slug or `Authorization`", body = ErrorBody),
        (status = 404, description = "No such model, or a version ingested without a thumbnail",
            body = ErrorBody),
        (status = 503, description = "Database unavailable or server overloaded", body = ErrorBody),
    )
)]
pub async fn thumbnail(
    State(state): State<AppState>,
    ServableModel { record, .. }: ServableModel,
    headers: HeaderMap,
) -> Result<Response, AppError> {
    let sha = record
        .curation
        .thumbnail_sha256
        .as_deref()
        .ok_or(AppError::NotFound("thumbnail"))?;
    let etag = HeaderValue::from_str(&format!("\"{sha}\""))
        .map_err(|_| AppError::Internal("unprintable thumbnail digest".into()))?;
    if not_modified(&headers, &etag) {
        return Ok(not_modified_response(etag, CACHE_CONTROL));
    }
    let image = state
        .storage()
        .thumbnail(record.model_id)
        .await?
        .ok_or(AppError::NotFound("thumbnail"))?;
    let media_type = HeaderValue::from_str(&image.media_type)
        .map_err(|_| AppError::Internal("unprintable thumbnail media type".into()))?;
    Ok((
        [
            (header::CONTENT_TYPE, media_type),
            (header::ETAG, etag),
            (
                header::CACHE_CONTROL,
                HeaderValue::from_static(CACHE_CONTROL),
            ),
        ],
        image.bytes,
    )
        .into_response())
}
