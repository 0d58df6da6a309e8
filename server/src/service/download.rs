//! `GET /api/models/{slug}/download.glb?level=K` (issue 19): a level the
//! visitor may reach, as one GLB, where the model's policy allows downloads,
//! for `<model-viewer>`, AR viewers and social platforms. It is the level's
//! decoded mesh (the stream's quantized positions, vertex colour when the
//! stream has it), never the original file.
//!
//! The file stands as the model does in the viewer and at its real size:
//! its node turns the recorded up axis to glTF's +Y and scales the recorded
//! unit to metres (AR viewers place it at that size). It names the model
//! and carries the version's credit and licence (`asset.copyright`, and a
//! Dublin Core `KHR_xmp_json_ld` packet with the licence's deed and the
//! model page), so a scan that leaves the site keeps its credit.

use super::cap::{audience_cap, device_cap, good_enough_level, Audience, CapRules, DeviceClass};
use super::error::{AppError, ErrorBody, LevelCappedBody};
use super::payload::{cache_control, level_bytes, not_modified, not_modified_response, within_cap};
use super::scene::SceneFrame;
use super::servable::{ServableModel, SlugParam};
use super::visitor::HintQuery;
use super::web::{page_url, public_base};
use super::AppState;
use crate::storage::{ModelKind, ModelRecord};
use axum::extract::{RawQuery, State};
use axum::http::{header, HeaderMap, HeaderValue};
use axum::response::{IntoResponse, Response};
use bytes::Bytes;
use serde::Deserialize;
use serde_json::json;
use sha2::{Digest, Sha256};
use utoipa::IntoParams;
use vitrine_codec::{Decoder, Limits};
use vitrine_mesh::export::GlbDocument;

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
    let doc = document(&record, &public_base(&state, &headers));
    // The level's payload digest names the whole prefix within its
    // compression; what the document says (rights can change) has its own.
    let sha = &record.levels[level as usize].sha256;
    let etag = HeaderValue::from_str(&format!(
        "\"glb-{}-{level}-{}-{}\"",
        record.compression_id,
        &sha[..sha.len().min(24)],
        document_digest(&doc)
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
    let glb = tokio::task::spawn_blocking(move || glb_of(&payloads, &doc))
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

/// What the GLB says beside the mesh: see the module's comment.
fn document(record: &ModelRecord, base: &str) -> GlbDocument {
    let curation = &record.curation;
    let frame = SceneFrame::of(curation);
    let rights = &curation.rights;
    let alt = |text: &str| json!({ "@type": "rdf:Alt", "rdf:_1": { "@language": "x-default", "@value": text } });
    let mut xmp = json!({
        "@context": {
            "dc": "http://purl.org/dc/elements/1.1/",
            "rdf": "http://www.w3.org/1999/02/22-rdf-syntax-ns#",
            "xmpRights": "http://ns.adobe.com/xap/1.0/rights/",
        },
        "dc:title": alt(&record.title),
        "dc:format": "model/gltf-binary",
        "dc:source": page_url(base, &record.slug),
    });
    if !record.description.trim().is_empty() {
        xmp["dc:description"] = alt(record.description.trim());
    }
    let notice = rights.notice();
    if let Some(notice) = &notice {
        xmp["dc:rights"] = alt(notice);
    }
    if let Some(licence) = rights.licence {
        xmp["xmpRights:WebStatement"] = licence.url.into();
    }
    GlbDocument {
        copyright: notice,
        name: Some(record.title.clone()),
        // Y up in metres (or in no stated unit) needs no node transform.
        matrix: (!frame.is_identity()).then(|| frame.matrix()),
        xmp: Some(xmp),
    }
}

/// A short digest of everything [`document`] wrote, for the ETag.
fn document_digest(doc: &GlbDocument) -> String {
    let said = json!([doc.copyright, doc.name, doc.matrix, doc.xmp]).to_string();
    let digest = Sha256::digest(said.as_bytes());
    digest[..6].iter().map(|b| format!("{b:02x}")).collect()
}

/// Decodes the base and batches as the viewer does and writes the mesh.
fn glb_of(payloads: &[Bytes], doc: &GlbDocument) -> Result<Vec<u8>, AppError> {
    let stored = |e: vitrine_codec::Error| AppError::Internal(format!("stored level: {e}"));
    let (base, batches) = payloads
        .split_first()
        .ok_or_else(|| AppError::Internal("no base mesh".into()))?;
    let mut decoder = Decoder::new(base, Limits::default()).map_err(stored)?;
    for batch in batches {
        decoder.apply_batch(batch).map_err(stored)?;
    }
    let mut out = Vec::new();
    vitrine_mesh::export::write_glb_document(&decoder.to_mesh(), doc, &mut out)
        .map_err(|e| AppError::Internal(format!("writing GLB: {e}")))?;
    Ok(out)
}

/// `download.glb` of level `level`.
pub fn url(slug: &str, level: u32) -> String {
    format!("/api/models/{slug}/download.glb?level={level}")
}

/// The level every anonymous visitor may download, on any device and at
/// any load: within the public audience's cap, the phone's vertex budget and
/// the good-enough level (which load caps never go below), so a link that
/// names it (a IIIF manifest's Model) is never refused for the level and
/// never names a level kept for researchers. `None` when the model offers
/// no download to the public: its policy allows none, it is not public, or
/// it is a point cloud.
pub fn anonymous_level(record: &ModelRecord, rules: &CapRules) -> Option<u32> {
    if record.kind == ModelKind::Points || !record.policy.downloads || !record.policy.public_access
    {
        return None;
    }
    let level = audience_cap(record, Audience::Public)
        .min(device_cap(record, DeviceClass::Phone, rules))
        .min(good_enough_level(record, rules));
    Some(level)
}
