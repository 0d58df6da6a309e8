//! Binary routes: base mesh, refinement batches, textures.
//!
//! Payloads never change once stored, so each has a strong ETag (its SHA-256)
//! and `Cache-Control: immutable`; conditional requests get 304 without
//! touching the payload. Batches above the visitor's level cap get 403
//! (audience or device) or 429 with `Retry-After` (load), JSON
//! `{"error": "level_capped", "cap": k, "reason": …}`. The cap check reads only
//! cached records, never the database, once a model is warm.

use super::cache::{Payload, PayloadKey, TextureEntry};
use super::cap::{audience_cap, Audience, CapReason};
use super::error::{AppError, ErrorBody, LevelCappedBody};
use super::servable::{PathParams, ServableModel};
use super::visitor::{HintQuery, VisitorHints};
use super::{AppState, Visitor};
use crate::storage::{ModelRecord, StorageError};
use axum::extract::State;
use axum::http::{header, HeaderMap, HeaderValue, StatusCode};
use axum::response::{IntoResponse, Response};
use bytes::Bytes;
use serde::Deserialize;
use std::sync::Arc;
use utoipa::{IntoParams, ToSchema};

pub(super) const OCTET_STREAM: &str = "application/octet-stream";
const PUBLIC_IMMUTABLE: &str = "public, max-age=31536000, immutable";
/// Levels only a token unlocks: browsers may keep them, shared caches may not.
const PRIVATE_IMMUTABLE: &str = "private, max-age=31536000, immutable";

/// Ids stay text until [`parse_id`], so that a malformed one gets our 400.
#[derive(Deserialize, IntoParams)]
#[into_params(parameter_in = Path)]
pub struct CompressionParam {
    /// Compression id, from the manifest.
    #[param(value_type = i64, minimum = 1)]
    id: String,
}

#[derive(Deserialize, IntoParams)]
#[into_params(parameter_in = Path)]
pub struct BatchParams {
    /// Compression id, from the manifest.
    #[param(value_type = i64, minimum = 1)]
    id: String,
    /// Batch number, 1 … `last_level`.
    #[param(value_type = i64, minimum = 1)]
    iteration: String,
}

#[derive(Deserialize, IntoParams)]
#[into_params(parameter_in = Path)]
pub struct TextureParam {
    /// Texture id, from the manifest.
    #[param(value_type = i64, minimum = 1)]
    id: String,
}

// Describes answers only (handlers send `Bytes`), as `Conditional` below
// describes a header the handlers read from the `HeaderMap`.
/// Opaque bytes: a payload of the stream (codec/FORMAT.md) or an image.
#[derive(ToSchema)]
#[schema(value_type = String, format = Binary)]
#[allow(dead_code)]
pub struct Binary(Bytes);

#[derive(IntoParams)]
#[into_params(parameter_in = Header)]
#[allow(dead_code)]
pub struct Conditional {
    /// ETags from earlier answers: 304 when one is this payload's.
    #[param(rename = "If-None-Match", value_type = String, required = false)]
    if_none_match: Option<String>,
}

/// Stream header plus base mesh (level 0).
#[utoipa::path(
    get,
    path = "/api/compressions/{id}/base",
    params(CompressionParam, HintQuery,
        Conditional),
    responses(
        (status = 200, description = "Payload", body = inline(Binary), content_type = "application/octet-stream",
            headers(
                ("ETag" = String, description = "Strong ETag (SHA-256 of the payload)"),
                ("Cache-Control" = String, description = "`public, max-age=31536000, immutable`, \
                    or `private, …` for levels only a token unlocks"))),
        (status = 304, description = "Not modified", headers(("ETag" = String), ("Cache-Control" = String))),
        (status = 400, description = "Malformed id, query or `Authorization`", body = ErrorBody),
        (status = 401, description = "The token is unknown, revoked or expired", body = ErrorBody),
        (status = 404, description = "No such compression", body = ErrorBody),
        (status = 409, description = "Stored in a stream format this build cannot decode", body = ErrorBody),
        (status = 503, description = "Database unavailable or server overloaded", body = ErrorBody,
            headers(("Retry-After" = u64, description = "Seconds to wait before asking again"))),
    )
)]
pub async fn base(
    State(state): State<AppState>,
    PathParams(CompressionParam { id }): PathParams<CompressionParam>,
    hints: VisitorHints,
    headers: HeaderMap,
) -> Result<Response, AppError> {
    let id = parse_id(&id, "compression id")?;
    let record = state.record_by_compression(id).await?;
    let model = ServableModel::decide(&state, record, &hints).await?;
    mesh(&state, &model.record, 0, &headers).await
}

/// Refinement batch `iteration` (1-based): applied to level iteration−1 it
/// gives level iteration.
#[utoipa::path(
    get,
    path = "/api/compressions/{id}/batches/{iteration}",
    params(BatchParams, HintQuery,
        Conditional),
    responses(
        (status = 200, description = "Payload", body = inline(Binary), content_type = "application/octet-stream",
            headers(
                ("ETag" = String, description = "Strong ETag (SHA-256 of the payload)"),
                ("Cache-Control" = String, description = "`public, max-age=31536000, immutable`, \
                    or `private, …` for levels only a token unlocks"))),
        (status = 304, description = "Not modified", headers(("ETag" = String), ("Cache-Control" = String))),
        (status = 400, description = "Malformed id, iteration, query or `Authorization`", body = ErrorBody),
        (status = 401, description = "The token is unknown, revoked or expired", body = ErrorBody),
        (status = 403, description = "Above the cap set by the audience policy or the device class \
            (`reason`: `audience`, `device`)", body = LevelCappedBody),
        (status = 404, description = "No such compression or batch", body = ErrorBody),
        (status = 409, description = "Stored in a stream format this build cannot decode", body = ErrorBody),
        (status = 429, description = "Above the cap set by server load (`reason`: `load`); ask \
            again after `Retry-After`", body = LevelCappedBody,
            headers(("Retry-After" = u64, description = "Seconds to wait before asking again"))),
        (status = 503, description = "Database unavailable or server overloaded", body = ErrorBody,
            headers(("Retry-After" = u64, description = "Seconds to wait before asking again"))),
    )
)]
pub async fn batch(
    State(state): State<AppState>,
    PathParams(BatchParams { id, iteration }): PathParams<BatchParams>,
    hints: VisitorHints,
    headers: HeaderMap,
) -> Result<Response, AppError> {
    let id = parse_id(&id, "compression id")?;
    let iteration: u32 = parse_id(&iteration, "iteration")?
        .try_into()
        .map_err(|_| AppError::NotFound("batch"))?;
    let record = state.record_by_compression(id).await?;
    let ServableModel { record, visitor } = ServableModel::decide(&state, record, &hints).await?;
    if iteration == 0 || iteration > record.batch_count() {
        return Err(AppError::NotFound("batch"));
    }
    within_cap(&state, &record, &visitor, iteration)?;
    mesh(&state, &record, iteration, &headers).await
}

/// Refuses a batch above the visitor's level cap.
pub(super) fn within_cap(
    state: &AppState,
    record: &ModelRecord,
    visitor: &Visitor,
    iteration: u32,
) -> Result<(), AppError> {
    let cap = state.level_cap(record, visitor);
    if iteration <= cap.level {
        return Ok(());
    }
    let reason = match cap.reason {
        Some(CapReason::Audience) => "audience",
        Some(CapReason::Device) => "device",
        _ => "load",
    };
    state.metrics().capped(reason);
    Err(AppError::LevelCapped {
        requested: iteration,
        cap,
        retry_after: state.load().config().retry_after,
    })
}

/// Level `level`'s payload: the base mesh for 0, else batch `level`.
async fn mesh(
    state: &AppState,
    record: &ModelRecord,
    level: u32,
    headers: &HeaderMap,
) -> Result<Response, AppError> {
    let etag = etag(&record.levels[level as usize].sha256);
    let cache_control = cache_control(record, level);
    if not_modified(headers, &etag) {
        return Ok(not_modified_response(etag, cache_control));
    }
    let bytes = level_bytes(state, record, level).await?;
    Ok(payload_response(
        bytes,
        etag,
        cache_control,
        HeaderValue::from_static(OCTET_STREAM),
    ))
}

/// The stored payload of level `level`, through the payload cache.
pub(super) async fn level_bytes(
    state: &AppState,
    record: &ModelRecord,
    level: u32,
) -> Result<Bytes, AppError> {
    let id = record.compression_id;
    let storage = state.storage();
    let load = async {
        let bytes = if level == 0 {
            storage.base_payload(id).await?
        } else {
            storage.batch_payload(id, level).await?
        };
        bytes
            .map(|b| Payload::Mesh(b.into()))
            .ok_or_else(|| missing(id, level))
    };
    let key = if level == 0 {
        PayloadKey::Base(id)
    } else {
        PayloadKey::Batch(id, level)
    };
    let Payload::Mesh(bytes) = state.caches().payload(state.metrics(), key, load).await? else {
        return Err(AppError::Internal(
            "payload cache returned a texture for a mesh key".into(),
        ));
    };
    Ok(bytes)
}

/// An image of a CCC colour mapping: the cell texture (PNG) or the full- or
/// low-resolution colour atlas (JPEG).
#[utoipa::path(
    get,
    path = "/api/textures/{id}",
    params(TextureParam, HintQuery,
        Conditional),
    responses(
        (status = 200, description = "Texture. Shared by every level of the model, so its cache \
            rule follows the model's policy: `public, max-age=31536000, immutable` for a public \
            model, `private, …` when only a token shows it",
            content((inline(Binary) = "image/png"), (inline(Binary) = "image/jpeg")),
            headers(
                ("ETag" = String, description = "Strong ETag (SHA-256 of the payload)"),
                ("Cache-Control" = String))),
        (status = 304, description = "Not modified", headers(("ETag" = String), ("Cache-Control" = String))),
        (status = 400, description = "Malformed id, query or `Authorization`", body = ErrorBody),
        (status = 401, description = "The token is unknown, revoked or expired", body = ErrorBody),
        (status = 404, description = "No such texture, or a restricted model's without a token for it",
            body = ErrorBody),
        (status = 503, description = "Database unavailable or server overloaded", body = ErrorBody,
            headers(("Retry-After" = u64, description = "Seconds to wait before asking again"))),
    )
)]
pub async fn texture(
    State(state): State<AppState>,
    PathParams(TextureParam { id }): PathParams<TextureParam>,
    hints: VisitorHints,
    headers: HeaderMap,
) -> Result<Response, AppError> {
    let id = parse_id(&id, "texture id")?;
    let storage = state.storage();
    let load = async {
        let entry = storage.texture(id).await?.map(|t| {
            Arc::new(TextureEntry {
                bytes: t.bytes.into(),
                media_type: t.media_type,
                sha256: t.sha256,
                model_slug: t.model_slug,
                public_access: t.public_access,
            })
        });
        Ok(Payload::Texture(entry))
    };
    let key = PayloadKey::Texture(id);
    let Payload::Texture(entry) = state.caches().payload(state.metrics(), key, load).await? else {
        return Err(AppError::Internal(
            "payload cache returned a mesh for a texture key".into(),
        ));
    };
    let entry = entry.ok_or(AppError::NotFound("texture"))?;
    let visitor = state.visitor(&hints, &entry.model_slug).await?;
    if !entry.public_access && visitor.audience == Audience::Public {
        return Err(AppError::NotFound("texture"));
    }
    let etag = etag(&entry.sha256);
    let cache_control = if entry.public_access {
        PUBLIC_IMMUTABLE
    } else {
        PRIVATE_IMMUTABLE
    };
    if not_modified(&headers, &etag) {
        return Ok(not_modified_response(etag, cache_control));
    }
    let content_type = HeaderValue::from_str(&entry.media_type)
        .unwrap_or_else(|_| HeaderValue::from_static(OCTET_STREAM));
    Ok(payload_response(
        entry.bytes.clone(),
        etag,
        cache_control,
        content_type,
    ))
}

/// Ids are positive decimal integers; anything else is a client error.
pub(super) fn parse_id(text: &str, what: &str) -> Result<i64, AppError> {
    let valid = !text.is_empty() && text.len() <= 18 && text.bytes().all(|b| b.is_ascii_digit());
    match text.parse::<i64>() {
        Ok(v) if valid && v > 0 => Ok(v),
        Ok(_) if valid => Err(AppError::NotFound("id")),
        _ => Err(AppError::BadRequest(format!(
            "{what} must be a positive integer, not {text:?}"
        ))),
    }
}

fn missing(id: i64, level: u32) -> StorageError {
    StorageError::Corrupt(format!(
        "compression {id} lists level {level} but its payload is missing"
    ))
}

/// Public levels may sit in shared caches; levels above the public cap only
/// in the token holder's browser.
pub(super) fn cache_control(record: &ModelRecord, level: u32) -> &'static str {
    if record.policy.public_access && level <= audience_cap(record, Audience::Public) {
        PUBLIC_IMMUTABLE
    } else {
        PRIVATE_IMMUTABLE
    }
}

pub(super) fn etag(sha256: &str) -> HeaderValue {
    // `get`, not indexing: a corrupt row is no reason to panic.
    let short = sha256.get(..32).unwrap_or(sha256);
    HeaderValue::from_str(&format!("\"{short}\""))
        .unwrap_or_else(|_| HeaderValue::from_static("\"invalid\""))
}

/// RFC 9110 §13.1.2: `If-None-Match` uses the weak comparison.
pub(super) fn not_modified(headers: &HeaderMap, etag: &HeaderValue) -> bool {
    let ours = etag.as_bytes();
    headers
        .get_all(header::IF_NONE_MATCH)
        .iter()
        .filter_map(|v| v.to_str().ok())
        .any(|list| {
            list.split(',')
                .map(str::trim)
                .any(|tag| tag == "*" || tag.strip_prefix("W/").unwrap_or(tag).as_bytes() == ours)
        })
}

pub(super) fn not_modified_response(etag: HeaderValue, cache_control: &'static str) -> Response {
    let headers = [
        (header::ETAG, etag),
        (
            header::CACHE_CONTROL,
            HeaderValue::from_static(cache_control),
        ),
    ];
    (StatusCode::NOT_MODIFIED, headers).into_response()
}

pub(super) fn payload_response(
    bytes: Bytes,
    etag: HeaderValue,
    cache_control: &'static str,
    content_type: HeaderValue,
) -> Response {
    let headers = [
        (header::CONTENT_TYPE, content_type),
        (header::ETAG, etag),
        (
            header::CACHE_CONTROL,
            HeaderValue::from_static(cache_control),
        ),
    ];
    (headers, bytes).into_response()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ids() {
        assert_eq!(parse_id("42", "id").unwrap(), 42);
        assert!(matches!(parse_id("0", "id"), Err(AppError::NotFound(_))));
        for bad in ["", "-1", "+1", "abc", "1.5", "99999999999999999999", " 1"] {
            assert!(
                matches!(parse_id(bad, "id"), Err(AppError::BadRequest(_))),
                "{bad:?}"
            );
        }
    }

    #[test]
    fn if_none_match_lists_and_weak_tags() {
        let ours = etag("0123456789abcdef0123456789abcdef0123");
        let mut h = HeaderMap::new();
        assert!(!not_modified(&h, &ours));
        h.insert(
            header::IF_NONE_MATCH,
            HeaderValue::from_static("\"x\", W/\"0123456789abcdef0123456789abcdef\""),
        );
        assert!(not_modified(&h, &ours));
        h.insert(header::IF_NONE_MATCH, HeaderValue::from_static("\"0123\""));
        assert!(!not_modified(&h, &ours));
        h.insert(header::IF_NONE_MATCH, HeaderValue::from_static("*"));
        assert!(not_modified(&h, &ours));
    }
}
