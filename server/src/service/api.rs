//! JSON routes: the model list and a model's manifest.

use super::cache_headers;
use super::cap::Audience;
use super::error::{AppError, ErrorBody};
use super::manifest::{self, Manifest};
use super::servable::{ServableModel, SlugParam};
use super::visitor::{HintQuery, VisitorHints};
use super::AppState;
use crate::storage::{Licence, ModelKind, ModelSummary, Translations, LICENCES};
use axum::extract::State;
use axum::response::{IntoResponse, Response};
use axum::Json;
use serde::Serialize;
use std::sync::Arc;
use utoipa::ToSchema;

#[derive(Serialize, ToSchema)]
pub struct ModelList {
    models: Vec<ListedModel>,
}

#[derive(Serialize, ToSchema)]
struct ListedModel {
    slug: String,
    title: String,
    /// BCP 47 tag of `title`, or null when not stated.
    language: Option<String>,
    /// Titles in other languages: `{"pt": {"title": "…"}}` (the viewer
    /// shows the visitor's, else `title`).
    #[schema(value_type = Object)]
    translations: Translations,
    version: u32,
    /// `mesh` or `points` (a point cloud).
    kind: ModelKind,
    /// Base mesh plus batches.
    levels: u32,
    manifest_url: String,
    page_url: String,
    /// `/api/models/{slug}/thumbnail?v={version}`; null when the version has none.
    thumbnail: Option<String>,
}

/// Models this visitor may see, from the cached list.
pub async fn visible_models(
    state: &AppState,
    hints: &VisitorHints,
) -> Result<Vec<ModelSummary>, AppError> {
    let storage = state.storage();
    let load = async { Ok(Arc::new(storage.list_models().await?)) };
    let all =
        super::cache::through(&state.caches().list, state.metrics(), "list", (), load).await?;
    let mut visible = Vec::with_capacity(all.len());
    // Models in a stream format this build cannot decode are left out: no
    // visitor could open them (the start-up log names them).
    for m in all.iter().filter(|m| m.servable()) {
        // Tokens are checked only when a restricted model is in the list.
        if m.public_access || state.visitor(hints, &m.slug).await?.audience != Audience::Public {
            visible.push(m.clone());
        }
    }
    Ok(visible)
}

/// Models this visitor may see.
#[utoipa::path(
    get,
    path = "/api/models",
    params(HintQuery),
    responses(
        (status = 200, description = "Model list (`Cache-Control: public, max-age=2, …` without a token, `private, no-store` with one)", body = ModelList),
        (status = 400, description = "Malformed query or `Authorization`", body = ErrorBody),
        (status = 401, description = "The token is unknown, revoked or expired", body = ErrorBody),
        (status = 503, description = "Database unavailable or server overloaded", body = ErrorBody,
            headers(("Retry-After" = u64, description = "Seconds to wait before asking again"))),
    )
)]
pub async fn list(
    State(state): State<AppState>,
    hints: VisitorHints,
) -> Result<Response, AppError> {
    let models = visible_models(&state, &hints)
        .await?
        .into_iter()
        .map(|m| ListedModel {
            thumbnail: m
                .has_thumbnail
                .then(|| super::curator::thumbnail::url(&m.slug, m.version)),
            manifest_url: format!("/api/models/{}", m.slug),
            page_url: format!("/m/{}", m.slug),
            slug: m.slug,
            title: m.title,
            language: m.language,
            translations: m.translations,
            version: m.version,
            kind: m.kind,
            levels: m.batch_count + 1,
        })
        .collect();
    let mut response = Json(ModelList { models }).into_response();
    cache_headers::visitor_json(&mut response, &hints);
    Ok(response)
}

/// A model's manifest: levels, textures, and this visitor's level cap now.
#[utoipa::path(
    get,
    path = "/api/models/{slug}",
    params(SlugParam, HintQuery),
    responses(
        (status = 200, description = "Manifest (`Cache-Control: public, max-age=2, …` without a token, `private, no-store` with one; `Vary: Authorization` and the device hints)", body = Manifest),
        (status = 400, description = "Malformed slug, query or `Authorization`", body = ErrorBody),
        (status = 401, description = "The token is unknown, revoked or expired", body = ErrorBody),
        (status = 404, description = "No such model, or a restricted one without a token for it",
            body = ErrorBody),
        (status = 409, description = "The model is stored in a stream format this build cannot \
            decode (written by another Vitrine version): it must be ingested again; the message \
            says which formats", body = ErrorBody),
        (status = 503, description = "Database unavailable, server overloaded, or a surge of new \
            visitors (error `busy`: admission control lets visitors in at a steady rate; wait \
            `Retry-After`, whose value is the visitor's place in the queue, and ask again)",
            body = ErrorBody,
            headers(("Retry-After" = u64, description = "Seconds to wait before asking again"))),
    )
)]
pub async fn manifest(
    State(state): State<AppState>,
    ServableModel { record, visitor }: ServableModel,
    hints: VisitorHints,
) -> Response {
    let cap = state.level_cap(&record, &visitor);
    let mut response = Json(manifest::build(&state, &record, &visitor, cap)).into_response();
    cache_headers::visitor_json(&mut response, &hints);
    response
}

#[derive(Serialize, ToSchema)]
pub struct LicenceList {
    /// In the order an upload form offers them.
    licences: &'static [Licence],
}

/// The licences and rights statements a version may be published under
/// (the `licence` of an upload or a version change).
#[utoipa::path(
    get,
    path = "/api/licences",
    responses((status = 200, description = "Every licence a version may name (`Cache-Control: public, max-age=3600`)", body = LicenceList))
)]
pub async fn licences() -> Response {
    let mut response = Json(LicenceList {
        licences: &LICENCES,
    })
    .into_response();
    cache_headers::anonymous(&mut response, cache_headers::RELEASE);
    response
}
