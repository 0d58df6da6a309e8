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
use super::error::AppError;
use super::visitor::VisitorHints;
use super::AppState;
use crate::storage::{ModelRecord, StorageError};
use axum::extract::{Path, State};
use axum::http::{header, HeaderMap, HeaderValue, StatusCode};
use axum::response::{IntoResponse, Response};
use bytes::Bytes;
use std::sync::Arc;

const OCTET_STREAM: &str = "application/octet-stream";
const PUBLIC_IMMUTABLE: &str = "public, max-age=31536000, immutable";
/// Levels only a token unlocks: browsers may keep them, shared caches may not.
const PRIVATE_IMMUTABLE: &str = "private, max-age=31536000, immutable";

pub async fn base(
    State(state): State<AppState>,
    Path(id): Path<String>,
    hints: VisitorHints,
    headers: HeaderMap,
) -> Result<Response, AppError> {
    let id = parse_id(&id, "compression id")?;
    let record = state.record_by_compression(id).await?;
    let visitor = state.visitor(&hints, &record.slug).await?;
    state.ensure_servable(&record, &visitor)?;
    let etag = etag(&record.levels[0].sha256);
    let cache_control = cache_control(&record, 0);
    if not_modified(&headers, &etag) {
        return Ok(not_modified_response(etag, cache_control));
    }
    let storage = state.storage();
    let load = async {
        let bytes = storage.base_payload(id).await?;
        bytes
            .map(|b| Payload::Mesh(b.into()))
            .ok_or_else(|| missing(id, 0))
    };
    let Payload::Mesh(bytes) = state
        .caches()
        .payload(state.metrics(), PayloadKey::Base(id), load)
        .await?
    else {
        return Err(AppError::Internal(
            "payload cache returned a texture for a mesh key".into(),
        ));
    };
    Ok(payload_response(
        bytes,
        etag,
        cache_control,
        HeaderValue::from_static(OCTET_STREAM),
    ))
}

pub async fn batch(
    State(state): State<AppState>,
    Path((id, iteration)): Path<(String, String)>,
    hints: VisitorHints,
    headers: HeaderMap,
) -> Result<Response, AppError> {
    let id = parse_id(&id, "compression id")?;
    let iteration: u32 = parse_id(&iteration, "iteration")?
        .try_into()
        .map_err(|_| AppError::NotFound("batch"))?;
    let record = state.record_by_compression(id).await?;
    let visitor = state.visitor(&hints, &record.slug).await?;
    state.ensure_servable(&record, &visitor)?;
    if iteration == 0 || iteration > record.batch_count() {
        return Err(AppError::NotFound("batch"));
    }
    let cap = state.level_cap(&record, &visitor);
    if iteration > cap.level {
        let reason = match cap.reason {
            Some(CapReason::Audience) => "audience",
            Some(CapReason::Device) => "device",
            _ => "load",
        };
        state.metrics().capped(reason);
        let retry_after = state.load().config().retry_after;
        return Err(AppError::LevelCapped {
            requested: iteration,
            cap,
            retry_after,
        });
    }
    let etag = etag(&record.levels[iteration as usize].sha256);
    let cache_control = cache_control(&record, iteration);
    if not_modified(&headers, &etag) {
        return Ok(not_modified_response(etag, cache_control));
    }
    let storage = state.storage();
    let load = async {
        let bytes = storage.batch_payload(id, iteration).await?;
        bytes
            .map(|b| Payload::Mesh(b.into()))
            .ok_or_else(|| missing(id, iteration))
    };
    let key = PayloadKey::Batch(id, iteration);
    let Payload::Mesh(bytes) = state.caches().payload(state.metrics(), key, load).await? else {
        return Err(AppError::Internal(
            "payload cache returned a texture for a mesh key".into(),
        ));
    };
    Ok(payload_response(
        bytes,
        etag,
        cache_control,
        HeaderValue::from_static(OCTET_STREAM),
    ))
}

pub async fn texture(
    State(state): State<AppState>,
    Path(id): Path<String>,
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
    let Payload::Texture(entry) = state
        .caches()
        .payload(state.metrics(), PayloadKey::Texture(id), load)
        .await?
    else {
        return Err(AppError::Internal(
            "payload cache returned a mesh for a texture key".into(),
        ));
    };
    let entry = entry.ok_or(AppError::NotFound("texture"))?;
    let visitor = state.visitor(&hints, &entry.model_slug).await?;
    if !entry.public_access && visitor.audience != Audience::Researcher {
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
fn parse_id(text: &str, what: &str) -> Result<i64, AppError> {
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
fn cache_control(record: &ModelRecord, level: u32) -> &'static str {
    if record.policy.public_access && level <= audience_cap(record, Audience::Public) {
        PUBLIC_IMMUTABLE
    } else {
        PRIVATE_IMMUTABLE
    }
}

fn etag(sha256: &str) -> HeaderValue {
    let short = &sha256[..sha256.len().min(32)];
    HeaderValue::from_str(&format!("\"{short}\""))
        .unwrap_or_else(|_| HeaderValue::from_static("\"invalid\""))
}

/// RFC 9110 §13.1.2: `If-None-Match` uses the weak comparison.
fn not_modified(headers: &HeaderMap, etag: &HeaderValue) -> bool {
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

fn not_modified_response(etag: HeaderValue, cache_control: &'static str) -> Response {
    let headers = [
        (header::ETAG, etag),
        (
            header::CACHE_CONTROL,
            HeaderValue::from_static(cache_control),
        ),
    ];
    (StatusCode::NOT_MODIFIED, headers).into_response()
}

fn payload_response(
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
