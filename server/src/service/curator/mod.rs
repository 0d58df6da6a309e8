//! What curators do over HTTP (issue 22): annotate models, upload scans that
//! are ingested as background jobs, list versions, withdraw one, set the
//! good-enough level. Every write needs a curator token, sent as
//! `Authorization: Bearer …` only: no cookies, so no cross-site request can
//! carry it (no CSRF). Also the thumbnail route, which anyone may read.

pub mod admin;
pub mod annotations;
pub mod jobs;
pub(crate) mod markdown;
pub mod thumbnail;
pub mod upload;

use super::error::AppError;
use super::AppState;
use crate::storage::{sha256_hex, TokenGrant, TokenScope};
use axum::extract::FromRequestParts;
use axum::http::request::Parts;
use axum::http::{header, HeaderMap};
use std::path::PathBuf;

/// Uploads and their ingest jobs.
#[derive(Clone, Debug, PartialEq)]
pub struct UploadConfig {
    /// Where uploads are spooled (generated names; removed after the ingest).
    pub dir: PathBuf,
    /// Larger uploads are refused with 413.
    pub limit_bytes: u64,
    /// Ingests run at once; more wait their turn (state `queued`).
    pub concurrent_jobs: usize,
    /// Jobs waiting at once on this instance; more are refused with 429.
    pub max_queued: usize,
    /// `https://museum.example`: the absolute base of `og:image`; by
    /// default the request's `Host`.
    pub public_base_url: Option<String>,
}

impl Default for UploadConfig {
    fn default() -> Self {
        UploadConfig {
            dir: std::env::temp_dir(),
            limit_bytes: 512 << 20,
            concurrent_jobs: 1,
            max_queued: 8,
            public_base_url: None,
        }
    }
}

/// A request with a live curator token. No token: 401 (`token_required`);
/// an unknown one: 401 (`invalid_token`); a researcher's: 403.
pub struct Curator(pub TokenGrant);

impl Curator {
    /// A token limited to one model may only touch that model.
    pub fn check_model(&self, slug: &str) -> Result<(), AppError> {
        if self.0.covers(slug) {
            Ok(())
        } else {
            Err(AppError::NotAllowed(format!(
                "this curator token is limited to another model than {slug:?}"
            )))
        }
    }
}

impl FromRequestParts<AppState> for Curator {
    type Rejection = AppError;

    async fn from_request_parts(parts: &mut Parts, state: &AppState) -> Result<Self, AppError> {
        let token = bearer(&parts.headers)?.ok_or(AppError::TokenRequired)?;
        let digest = sha256_hex(token.as_bytes());
        let storage = state.storage();
        let load = async { storage.token_grant(&digest, crate::storage::now_ms()).await };
        let grant = super::cache::through(
            &state.caches().tokens,
            state.metrics(),
            "token",
            digest.clone(),
            load,
        )
        .await?
        .ok_or(AppError::InvalidToken)?;
        if grant.scope != TokenScope::Curator {
            return Err(AppError::NotAllowed(format!(
                "a {} token cannot publish or annotate: this needs a curator token",
                grant.scope.name()
            )));
        }
        Ok(Curator(grant))
    }
}

/// The token of `Authorization: Bearer …`, the only place a curator's is read.
fn bearer(headers: &HeaderMap) -> Result<Option<String>, AppError> {
    let Some(value) = headers.get(header::AUTHORIZATION) else {
        return Ok(None);
    };
    let text = value
        .to_str()
        .map_err(|_| AppError::BadRequest("Authorization is not ASCII".into()))?;
    match text.split_once(' ') {
        Some((scheme, token))
            if scheme.eq_ignore_ascii_case("bearer") && !token.trim().is_empty() =>
        {
            Ok(Some(token.trim().to_owned()))
        }
        _ => Err(AppError::BadRequest(
            "Authorization must be 'Bearer <token>'".into(),
        )),
    }
}
