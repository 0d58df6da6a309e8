//! `/api/models/{slug}/annotations`: curator-authored hotspots, a point and
//! a normal in model coordinates with a title, Markdown text (served also as
//! sanitised HTML) and an optional saved view. Anyone who may see the model
//! reads them; writing needs a curator token. They belong to the slug, not
//! to one version, since they are in model coordinates.

use super::markdown;
use super::Curator;
use crate::service::error::{AppError, ErrorBody};
use crate::service::servable::{PathParams, ServableModel, SlugParam};
use crate::service::AppState;
use crate::storage::{valid_slug, AnnotationRecord, NewAnnotation};
use axum::extract::rejection::JsonRejection;
use axum::extract::State;
use axum::http::StatusCode;
use axum::response::{IntoResponse, Response};
use axum::Json;
use serde::{Deserialize, Serialize};
use utoipa::{IntoParams, ToSchema};

/// Longest title, in characters.
pub const MAX_TITLE_CHARS: usize = 200;
/// Longest text (Markdown source), in characters.
pub const MAX_TEXT_CHARS: usize = 10_000;
/// Largest saved view, serialised.
pub const MAX_VIEW_BYTES: usize = 4_096;

/// An annotation as served.
#[derive(Serialize, ToSchema)]
pub struct Annotation {
    id: i64,
    title: String,
    /// Markdown source.
    text: String,
    /// `text` rendered and sanitised (no raw HTML, scripts or `javascript:` URLs).
    html: String,
    /// Model coordinates (those of the decoded stream).
    position: [f64; 3],
    /// Unit length, model coordinates.
    normal: [f64; 3],
    /// The saved camera, as the viewer sent it.
    #[schema(value_type = Option<Object>)]
    view: Option<serde_json::Value>,
    /// Unix milliseconds.
    created_at: i64,
    updated_at: i64,
}

impl From<AnnotationRecord> for Annotation {
    fn from(a: AnnotationRecord) -> Self {
        Annotation {
            id: a.id,
            title: a.title,
            text: a.text,
            html: a.html,
            position: a.position,
            normal: a.normal,
            view: a.view,
            created_at: a.created_at_ms,
            updated_at: a.updated_at_ms,
        }
    }
}

/// What a curator sends to create or replace an annotation.
#[derive(Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct AnnotationInput {
    /// 1–200 characters.
    title: String,
    /// Markdown, at most 10,000 characters.
    #[serde(default)]
    text: String,
    position: [f64; 3],
    /// Non-zero; stored normalised.
    normal: [f64; 3],
    /// A saved camera (a JSON object of at most 4 KiB), or null.
    #[serde(default)]
    #[schema(value_type = Option<Object>)]
    view: Option<serde_json::Value>,
}

impl AnnotationInput {
    /// Checks limits and numbers; renders the text.
    fn validate(self) -> Result<NewAnnotation, AppError> {
        let bad = |m: String| Err(AppError::Unprocessable(m));
        let title = self.title.trim().to_owned();
        if title.is_empty() {
            return bad("title must not be empty".into());
        }
        if title.chars().count() > MAX_TITLE_CHARS {
            return bad(format!("title is longer than {MAX_TITLE_CHARS} characters"));
        }
        if self.text.chars().count() > MAX_TEXT_CHARS {
            return bad(format!("text is longer than {MAX_TEXT_CHARS} characters"));
        }
        if !self
            .position
            .iter()
            .chain(&self.normal)
            .all(|v| v.is_finite())
        {
            return bad("position and normal must be finite numbers".into());
        }
        let length = self.normal.iter().map(|v| v * v).sum::<f64>().sqrt();
        if !(length > 1e-12 && length.is_finite()) {
            return bad("normal must not be zero".into());
        }
        let normal = self.normal.map(|v| v / length);
        let view = match self.view {
            None | Some(serde_json::Value::Null) => None,
            Some(v @ serde_json::Value::Object(_)) => {
                if v.to_string().len() > MAX_VIEW_BYTES {
                    return bad(format!("view is larger than {MAX_VIEW_BYTES} bytes"));
                }
                Some(v)
            }
            Some(_) => return bad("view must be an object or null".into()),
        };
        Ok(NewAnnotation {
            html: markdown::render(&self.text),
            title,
            text: self.text,
            position: self.position,
            normal,
            view,
        })
    }
}

/// `{slug}` and `{id}`.
#[derive(Deserialize, IntoParams)]
#[into_params(parameter_in = Path)]
pub struct AnnotationPath {
    slug: String,
    id: i64,
}

/// A JSON body, malformed ones answered 422 with serde's message.
fn body(input: Result<Json<AnnotationInput>, JsonRejection>) -> Result<NewAnnotation, AppError> {
    match input {
        Ok(Json(input)) => input.validate(),
        Err(e) => Err(AppError::Unprocessable(e.body_text())),
    }
}

/// The model must exist (any audience: curators annotate restricted models too).
async fn existing(state: &AppState, slug: &str) -> Result<(), AppError> {
    if !valid_slug(slug) {
        return Err(AppError::BadRequest(format!(
            "{slug:?} is not a model slug"
        )));
    }
    state.record_by_slug(slug).await.map(|_| ())
}

/// The model's annotations, oldest first.
#[utoipa::path(
    get,
    path = "/api/models/{slug}/annotations",
    params(SlugParam),
    responses(
        (status = 200, description = "Annotations", body = Vec<Annotation>),
        (status = 400, description = "Malformed slug or `Authorization`", body = ErrorBody),
        (status = 404, description = "No such model", body = ErrorBody),
        (status = 503, description = "Database unavailable or server overloaded", body = ErrorBody),
    )
)]
pub async fn list(
    State(state): State<AppState>,
    model: ServableModel,
) -> Result<Json<Vec<Annotation>>, AppError> {
    let rows = state.storage().annotations(&model.record.slug).await?;
    Ok(Json(rows.into_iter().map(Annotation::from).collect()))
}

/// Adds an annotation (curator token).
#[utoipa::path(
    post,
    path = "/api/models/{slug}/annotations",
    params(SlugParam),
    request_body = AnnotationInput,
    security(("bearer" = [])),
    responses(
        (status = 201, description = "Created", body = Annotation),
        (status = 400, description = "Malformed slug or `Authorization`", body = ErrorBody),
        (status = 401, description = "No token, or an unknown one", body = ErrorBody),
        (status = 403, description = "Not a curator token, or one for another model", body = ErrorBody),
        (status = 404, description = "No such model", body = ErrorBody),
        (status = 422, description = "Invalid annotation; the message says why", body = ErrorBody),
    )
)]
pub async fn create(
    State(state): State<AppState>,
    curator: Curator,
    PathParams(SlugPath { slug }): PathParams<SlugPath>,
    input: Result<Json<AnnotationInput>, JsonRejection>,
) -> Result<Response, AppError> {
    curator.check_model(&slug)?;
    existing(&state, &slug).await?;
    let new = body(input)?;
    let stored = state.storage().insert_annotation(&slug, &new).await?;
    Ok((StatusCode::CREATED, Json(Annotation::from(stored))).into_response())
}

/// Replaces an annotation (curator token).
#[utoipa::path(
    put,
    path = "/api/models/{slug}/annotations/{id}",
    params(AnnotationPath),
    request_body = AnnotationInput,
    security(("bearer" = [])),
    responses(
        (status = 200, description = "Replaced", body = Annotation),
        (status = 400, description = "Malformed path or `Authorization`", body = ErrorBody),
        (status = 401, description = "No token, or an unknown one", body = ErrorBody),
        (status = 403, description = "Not a curator token, or one for another model", body = ErrorBody),
        (status = 404, description = "No such model or annotation", body = ErrorBody),
        (status = 422, description = "Invalid annotation; the message says why", body = ErrorBody),
    )
)]
pub async fn update(
    State(state): State<AppState>,
    curator: Curator,
    PathParams(AnnotationPath { slug, id }): PathParams<AnnotationPath>,
    input: Result<Json<AnnotationInput>, JsonRejection>,
) -> Result<Json<Annotation>, AppError> {
    curator.check_model(&slug)?;
    existing(&state, &slug).await?;
    let new = body(input)?;
    let stored = state.storage().update_annotation(&slug, id, &new).await?;
    Ok(Json(stored.ok_or(AppError::NotFound("annotation"))?.into()))
}

/// Deletes an annotation (curator token).
#[utoipa::path(
    delete,
    path = "/api/models/{slug}/annotations/{id}",
    params(AnnotationPath),
    security(("bearer" = [])),
    responses(
        (status = 204, description = "Deleted"),
        (status = 400, description = "Malformed path or `Authorization`", body = ErrorBody),
        (status = 401, description = "No token, or an unknown one", body = ErrorBody),
        (status = 403, description = "Not a curator token, or one for another model", body = ErrorBody),
        (status = 404, description = "No such model or annotation", body = ErrorBody),
    )
)]
pub async fn delete(
    State(state): State<AppState>,
    curator: Curator,
    PathParams(AnnotationPath { slug, id }): PathParams<AnnotationPath>,
) -> Result<StatusCode, AppError> {
    curator.check_model(&slug)?;
    existing(&state, &slug).await?;
    if state.storage().delete_annotation(&slug, id).await? {
        Ok(StatusCode::NO_CONTENT)
    } else {
        Err(AppError::NotFound("annotation"))
    }
}

/// `{slug}` alone, readable here (`SlugParam` keeps its field private).
#[derive(Deserialize)]
pub struct SlugPath {
    pub slug: String,
}
