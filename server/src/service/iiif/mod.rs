//! IIIF (issue 44): each public model as a IIIF Presentation 4 Manifest
//! (`/iiif/{slug}/manifest`), every public model in a Collection
//! (`/iiif/collection`), the model's annotations as a Web Annotation page
//! (`/iiif/{slug}/annotations`), and an import of such a page for curators
//! (`import.rs`).
//!
//! Everything here is answered as an anonymous visitor sees it, whoever
//! asks: a restricted model does not exist (404, as an unknown one), the
//! Model painted is a level every visitor may download, and a token changes
//! nothing, so answers are shared by caches (`cache_headers.rs`) and any
//! site may read them (`Access-Control-Allow-Origin: *`, whatever
//! `--cors-origin` says: IIIF viewers and aggregators run on other sites).

mod ids;
pub mod import;
mod presentation;
mod tours;
mod values;
mod web_annotation;

use super::api::visible_models;
use super::cache_headers;
use super::curator::annotations::SlugPath;
use super::curator::thumbnail;
use super::download::anonymous_level;
use super::error::{AppError, ErrorBody};
use super::payload::not_modified;
use super::servable::{PathParams, ServableModel, SlugParam};
use super::visitor::VisitorHints;
use super::web::public_base;
use super::AppState;
use crate::storage::{valid_slug, ModelRecord};
use axum::extract::State;
use axum::http::{header, HeaderMap, HeaderValue, StatusCode};
use axum::response::{IntoResponse, Response};
use ids::Ids;
use serde_json::Value;
use sha2::{Digest, Sha256};
use std::sync::Arc;

/// A model's IIIF Presentation 4 Manifest.
#[utoipa::path(
    get,
    path = "/iiif/{slug}/manifest",
    params(SlugParam),
    responses(
        (status = 200, description = "IIIF Presentation 4 Manifest: a Scene painting the GLB of \
            the level every anonymous visitor may download (none when the policy offers no \
            download), the home camera and lights, the annotations as commenting Web \
            Annotations, the version's guided tours as Ranges in `structures`; \
            `Access-Control-Allow-Origin: *`, `Cache-Control: public, max-age=300`, \
            strong ETag", content_type = "application/ld+json", body = Object,
            headers(("ETag" = String), ("Cache-Control" = String))),
        (status = 304, description = "Not modified", headers(("ETag" = String), ("Cache-Control" = String))),
        (status = 400, description = "Malformed slug", body = ErrorBody),
        (status = 404, description = "No such model, or not a public one", body = ErrorBody),
        (status = 409, description = "Stored in a stream format this build cannot decode", body = ErrorBody),
        (status = 503, description = "Database unavailable or server overloaded", body = ErrorBody),
    )
)]
pub async fn manifest(
    State(state): State<AppState>,
    PathParams(SlugPath { slug }): PathParams<SlugPath>,
    headers: HeaderMap,
) -> Result<Response, AppError> {
    let record = public_model(&state, &slug).await?;
    let base = public_base(&state, &headers);
    let annotations = state.storage().annotations(&record.slug).await?;
    let tours = state
        .storage()
        .tours(&record.slug, Some(record.version))
        .await?;
    let document = presentation::manifest(&presentation::ManifestInput {
        ids: Ids {
            base: &base,
            slug: &record.slug,
        },
        record: &record,
        level: anonymous_level(&record, &state.config().caps),
        annotations: &annotations,
        tours: &tours,
        thumbnail: record
            .curation
            .thumbnail_sha256
            .is_some()
            .then(|| thumbnail::url(&record.slug, record.version)),
    });
    answer(&document, &headers)
}

/// A model's annotations as a IIIF AnnotationPage (the Manifest's
/// `annotations`, on its own).
#[utoipa::path(
    get,
    path = "/iiif/{slug}/annotations",
    params(SlugParam),
    responses(
        (status = 200, description = "AnnotationPage of commenting Web Annotations, each a \
            PointSelector on the Scene (+Y up, metres); CORS and caching as the Manifest",
            content_type = "application/ld+json", body = Object,
            headers(("ETag" = String), ("Cache-Control" = String))),
        (status = 304, description = "Not modified", headers(("ETag" = String), ("Cache-Control" = String))),
        (status = 400, description = "Malformed slug", body = ErrorBody),
        (status = 404, description = "No such model, or not a public one", body = ErrorBody),
        (status = 409, description = "Stored in a stream format this build cannot decode", body = ErrorBody),
        (status = 503, description = "Database unavailable or server overloaded", body = ErrorBody),
    )
)]
pub async fn annotations(
    State(state): State<AppState>,
    PathParams(SlugPath { slug }): PathParams<SlugPath>,
    headers: HeaderMap,
) -> Result<Response, AppError> {
    let record = public_model(&state, &slug).await?;
    let base = public_base(&state, &headers);
    let annotations = state.storage().annotations(&record.slug).await?;
    let ids = Ids {
        base: &base,
        slug: &record.slug,
    };
    let frame = super::scene::SceneFrame::of(&record.curation);
    let mut page = web_annotation::page(&ids, &frame, &annotations);
    page["@context"] = ids::CONTEXT.into();
    answer(&page, &headers)
}

/// Every public model's Manifest.
#[utoipa::path(
    get,
    path = "/iiif/collection",
    responses(
        (status = 200, description = "IIIF Presentation 4 Collection of every public model's \
            Manifest; CORS and caching as a Manifest", content_type = "application/ld+json", body = Object,
            headers(("ETag" = String), ("Cache-Control" = String))),
        (status = 304, description = "Not modified", headers(("ETag" = String), ("Cache-Control" = String))),
        (status = 503, description = "Database unavailable or server overloaded", body = ErrorBody),
    )
)]
pub async fn collection(
    State(state): State<AppState>,
    headers: HeaderMap,
) -> Result<Response, AppError> {
    let models = visible_models(&state, &VisitorHints::anonymous()).await?;
    let listed: Vec<presentation::Listed<'_>> = models
        .iter()
        .map(|m| presentation::Listed {
            slug: &m.slug,
            title: &m.title,
            thumbnail: m.has_thumbnail.then(|| thumbnail::url(&m.slug, m.version)),
        })
        .collect();
    let base = public_base(&state, &headers);
    let document = presentation::collection(&base, &state.config().site_name, &listed);
    answer(&document, &headers)
}

/// The model named by `slug` as a visitor without a token sees it: a
/// restricted model is as unknown as a missing one.
async fn public_model(state: &AppState, slug: &str) -> Result<Arc<ModelRecord>, AppError> {
    if !valid_slug(slug) {
        return Err(AppError::BadRequest(format!(
            "{slug:?} is not a model slug"
        )));
    }
    let record = state.record_by_slug(slug).await?;
    let model = ServableModel::decide(state, record, &VisitorHints::anonymous()).await?;
    Ok(model.record)
}

/// A IIIF document with its media type, a strong ETag of its bytes, the
/// shared cache rule and CORS for any origin; 304 when the client has it.
fn answer(document: &Value, request: &HeaderMap) -> Result<Response, AppError> {
    let bytes = serde_json::to_vec(document)
        .map_err(|e| AppError::Internal(format!("IIIF document: {e}")))?;
    let digest = Sha256::digest(&bytes);
    let etag = HeaderValue::from_str(&format!("\"iiif-{}\"", hex::encode(&digest[..16])))
        .map_err(|e| AppError::Internal(e.to_string()))?;
    let mut response = if not_modified(request, &etag) {
        StatusCode::NOT_MODIFIED.into_response()
    } else {
        (
            [(
                header::CONTENT_TYPE,
                HeaderValue::from_static(ids::MEDIA_TYPE),
            )],
            bytes,
        )
            .into_response()
    };
    let headers = response.headers_mut();
    headers.insert(header::ETAG, etag);
    headers.insert(
        header::ACCESS_CONTROL_ALLOW_ORIGIN,
        HeaderValue::from_static("*"),
    );
    cache_headers::anonymous(&mut response, cache_headers::ANONYMOUS);
    Ok(response)
}
