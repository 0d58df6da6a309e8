//! What a request is about: its path parameters, and the model they name
//! once this visitor may be shown it (the one decision behind manifests,
//! model pages and payloads).

use super::cap::Audience;
use super::error::AppError;
use super::visitor::VisitorHints;
use super::{AppState, Visitor};
use crate::storage::{valid_slug, ModelRecord};
use axum::extract::{FromRequestParts, Path};
use axum::http::request::Parts;
use serde::de::DeserializeOwned;
use serde::Deserialize;
use std::sync::Arc;
use utoipa::IntoParams;

/// axum's `Path`, with a malformed path answered like any other bad request
/// (the JSON error body) rather than in plain text.
pub struct PathParams<T>(pub T);

impl<T, S> FromRequestParts<S> for PathParams<T>
where
    T: DeserializeOwned + Send,
    S: Send + Sync,
{
    type Rejection = AppError;

    async fn from_request_parts(parts: &mut Parts, state: &S) -> Result<Self, AppError> {
        match Path::<T>::from_request_parts(parts, state).await {
            Ok(Path(params)) => Ok(PathParams(params)),
            Err(e) => Err(AppError::BadRequest(e.body_text())),
        }
    }
}

/// The `{slug}` of a model route.
#[derive(Deserialize, IntoParams)]
#[into_params(parameter_in = Path)]
pub struct SlugParam {
    #[param(pattern = "^[a-z0-9]([a-z0-9-]{0,62}[a-z0-9])?$")]
    slug: String,
}

/// A model found by the `{slug}` of the route, that this visitor may see and
/// this build can decode.
pub struct ServableModel {
    pub record: Arc<ModelRecord>,
    pub visitor: Visitor,
}

impl FromRequestParts<AppState> for ServableModel {
    type Rejection = AppError;

    async fn from_request_parts(parts: &mut Parts, state: &AppState) -> Result<Self, AppError> {
        let PathParams(SlugParam { slug }) = PathParams::from_request_parts(parts, state).await?;
        let hints = VisitorHints::from_request_parts(parts, state).await?;
        if !valid_slug(&slug) {
            return Err(AppError::BadRequest(format!(
                "{slug:?} is not a model slug"
            )));
        }
        let record = state.record_by_slug(&slug).await?;
        ServableModel::decide(state, record, &hints).await
    }
}

impl ServableModel {
    /// Checks the visitor's token against `record`. Restricted models do not
    /// exist for visitors without a token for them; a visible model stored in
    /// a stream format this build cannot decode is refused with a message
    /// that says so (checked after visibility, so a restricted model's
    /// existence is not revealed).
    pub async fn decide(
        state: &AppState,
        record: Arc<ModelRecord>,
        hints: &VisitorHints,
    ) -> Result<ServableModel, AppError> {
        let mut visitor = state.visitor(hints, &record.slug).await?;
        if visitor.audience == Audience::Study && visitor.study_model != Some(record.model_id) {
            // The study was of an earlier version: its invitation opens nothing now.
            visitor.audience = Audience::Public;
        }
        if !(record.policy.public_access
            || matches!(visitor.audience, Audience::Researcher | Audience::Study))
        {
            return Err(AppError::NotFound("model"));
        }
        if !record.servable() {
            return Err(AppError::StaleFormat {
                slug: record.slug.clone(),
                stored: record.stream_format,
                reads: record.kind.reads(),
            });
        }
        Ok(ServableModel { record, visitor })
    }
}
