//! A model version's texts in other languages (issue 43), for curators:
//! `/api/admin/models/{slug}/versions/{version}/texts` reads and replaces
//! the language of the version's own title, description and credit and
//! every translation of them. Visitors get them through the manifest, the
//! gallery, the model page's head, oEmbed and IIIF, each picking the
//! visitor's language with a fallback to the version's own texts
//! ([`crate::storage::ModelTexts::pick`]).

pub mod input;

use super::curator::admin::AdminVersion;
use super::curator::Curator;
use super::error::{AppError, ErrorBody};
use super::servable::PathParams;
use super::AppState;
use crate::storage::{valid_slug, Translations, VersionTexts};
use axum::extract::rejection::JsonRejection;
use axum::extract::State;
use axum::Json;
use input::TextsInput;
use serde::Serialize;
use utoipa::ToSchema;

/// The route, for the guard's body limit.
pub const ADMIN_PATH: &str = "/api/admin/models/{slug}/versions/{version}/texts";

/// A version's texts: its own, in `language`, and the translations.
#[derive(Serialize, ToSchema)]
pub struct Texts {
    /// BCP 47 tag of `title`, `description` and `credit`, or null when
    /// not stated.
    language: Option<String>,
    title: String,
    description: String,
    /// Null when the version has no credit line (a translated credit is
    /// then not shown either).
    credit: Option<String>,
    /// Per BCP 47 tag, `{"title", "description", "credit"}`, each present
    /// only where it replaces the version's own text.
    #[schema(value_type = Object)]
    translations: Translations,
}

impl From<VersionTexts> for Texts {
    fn from(v: VersionTexts) -> Self {
        Texts {
            language: v.texts.language,
            title: v.title,
            description: v.description,
            credit: v.credit,
            translations: v.texts.translations,
        }
    }
}

fn check_slug(slug: &str) -> Result<(), AppError> {
    if valid_slug(slug) {
        Ok(())
    } else {
        Err(AppError::BadRequest(format!(
            "{slug:?} is not a model slug"
        )))
    }
}

async fn texts_of(state: &AppState, slug: &str, version: u32) -> Result<Texts, AppError> {
    check_slug(slug)?;
    state
        .storage()
        .version_texts(slug, version)
        .await?
        .map(Texts::from)
        .ok_or(AppError::NotFound("version"))
}

/// A version's own texts and their translations (curator token).
#[utoipa::path(
    get,
    path = ADMIN_PATH,
    params(AdminVersion),
    security(("bearer" = [])),
    responses(
        (status = 200, description = "The version's texts", body = Texts),
        (status = 400, description = "Malformed path or `Authorization`", body = ErrorBody),
        (status = 401, description = "No token, or an unknown one", body = ErrorBody),
        (status = 403, description = "Not a curator token, or one for another model", body = ErrorBody),
        (status = 404, description = "No such model or version", body = ErrorBody),
    )
)]
pub async fn get(
    State(state): State<AppState>,
    curator: Curator,
    PathParams(AdminVersion { slug, version }): PathParams<AdminVersion>,
) -> Result<Json<Texts>, AppError> {
    curator.check_model(&slug)?;
    Ok(Json(texts_of(&state, &slug, version).await?))
}

/// Replaces the language of a version's own texts and all their
/// translations (curator token); answers the texts as they now are.
#[utoipa::path(
    put,
    path = ADMIN_PATH,
    params(AdminVersion),
    request_body = TextsInput,
    security(("bearer" = [])),
    responses(
        (status = 200, description = "The version's texts now", body = Texts),
        (status = 400, description = "Malformed path or `Authorization`", body = ErrorBody),
        (status = 401, description = "No token, or an unknown one", body = ErrorBody),
        (status = 403, description = "Not a curator token, or one for another model", body = ErrorBody),
        (status = 404, description = "No such model or version", body = ErrorBody),
        (status = 413, description = "Body over 1 MiB", body = ErrorBody),
        (status = 422, description = "A malformed language tag, a translation without text, \
            a title over 200 characters or of several lines, a description over 10,000, a \
            credit over 300 bytes or of several lines, or more than 20 languages",
            body = ErrorBody),
    )
)]
pub async fn put(
    State(state): State<AppState>,
    curator: Curator,
    PathParams(AdminVersion { slug, version }): PathParams<AdminVersion>,
    input: Result<Json<TextsInput>, JsonRejection>,
) -> Result<Json<Texts>, AppError> {
    curator.check_model(&slug)?;
    let Json(input) = input.map_err(|e| AppError::Unprocessable(e.body_text()))?;
    let texts = input.validate().map_err(AppError::Unprocessable)?;
    check_slug(&slug)?;
    if !state
        .storage()
        .set_version_texts(&slug, version, &texts)
        .await?
    {
        return Err(AppError::NotFound("version"));
    }
    state.invalidate();
    Ok(Json(texts_of(&state, &slug, version).await?))
}
