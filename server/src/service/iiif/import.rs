//! `POST /api/admin/models/{slug}/annotations/import` (curator token): a
//! IIIF AnnotationPage, or a JSON array of Web Annotations, added to the
//! model's annotations, all of them in one transaction or none.
//!
//! Each must be a commenting annotation whose target is a `PointSelector`
//! on this model's Scene (the shape `/iiif/{slug}/annotations` exports);
//! the point, in Scene coordinates (+Y up, metres), is turned into model
//! coordinates through the current version's up axis and unit. Annotations
//! belong to the slug, not to one version (`curator/annotations.rs`), so an
//! import serves every version. Their `id`s are not kept: each gets a new
//! one. What a Web Annotation cannot say is filled in: the normal points
//! away from the centre of the model's bounds (the up axis without them),
//! and there is no saved view.
//!
//! Limits: a body of at most [`MAX_IMPORT_BYTES`] (413 `payload_too_large`
//! before it is read), at most [`MAX_IMPORT_ITEMS`] annotations (413 with
//! the count), each within the limits of the annotation API (title, text,
//! language). Not JSON: 400. Anything malformed: 422 naming each refused
//! item (its index and `id`) and why, and nothing is stored.

use super::web_annotation::{items_of, read};
use crate::service::curator::annotations::{AnnotationInput, SlugPath};
use crate::service::curator::Curator;
use crate::service::error::{AppError, ErrorBody};
use crate::service::scene::SceneFrame;
use crate::service::servable::{PathParams, SlugParam};
use crate::service::AppState;
use crate::storage::{valid_slug, ModelRecord, NewAnnotation, UpAxis};
use axum::body::Body;
use axum::extract::State;
use axum::http::StatusCode;
use axum::response::{IntoResponse, Response};
use axum::Json;
use serde::Serialize;
use serde_json::Value;
use utoipa::ToSchema;

/// The route, as the guard's body limit names it.
pub const PATH: &str = "/api/admin/models/{slug}/annotations/import";
/// Largest body an import takes: 4 MiB (thousands of annotations with
/// pages of text; the other routes take 64 KiB).
pub const MAX_IMPORT_BYTES: usize = 4 << 20;
/// Most annotations one import adds.
pub const MAX_IMPORT_ITEMS: usize = 5_000;
/// Refused items named in one answer; the count says how many in all.
const REASONS_SHOWN: usize = 20;

#[derive(Serialize, ToSchema)]
pub struct ImportReport {
    /// Annotations added.
    imported: usize,
}

/// Imports a IIIF AnnotationPage or a list of Web Annotations (curator
/// token); all or nothing.
#[utoipa::path(
    post,
    path = "/api/admin/models/{slug}/annotations/import",
    params(SlugParam),
    request_body(content = Object, content_type = "application/json",
        description = "A IIIF AnnotationPage (`type`, `items`) or a JSON array of Web \
            Annotations: each `motivation` commenting, `label` a language map (the title), one \
            TextualBody (`value`, `format` text/markdown or text/plain, `language`), `target` a \
            SpecificResource on `…/iiif/{slug}/scene` with a PointSelector (x, y, z: +Y up, \
            metres). At most 4 MiB and 5,000 annotations."),
    security(("bearer" = [])),
    responses(
        (status = 201, description = "Every annotation added", body = ImportReport),
        (status = 400, description = "Malformed slug, `Authorization`, or a body that is not JSON", body = ErrorBody),
        (status = 401, description = "No token, or an unknown one", body = ErrorBody),
        (status = 403, description = "Not a curator token, or one for another model", body = ErrorBody),
        (status = 404, description = "No such model", body = ErrorBody),
        (status = 413, description = "Over 4 MiB, or over 5,000 annotations (`payload_too_large`)", body = ErrorBody),
        (status = 422, description = "Not an AnnotationPage or list, or malformed annotations: \
            the message names each (index and id) and what is wrong; none was added", body = ErrorBody),
    )
)]
pub async fn import(
    State(state): State<AppState>,
    curator: Curator,
    PathParams(SlugPath { slug }): PathParams<SlugPath>,
    body: Body,
) -> Result<Response, AppError> {
    curator.check_model(&slug)?;
    if !valid_slug(&slug) {
        return Err(AppError::BadRequest(format!(
            "{slug:?} is not a model slug"
        )));
    }
    // Curators import into restricted models too.
    let record = state.record_by_slug(&slug).await?;
    let bytes = axum::body::to_bytes(body, MAX_IMPORT_BYTES)
        .await
        .map_err(|_| AppError::PayloadTooLarge)?;
    let document: Value = serde_json::from_slice(&bytes)
        .map_err(|e| AppError::BadRequest(format!("the body is not JSON: {e}")))?;
    let items = items_of(&document).map_err(AppError::Unprocessable)?;
    if items.len() > MAX_IMPORT_ITEMS {
        return Err(AppError::OverLimit(format!(
            "{} annotations: an import takes at most {MAX_IMPORT_ITEMS}",
            items.len()
        )));
    }
    let annotations = annotations_of(items, &record)?;
    let imported = state
        .storage()
        .insert_annotations(&slug, &annotations)
        .await?;
    Ok((StatusCode::CREATED, Json(ImportReport { imported })).into_response())
}

/// Every item checked; the refusals, if any, all named.
fn annotations_of(items: &[Value], record: &ModelRecord) -> Result<Vec<NewAnnotation>, AppError> {
    let frame = SceneFrame::of(&record.curation);
    let mut accepted = Vec::with_capacity(items.len());
    let mut refused = Vec::new();
    for (index, item) in items.iter().enumerate() {
        let checked = read(item, &record.slug).and_then(|a| {
            let position = frame.to_model(a.point);
            AnnotationInput::new(
                a.title,
                a.text,
                position,
                outward(record, position),
                a.language,
            )
            .with_translations(a.translations)
            .checked()
        });
        match checked {
            Ok(annotation) => accepted.push(annotation),
            Err(reason) => refused.push(match item.get("id").and_then(Value::as_str) {
                Some(id) => format!("items[{index}] ({id}): {reason}"),
                None => format!("items[{index}]: {reason}"),
            }),
        }
    }
    if refused.is_empty() {
        return Ok(accepted);
    }
    let more = refused.len().saturating_sub(REASONS_SHOWN);
    let mut message = format!(
        "{} of {} annotations refused, nothing imported: {}",
        refused.len(),
        items.len(),
        refused[..refused.len().min(REASONS_SHOWN)].join("; ")
    );
    if more > 0 {
        message.push_str(&format!("; and {more} more"));
    }
    Err(AppError::Unprocessable(message))
}

/// A normal for a point that came without one: away from the centre of the
/// model's bounds, or the up axis when the point is that centre or the
/// version recorded no bounds (model coordinates).
fn outward(record: &ModelRecord, p: [f64; 3]) -> [f64; 3] {
    let up = record
        .curation
        .up_axis
        .unwrap_or(UpAxis::Y)
        .vector()
        .map(f64::from);
    let Some(bounds) = record.curation.bounds else {
        return up;
    };
    let d: [f64; 3] = [0, 1, 2].map(|i| p[i] - (bounds.min[i] + bounds.max[i]) / 2.0);
    let length = d.iter().map(|v| v * v).sum::<f64>().sqrt();
    if length > 1e-9 * bounds.diagonal().max(1e-300) && length.is_finite() {
        d
    } else {
        up
    }
}
