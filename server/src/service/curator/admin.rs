//! `/api/admin/models/{slug}/…`: what the `/admin` page does with a model's
//! versions (curator token): list them, withdraw one (or put it back), set
//! the good-enough level. The same storage calls as `vitrine models` and
//! `vitrine study report --apply`.

use super::Curator;
use crate::service::error::{AppError, ErrorBody};
use crate::service::servable::PathParams;
use crate::service::AppState;
use crate::storage::{parse_credit, parse_licence, valid_slug, Rights, VersionRecord};
use axum::extract::rejection::JsonRejection;
use axum::extract::State;
use axum::Json;
use serde::{Deserialize, Serialize};
use utoipa::{IntoParams, ToSchema};

#[derive(Serialize, ToSchema)]
pub struct Version {
    version: u32,
    title: String,
    /// `ready` or `withdrawn`. The visible version is the highest ready one.
    status: String,
    policy: String,
    /// Null: the 20 % rule.
    good_enough_level: Option<u32>,
    /// Levels including the base.
    levels: u32,
    /// Unix milliseconds.
    created_at: i64,
    /// Credit line, or null.
    credit: Option<String>,
    /// Licence identifier (`GET /api/licences`), or null.
    licence: Option<&'static str>,
}

impl From<VersionRecord> for Version {
    fn from(v: VersionRecord) -> Self {
        Version {
            version: v.version,
            title: v.title,
            status: v.status,
            policy: v.policy,
            good_enough_level: v.good_enough_level,
            levels: v.levels,
            created_at: v.created_at_ms,
            credit: v.rights.credit,
            licence: v.rights.licence.map(|l| l.id),
        }
    }
}

#[derive(Serialize, ToSchema)]
pub struct VersionList {
    slug: String,
    /// Newest first.
    versions: Vec<Version>,
}

#[derive(Deserialize, IntoParams)]
#[into_params(parameter_in = Path)]
pub struct AdminSlug {
    slug: String,
}

#[derive(Deserialize, IntoParams)]
#[into_params(parameter_in = Path)]
pub struct AdminVersion {
    pub(crate) slug: String,
    pub(crate) version: u32,
}

/// A change to one version; absent fields are left as they are.
#[derive(Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct VersionChange {
    /// `ready` or `withdrawn`.
    status: Option<String>,
    /// A level of the version, or null for the 20 % rule. Absent: unchanged.
    #[serde(default, deserialize_with = "present")]
    #[schema(value_type = Option<u32>)]
    good_enough_level: Option<Option<u32>>,
    /// Credit line (one line, at most 300 bytes), or null or `""` to clear
    /// it. Absent: unchanged. Rights change without ingesting again.
    #[serde(default, deserialize_with = "present")]
    #[schema(value_type = Option<String>)]
    credit: Option<Option<String>>,
    /// Licence identifier (`GET /api/licences`), or null or `""` to clear
    /// it. Absent: unchanged.
    #[serde(default, deserialize_with = "present")]
    #[schema(value_type = Option<String>)]
    licence: Option<Option<String>>,
}

/// Tells an explicit null (`Some(None)`) from an absent field (`None`).
pub(super) fn present<'de, D, T>(d: D) -> Result<Option<Option<T>>, D::Error>
where
    D: serde::Deserializer<'de>,
    T: Deserialize<'de>,
{
    Option::<T>::deserialize(d).map(Some)
}

async fn versions_of(state: &AppState, slug: &str) -> Result<Vec<VersionRecord>, AppError> {
    if !valid_slug(slug) {
        return Err(AppError::BadRequest(format!(
            "{slug:?} is not a model slug"
        )));
    }
    let versions = state.storage().versions(slug).await?;
    if versions.is_empty() {
        return Err(AppError::NotFound("model"));
    }
    Ok(versions)
}

/// Every version of a model, withdrawn ones too (curator token).
#[utoipa::path(
    get,
    path = "/api/admin/models/{slug}/versions",
    params(AdminSlug),
    security(("bearer" = [])),
    responses(
        (status = 200, description = "Versions, newest first", body = VersionList),
        (status = 400, description = "Malformed slug or `Authorization`", body = ErrorBody),
        (status = 401, description = "No token, or an unknown one", body = ErrorBody),
        (status = 403, description = "Not a curator token, or one for another model", body = ErrorBody),
        (status = 404, description = "No such model", body = ErrorBody),
    )
)]
pub async fn versions(
    State(state): State<AppState>,
    curator: Curator,
    PathParams(AdminSlug { slug }): PathParams<AdminSlug>,
) -> Result<Json<VersionList>, AppError> {
    curator.check_model(&slug)?;
    let versions = versions_of(&state, &slug).await?;
    Ok(Json(VersionList {
        slug,
        versions: versions.into_iter().map(Version::from).collect(),
    }))
}

/// Withdraws a version or puts it back, sets its good-enough level, or
/// changes its credit line or licence (curator token). Answers the version
/// as it now is.
#[utoipa::path(
    put,
    path = "/api/admin/models/{slug}/versions/{version}",
    params(AdminVersion),
    request_body = VersionChange,
    security(("bearer" = [])),
    responses(
        (status = 200, description = "The version now", body = Version),
        (status = 400, description = "Malformed path or `Authorization`", body = ErrorBody),
        (status = 401, description = "No token, or an unknown one", body = ErrorBody),
        (status = 403, description = "Not a curator token, or one for another model", body = ErrorBody),
        (status = 404, description = "No such model or version", body = ErrorBody),
        (status = 422, description = "Unknown status or licence, a level past the last, or a \
            credit line over 300 bytes or of several lines", body = ErrorBody),
    )
)]
pub async fn change(
    State(state): State<AppState>,
    curator: Curator,
    PathParams(AdminVersion { slug, version }): PathParams<AdminVersion>,
    change: Result<Json<VersionChange>, JsonRejection>,
) -> Result<Json<Version>, AppError> {
    curator.check_model(&slug)?;
    let Json(change) = change.map_err(|e| AppError::Unprocessable(e.body_text()))?;
    let versions = versions_of(&state, &slug).await?;
    let current = versions
        .iter()
        .find(|v| v.version == version)
        .ok_or(AppError::NotFound("version"))?;
    if let Some(status) = &change.status {
        if !matches!(status.as_str(), "ready" | "withdrawn") {
            return Err(AppError::Unprocessable(format!(
                "status {status:?} must be ready or withdrawn"
            )));
        }
    }
    if let Some(Some(level)) = change.good_enough_level {
        if level >= current.levels {
            return Err(AppError::Unprocessable(format!(
                "good-enough level {level} is past the last level {}",
                current.levels - 1
            )));
        }
    }
    let rights = match (&change.credit, &change.licence) {
        (None, None) => None,
        (credit, licence) => Some(Rights {
            credit: match credit {
                Some(credit) => parse_credit(credit.as_deref()).map_err(AppError::Unprocessable)?,
                None => current.rights.credit.clone(),
            },
            licence: match licence {
                Some(id) => parse_licence(id.as_deref()).map_err(AppError::Unprocessable)?,
                None => current.rights.licence,
            },
        }),
    };
    let storage = state.storage();
    if let Some(rights) = &rights {
        storage.set_version_rights(&slug, version, rights).await?;
    }
    if let Some(status) = &change.status {
        storage.set_version_status(&slug, version, status).await?;
    }
    if let Some(level) = change.good_enough_level {
        storage.set_good_enough_level(&slug, version, level).await?;
    }
    state.invalidate();
    let now = versions_of(&state, &slug).await?;
    let changed = now
        .into_iter()
        .find(|v| v.version == version)
        .ok_or(AppError::NotFound("version"))?;
    Ok(Json(changed.into()))
}
