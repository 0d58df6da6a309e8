//! `POST /api/models`: a curator uploads a scan as `multipart/form-data`
//! (`file`, `slug`, `title`, optional `description`, `policy`, `colour`,
//! `kind`, `unit`, `up`, `credit`, `licence`, `language`). A point cloud (a PLY without faces, LAS, LAZ) is stored as a
//! point stream.
//! The file is streamed to a spool file on disk, never held in memory; its
//! name as sent never becomes a path (the spool file's name is generated
//! and keeps only the validated extension, which picks the importer). The
//! ingest is a background job ([`super::jobs`]): the answer is 202 with the
//! job to poll.

use super::jobs::{self, JobInput};
use super::Curator;
use crate::ingest::curation::UNITS;
use crate::ingest::{IngestOptions, ModelMeta};
use crate::service::error::{AppError, ErrorBody};
use crate::service::AppState;
use crate::storage::{valid_slug, ModelKind, NewJob, OnExisting, Rights, UpAxis};
use axum::extract::multipart::{Field, Multipart, MultipartError};
use axum::extract::State;
use axum::http::StatusCode;
use axum::response::{IntoResponse, Response};
use axum::Json;
use serde::Serialize;
use tempfile::TempPath;
use tokio::io::AsyncWriteExt;
use utoipa::ToSchema;
use vitrine_colour::ColourMode;

/// Formats an upload may be in: the single-file ones (OBJ's materials and
/// a glTF's external buffers would need files beside them), and the point
/// clouds' LAS and LAZ.
pub const EXTENSIONS: [&str; 8] = ["ply", "obj", "off", "glb", "gltf", "md2", "las", "laz"];

/// Longest text field (title, description…), in bytes.
const MAX_FIELD_BYTES: usize = 16 * 1024;

/// The form, as described (the handler reads it as a stream).
#[derive(ToSchema)]
#[allow(dead_code)]
pub struct UploadForm {
    /// The scan: PLY, OBJ, OFF, GLB, glTF (embedded buffers) or MD2; or a
    /// point cloud: PLY without faces, LAS or LAZ.
    #[schema(value_type = String, format = Binary)]
    file: Vec<u8>,
    /// URL name: 1–64 of a-z, 0-9 and '-'. An existing slug gets a new version.
    slug: String,
    title: String,
    description: Option<String>,
    /// Audience policy (default `exhibition`).
    policy: Option<String>,
    /// `ccc`, `vertex`, `vertex-metric` or `none` (default: `ccc` for a
    /// textured scan, `vertex` with per-vertex colour, else `none`).
    colour: Option<String>,
    /// `mesh` or `points` (default: `points` for LAS, LAZ and a PLY that
    /// declares no faces, else `mesh`).
    kind: Option<String>,
    /// The unit of the file's coordinates: `mm`, `cm`, `m` or `in`
    /// (measurements are given in it; downloads are scaled to metres).
    unit: Option<String>,
    /// Which model axis points up: `x`, `y`, `z`, `-x`, `-y` or `-z`
    /// (default: detected, as `vitrine ingest --up`).
    up: Option<String>,
    /// Credit line shown under the model and carried by its downloads; one
    /// line, at most 300 bytes.
    credit: Option<String>,
    /// Licence or rights statement, an identifier from `GET /api/licences`
    /// (`CC-BY-4.0`, `CC0-1.0`, `InC`, …).
    licence: Option<String>,
    /// The language of title, description and credit, a BCP 47 tag (`pt`,
    /// `pt-BR`); translations are added in `/admin` afterwards.
    language: Option<String>,
}

#[derive(Serialize, ToSchema)]
pub struct Accepted {
    job: i64,
    status_url: String,
}

/// Uploads a scan and starts its ingest (curator token).
#[utoipa::path(
    post,
    path = "/api/models",
    request_body(content = UploadForm, content_type = "multipart/form-data"),
    security(("bearer" = [])),
    responses(
        (status = 202, description = "Ingest queued: poll `status_url`", body = Accepted),
        (status = 400, description = "Malformed form or `Authorization`", body = ErrorBody),
        (status = 401, description = "No token, or an unknown one", body = ErrorBody),
        (status = 403, description = "Not a curator token, or one for another model", body = ErrorBody),
        (status = 413, description = "The file is over the upload limit (`--upload-limit-mb`)",
            body = ErrorBody),
        (status = 422, description = "A field is missing or invalid; the message says which",
            body = ErrorBody),
        (status = 429, description = "Too many uploads waiting; try again later", body = ErrorBody),
    )
)]
pub async fn upload(
    State(state): State<AppState>,
    curator: Curator,
    mut form: Multipart,
) -> Result<Response, AppError> {
    let limit = state.config().uploads.limit_bytes;
    let mut fields = Fields::default();
    let mut spooled: Option<(TempPath, String)> = None;
    while let Some(field) = form.next_field().await.map_err(multipart_error)? {
        match field.name().unwrap_or("") {
            "file" => {
                let sent_name = field.file_name().unwrap_or("").to_owned();
                spooled = Some((spool(&state, field, &sent_name, limit).await?, sent_name));
            }
            name => {
                let name = name.to_owned();
                let value = text(field).await?;
                fields.set(&name, value)?;
            }
        }
    }
    let (file, source_name) =
        spooled.ok_or_else(|| AppError::Unprocessable("the form has no `file`".into()))?;
    let (meta, options, kind) = fields.validate()?;
    curator.check_model(&meta.slug)?;
    let place = state.jobs().reserve().ok_or_else(|| {
        AppError::TooManyRequests("too many uploads are waiting; try again later".into())
    })?;
    let job = state
        .storage()
        .insert_job(&NewJob {
            slug: meta.slug.clone(),
            title: meta.title.clone(),
            source_name,
            token_id: Some(curator.0.id),
        })
        .await?;
    let accepted = Accepted {
        job: job.id,
        status_url: format!("/api/jobs/{}", job.id),
    };
    jobs::spawn(
        state.clone(),
        job,
        place,
        JobInput {
            file,
            meta,
            options,
            kind,
        },
    );
    Ok((StatusCode::ACCEPTED, Json(accepted)).into_response())
}

fn multipart_error(e: MultipartError) -> AppError {
    if e.status() == StatusCode::PAYLOAD_TOO_LARGE {
        AppError::PayloadTooLarge
    } else {
        AppError::BadRequest(format!("malformed form: {}", e.body_text()))
    }
}

/// Streams the file to a spool file named by `tempfile`, with the sent
/// name's extension once it is one of [`EXTENSIONS`]; 413 past `limit`.
async fn spool(
    state: &AppState,
    mut field: Field<'_>,
    sent_name: &str,
    limit: u64,
) -> Result<TempPath, AppError> {
    let extension = std::path::Path::new(sent_name)
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .filter(|e| EXTENSIONS.contains(&e.as_str()))
        .ok_or_else(|| {
            AppError::Unprocessable(format!(
                "the file's name must end in one of .{}",
                EXTENSIONS.join(", .")
            ))
        })?;
    let dir = &state.config().uploads.dir;
    let named = tempfile::Builder::new()
        .prefix("vitrine-upload-")
        .suffix(&format!(".{extension}"))
        .tempfile_in(dir)
        .map_err(|e| AppError::Internal(format!("spooling an upload in {}: {e}", dir.display())))?;
    let (std_file, path) = named.into_parts();
    let mut file = tokio::fs::File::from_std(std_file);
    let mut written: u64 = 0;
    while let Some(chunk) = field.chunk().await.map_err(multipart_error)? {
        written += chunk.len() as u64;
        if written > limit {
            return Err(AppError::PayloadTooLarge);
        }
        file.write_all(&chunk)
            .await
            .map_err(|e| AppError::Internal(format!("spooling an upload: {e}")))?;
    }
    file.flush()
        .await
        .map_err(|e| AppError::Internal(format!("spooling an upload: {e}")))?;
    if written == 0 {
        return Err(AppError::Unprocessable("the file is empty".into()));
    }
    Ok(path)
}

async fn text(mut field: Field<'_>) -> Result<String, AppError> {
    let mut bytes = Vec::new();
    while let Some(chunk) = field.chunk().await.map_err(multipart_error)? {
        if bytes.len() + chunk.len() > MAX_FIELD_BYTES {
            return Err(AppError::Unprocessable(format!(
                "a form field is longer than {MAX_FIELD_BYTES} bytes"
            )));
        }
        bytes.extend_from_slice(&chunk);
    }
    String::from_utf8(bytes)
        .map_err(|_| AppError::Unprocessable("a form field is not UTF-8".into()))
}

/// The text fields of the form.
#[derive(Default)]
struct Fields {
    slug: Option<String>,
    title: Option<String>,
    description: Option<String>,
    policy: Option<String>,
    colour: Option<String>,
    kind: Option<String>,
    unit: Option<String>,
    up: Option<String>,
    credit: Option<String>,
    licence: Option<String>,
    language: Option<String>,
}

impl Fields {
    fn set(&mut self, name: &str, value: String) -> Result<(), AppError> {
        let slot = match name {
            "slug" => &mut self.slug,
            "title" => &mut self.title,
            "description" => &mut self.description,
            "policy" => &mut self.policy,
            "colour" => &mut self.colour,
            "kind" => &mut self.kind,
            "unit" => &mut self.unit,
            "up" => &mut self.up,
            "credit" => &mut self.credit,
            "licence" => &mut self.licence,
            "language" => &mut self.language,
            other => {
                return Err(AppError::Unprocessable(format!(
                    "unknown form field {other:?} (file, slug, title, description, policy, \
                     colour, kind, unit, up, credit, licence, language)"
                )))
            }
        };
        *slot = Some(value);
        Ok(())
    }

    fn validate(self) -> Result<(ModelMeta, IngestOptions, Option<ModelKind>), AppError> {
        let bad = |m: String| AppError::Unprocessable(m);
        let slug = self
            .slug
            .ok_or_else(|| bad("the form has no `slug`".into()))?;
        if !valid_slug(&slug) {
            return Err(bad(format!(
                "slug {slug:?} must be 1–64 of a-z, 0-9 and '-', not starting or ending with '-'"
            )));
        }
        let title = self.title.unwrap_or_default().trim().to_owned();
        if title.is_empty() {
            return Err(bad("the form has no `title`".into()));
        }
        let mut meta = ModelMeta::new(slug, title);
        meta.description = self.description.unwrap_or_default();
        if let Some(policy) = self.policy.filter(|p| !p.is_empty()) {
            meta.policy = policy;
        }
        meta.on_existing = OnExisting::NewVersion;
        meta.unit = match self.unit.as_deref() {
            None | Some("") => None,
            Some(unit) if UNITS.contains(&unit) => Some(unit.to_owned()),
            Some(unit) => {
                return Err(bad(format!(
                    "unit {unit:?} must be one of {}",
                    UNITS.join(", ")
                )))
            }
        };
        meta.up = match self.up.as_deref() {
            None | Some("") => None,
            Some(name) => Some(
                name.parse::<UpAxis>()
                    .map_err(|e| bad(format!("up: {e}")))?,
            ),
        };
        meta.rights =
            Rights::parse(self.credit.as_deref(), self.licence.as_deref()).map_err(bad)?;
        meta.language = match self.language.as_deref().map(str::trim) {
            None | Some("") => None,
            Some(tag) => Some(super::annotations::parse_language(tag).map_err(bad)?),
        };
        let colour = match self.colour.as_deref() {
            None | Some("") => None,
            Some(name) => Some(name.parse::<ColourMode>().map_err(|_| {
                bad(format!(
                    "colour {name:?} must be ccc, vertex, vertex-metric or none"
                ))
            })?),
        };
        let kind = match self.kind.as_deref() {
            None | Some("") => None,
            Some(name) => Some(
                ModelKind::parse(name)
                    .ok_or_else(|| bad(format!("kind {name:?} must be mesh or points")))?,
            ),
        };
        let options = IngestOptions {
            colour,
            ..IngestOptions::default()
        };
        Ok((meta, options, kind))
    }
}
