//! Guided tours (issue 44): `/api/models/{slug}/tours` for visitors (the
//! tours of the version they are served) and
//! `/api/admin/models/{slug}/tours[/{id}]` for curators (every version's;
//! create, replace — which is also how steps are reordered — and delete,
//! with a curator token like the rest of `/api/admin`). A tour belongs to
//! the model version it was recorded on: its views are cameras in that
//! version's coordinates, and a new version of the scan may move them.
//! The IIIF Manifest lists a version's tours as Ranges (`iiif/tours.rs`).

pub mod input;

use super::curator::annotations::SlugPath;
use super::curator::Curator;
use super::error::{AppError, ErrorBody};
use super::servable::{PathParams, ServableModel, SlugParam};
use super::AppState;
use crate::storage::{valid_slug, LanguageMap, NewTour, TourRecord, TourStep as StoredStep};
use axum::extract::rejection::JsonRejection;
use axum::extract::State;
use axum::http::StatusCode;
use axum::response::{IntoResponse, Response};
use axum::Json;
use input::TourInput;
use serde::{Deserialize, Serialize};
use utoipa::{IntoParams, ToSchema};

/// The collection route of a model's tours, for the guard's body limit.
pub const ADMIN_PATH: &str = "/api/admin/models/{slug}/tours";
/// One tour's route.
pub const ADMIN_ONE_PATH: &str = "/api/admin/models/{slug}/tours/{id}";

/// A tour as served.
#[derive(Serialize, ToSchema)]
pub struct Tour {
    id: i64,
    /// The model version the tour was recorded on.
    version: u32,
    /// Title per BCP 47 language tag.
    #[schema(value_type = Object)]
    title: LanguageMap,
    /// In the order they are played.
    steps: Vec<TourStep>,
    /// Unix milliseconds.
    created_at: i64,
    updated_at: i64,
}

/// A step as served.
#[derive(Serialize, ToSchema)]
pub struct TourStep {
    /// The share-link fragment of the view (`web/src/view-state.js`).
    view: String,
    #[schema(value_type = Object)]
    title: LanguageMap,
    /// Markdown source per language.
    #[schema(value_type = Object)]
    text: LanguageMap,
    /// `text` rendered and sanitised, per language.
    #[schema(value_type = Object)]
    html: LanguageMap,
}

impl From<StoredStep> for TourStep {
    fn from(s: StoredStep) -> Self {
        TourStep {
            view: s.view,
            title: s.title,
            text: s.text,
            html: s.html,
        }
    }
}

impl From<TourRecord> for Tour {
    fn from(t: TourRecord) -> Self {
        Tour {
            id: t.id,
            version: t.version,
            title: t.title,
            steps: t.steps.into_iter().map(TourStep::from).collect(),
            created_at: t.created_at_ms,
            updated_at: t.updated_at_ms,
        }
    }
}

/// `{slug}` and `{id}`.
#[derive(Deserialize, IntoParams)]
#[into_params(parameter_in = Path)]
pub struct TourPath {
    slug: String,
    id: i64,
}

/// The tours of the version this visitor is served, oldest first.
#[utoipa::path(
    get,
    path = "/api/models/{slug}/tours",
    params(SlugParam),
    responses(
        (status = 200, description = "Tours of the version served", body = Vec<Tour>),
        (status = 400, description = "Malformed slug or `Authorization`", body = ErrorBody),
        (status = 404, description = "No such model", body = ErrorBody),
        (status = 503, description = "Database unavailable or server overloaded", body = ErrorBody),
    )
)]
pub async fn list(
    State(state): State<AppState>,
    model: ServableModel,
) -> Result<Json<Vec<Tour>>, AppError> {
    let rows = state
        .storage()
        .tours(&model.record.slug, Some(model.record.version))
        .await?;
    Ok(Json(rows.into_iter().map(Tour::from).collect()))
}

/// Every tour of the model, of every version (curator token).
#[utoipa::path(
    get,
    path = "/api/admin/models/{slug}/tours",
    params(SlugParam),
    security(("bearer" = [])),
    responses(
        (status = 200, description = "Tours of every version, oldest first", body = Vec<Tour>),
        (status = 400, description = "Malformed slug or `Authorization`", body = ErrorBody),
        (status = 401, description = "No token, or an unknown one", body = ErrorBody),
        (status = 403, description = "Not a curator token, or one for another model", body = ErrorBody),
        (status = 404, description = "No such model", body = ErrorBody),
    )
)]
pub async fn all(
    State(state): State<AppState>,
    curator: Curator,
    PathParams(SlugPath { slug }): PathParams<SlugPath>,
) -> Result<Json<Vec<Tour>>, AppError> {
    curator.check_model(&slug)?;
    served_version(&state, &slug).await?;
    let rows = state.storage().tours(&slug, None).await?;
    Ok(Json(rows.into_iter().map(Tour::from).collect()))
}

/// Adds a tour (curator token).
#[utoipa::path(
    post,
    path = "/api/admin/models/{slug}/tours",
    params(SlugParam),
    request_body(content = TourInput, description = "At most 1 MiB; 1–50 steps; titles 1–200 \
        characters and texts at most 10,000 per language, at most 12 languages; each view at \
        most 2,048 bytes and with a camera"),
    security(("bearer" = [])),
    responses(
        (status = 201, description = "Created", body = Tour),
        (status = 400, description = "Malformed slug or `Authorization`", body = ErrorBody),
        (status = 401, description = "No token, or an unknown one", body = ErrorBody),
        (status = 403, description = "Not a curator token, or one for another model", body = ErrorBody),
        (status = 404, description = "No such model", body = ErrorBody),
        (status = 413, description = "Body over 1 MiB", body = ErrorBody),
        (status = 422, description = "Invalid tour; the message names the step and field", body = ErrorBody),
    )
)]
pub async fn create(
    State(state): State<AppState>,
    curator: Curator,
    PathParams(SlugPath { slug }): PathParams<SlugPath>,
    input: Result<Json<TourInput>, JsonRejection>,
) -> Result<Response, AppError> {
    curator.check_model(&slug)?;
    let new = body(&state, &slug, input).await?;
    let stored = state.storage().insert_tour(&slug, &new).await?;
    Ok((StatusCode::CREATED, Json(Tour::from(stored))).into_response())
}

/// Replaces a tour: title, steps in their new order, version (curator token).
#[utoipa::path(
    put,
    path = "/api/admin/models/{slug}/tours/{id}",
    params(TourPath),
    request_body(content = TourInput, description = "As for a new tour"),
    security(("bearer" = [])),
    responses(
        (status = 200, description = "Replaced", body = Tour),
        (status = 400, description = "Malformed path or `Authorization`", body = ErrorBody),
        (status = 401, description = "No token, or an unknown one", body = ErrorBody),
        (status = 403, description = "Not a curator token, or one for another model", body = ErrorBody),
        (status = 404, description = "No such model or tour", body = ErrorBody),
        (status = 413, description = "Body over 1 MiB", body = ErrorBody),
        (status = 422, description = "Invalid tour; the message names the step and field", body = ErrorBody),
    )
)]
pub async fn update(
    State(state): State<AppState>,
    curator: Curator,
    PathParams(TourPath { slug, id }): PathParams<TourPath>,
    input: Result<Json<TourInput>, JsonRejection>,
) -> Result<Json<Tour>, AppError> {
    curator.check_model(&slug)?;
    let new = body(&state, &slug, input).await?;
    let stored = state.storage().update_tour(&slug, id, &new).await?;
    Ok(Json(stored.ok_or(AppError::NotFound("tour"))?.into()))
}

/// Deletes a tour (curator token).
#[utoipa::path(
    delete,
    path = "/api/admin/models/{slug}/tours/{id}",
    params(TourPath),
    security(("bearer" = [])),
    responses(
        (status = 204, description = "Deleted"),
        (status = 400, description = "Malformed path or `Authorization`", body = ErrorBody),
        (status = 401, description = "No token, or an unknown one", body = ErrorBody),
        (status = 403, description = "Not a curator token, or one for another model", body = ErrorBody),
        (status = 404, description = "No such model or tour", body = ErrorBody),
    )
)]
pub async fn delete(
    State(state): State<AppState>,
    curator: Curator,
    PathParams(TourPath { slug, id }): PathParams<TourPath>,
) -> Result<StatusCode, AppError> {
    curator.check_model(&slug)?;
    served_version(&state, &slug).await?;
    if state.storage().delete_tour(&slug, id).await? {
        Ok(StatusCode::NO_CONTENT)
    } else {
        Err(AppError::NotFound("tour"))
    }
}

/// The version visitors are served (any audience: curators write tours of
/// restricted models too).
async fn served_version(state: &AppState, slug: &str) -> Result<u32, AppError> {
    if !valid_slug(slug) {
        return Err(AppError::BadRequest(format!(
            "{slug:?} is not a model slug"
        )));
    }
    Ok(state.record_by_slug(slug).await?.version)
}

/// A checked tour; a version named must be one of the model's.
async fn body(
    state: &AppState,
    slug: &str,
    input: Result<Json<TourInput>, JsonRejection>,
) -> Result<NewTour, AppError> {
    let served = served_version(state, slug).await?;
    let Json(input) = input.map_err(|e| AppError::Unprocessable(e.body_text()))?;
    let new = input.checked(served).map_err(AppError::Unprocessable)?;
    if new.version != served {
        let versions = state.storage().versions(slug).await?;
        if !versions.iter().any(|v| v.version == new.version) {
            return Err(AppError::Unprocessable(format!(
                "{slug:?} has no version {}",
                new.version
            )));
        }
    }
    Ok(new)
}
