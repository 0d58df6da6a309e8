//! `GET /api/models/{slug}/download.glb?level=K` (issue 19): a level the
//! visitor may reach, as one GLB, where the model's policy allows downloads,
//! for `<model-viewer>`, AR viewers and social platforms. It is the level's
//! decoded mesh (the stream's quantized positions, vertex colour when the
//! stream has it), never the original file.

use super::error::{AppError, ErrorBody, LevelCappedBody};
use super::payload::{cache_control, level_bytes, not_modified, not_modified_response, within_cap};
use super::servable::{ServableModel, SlugParam};
use super::visitor::HintQuery;
use super::AppState;
use crate::storage::ModelKind;
use axum::extract::{RawQuery, State};
use axum::http::{header, HeaderMap, HeaderValue};
use axum::response::{IntoResponse, Response};
use bytes::Bytes;
use serde::Deserialize;
use utoipa::IntoParams;
use vitrine_codec::{Decoder, Limits};

/// Downloads decoded at once; more wait for 503 and `Retry-After` (a level
/// of a 2 M-vertex scan takes about a second of one core).
pub const MAX_CONCURRENT_DOWNLOADS: usize = 2;

#[derive(Deserialize, IntoParams)]
#[into_params(parameter_in = Query)]
pub struct DownloadQuery {
    /// Level to download (default: the visitor's cap).
    level: Option<u32>,
}

/// One level as a binary glTF file.
#[utoipa::path(
    get,
    path = "/api/models/{slug}/download.glb",
    params(SlugParam, DownloadQuery, HintQuery),
    responses(
        (status = 200, description = "The level as GLB (`Content-Disposition: attachment`)",
            content((inline(super::payload::Binary) = "model/gltf-binary")),
            headers(("ETag" = String), ("Cache-Control" = String), ("Content-Disposition" = String))),
        (status = 304, description = "Not modified", headers(("ETag" = String), ("Cache-Control" = String))),
        (status = 400, description = "Malformed slug, level, query or `Authorization`", body = ErrorBody),
        (status = 401, description = "The token is unknown, revoked or expired", body = ErrorBody),
        (status = 403, description = "The policy allows no downloads (`not_allowed`), or the level \
            is above the audience or device cap (`level_capped`)", body = ErrorBody),
        (status = 404, description = "No such model or level", body = ErrorBody),
        (status = 409, description = "Stored in a stream format this build cannot decode, or a \
            point cloud (`conflict`: only meshes are downloaded as GLB)", body = ErrorBody),
        (status = 429, description = "Above the cap set by server load", body = LevelCappedBody,
            headers(("Retry-After" = u64, description = "Seconds to wait before asking again"))),
        (status = 503, description = "Database unavailable, or downloads busy", body = ErrorBody,
            headers(("Retry-After" = u64, description = "Seconds to wait before asking again"))),
    )
)]
pub async fn download(
    State(state): State<AppState>,
    ServableModel { record, visitor }: ServableModel,
    RawQuery(query): RawQuery,
    headers: HeaderMap,
) -> Result<Response, AppError> {
    let query: DownloadQuery = serde_urlencoded::from_str(query.as_deref().unwrap_or(""))
        .map_err(|e| AppError::BadRequest(format!("query: {e}")))?;
    if record.kind == ModelKind::Points {
        return Err(AppError::Conflict(format!(
            "model {:?} is a point cloud: GLB downloads are of meshes only (fetch its levels from the manifest)",
            record.slug
        )));
    }
    if !record.policy.downloads {
        return Err(AppError::NotAllowed(format!(
            "model {:?} cannot be downloaded: its policy ({}) allows no downloads",
            record.slug, record.policy.name
        )));
    }
    let level = query
        .level
        .unwrap_or_else(|| state.level_cap(&record, &visitor).level);
    if level > record.batch_count() {
        return Err(AppError::NotFound("level"));
    }
    if level > 0 {
        within_cap(&state, &record, &visitor, level)?;
    }
    // The level's payload digest names the whole prefix within its compression.
    let sha = &record.levels[level as usize].sha256;
    let etag = HeaderValue::from_str(&format!(
        "\"glb-{}-{level}-{}\"",
        record.compression_id,
        &sha[..sha.len().min(24)]
    ))
    .map_err(|e| AppError::Internal(e.to_string()))?;
    // Named by slug, not by compression: never immutable (cache_headers).
    let cache_control = super::cache_headers::download(
        visitor.grant.is_some() || visitor.study_model.is_some(),
        query.level.is_some(),
        cache_control(&record, level).starts_with("public"),
    );
    if not_modified(&headers, &etag) {
        return Ok(not_modified_response(etag, cache_control));
    }
    let Ok(_permit) = state.downloads().clone().try_acquire_owned() else {
        return Err(AppError::Overloaded {
            retry_after: state.config().limits.shed_retry_after,
        });
    };
    let mut payloads = Vec::with_capacity(level as usize + 1);
    for k in 0..=level {
        payloads.push(level_bytes(&state, &record, k).await?);
    }
    let glb = tokio::task::spawn_blocking(move || glb_of(&payloads))
        .await
        .map_err(|e| AppError::Internal(format!("download task: {e}")))??;
    let disposition = format!("attachment; filename=\"{}-level-{level}.glb\"", record.slug);
    let headers = [
        (
            header::CONTENT_TYPE,
            HeaderValue::from_static("model/gltf-binary"),
        ),
        (header::ETAG, etag),
        (
            header::CACHE_CONTROL,
            HeaderValue::from_static(cache_control),
        ),
        (
            header::CONTENT_DISPOSITION,
            HeaderValue::from_str(&disposition).map_err(|e| AppError::Internal(e.to_string()))?,
        ),
    ];
    Ok((headers, Bytes::from(glb)).into_response())
}

/// Decodes the base and batches as the viewer does and writes the mesh.
fn glb_of(payloads: &[Bytes]) -> Result<Vec<u8>, AppError> {
    let stored = |e: vitrine_codec::Error| AppError::Internal(format!("stored level: {e}"));
    let (base, batches) = payloads
        .split_first()
        .ok_or_else(|| AppError::Internal("no base mesh".into()))?;
    let mut decoder = Decoder::new(base, Limits::default()).map_err(stored)?;
    for batch in batches {
        decoder.apply_batch(batch).map_err(stored)?;
    }
    let mut out = Vec::new();
    vitrine_mesh::export::write_glb(&decoder.to_mesh(), &mut out)
        .map_err(|e| AppError::Internal(format!("writing GLB: {e}")))?;
    Ok(out)
}
