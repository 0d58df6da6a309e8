//! JSON routes: the model list and a model's manifest.

use super::cap::{good_enough_level, Audience, CapReason, DeviceClass, LevelCap};
use super::error::AppError;
use super::payload;
use super::visitor::VisitorHints;
use super::{AppState, Visitor};
use crate::storage::{valid_slug, ModelRecord, ModelSummary, TextureRef};
use axum::extract::{Path, State};
use axum::http::{header, HeaderValue};
use axum::response::{IntoResponse, Response};
use axum::routing::{any, get};
use axum::{Json, Router};
use serde::Serialize;
use std::sync::Arc;

pub fn routes() -> Router<AppState> {
    Router::new()
        .route("/api/models", get(list))
        .route("/api/models/{slug}", get(manifest))
        .route("/api/compressions/{id}/base", get(payload::base))
        .route(
            "/api/compressions/{id}/batches/{iteration}",
            get(payload::batch),
        )
        .route("/api/textures/{id}", get(payload::texture))
        .route(
            "/api/{*rest}",
            any(|| async { AppError::NotFound("route") }),
        )
}

#[derive(Serialize)]
struct ModelList {
    models: Vec<ListedModel>,
}

#[derive(Serialize)]
struct ListedModel {
    slug: String,
    title: String,
    version: u32,
    levels: u32,
    manifest_url: String,
    page_url: String,
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
        if m.public_access || state.visitor(hints, &m.slug).await?.audience == Audience::Researcher
        {
            visible.push(m.clone());
        }
    }
    Ok(visible)
}

async fn list(State(state): State<AppState>, hints: VisitorHints) -> Result<Response, AppError> {
    let models = visible_models(&state, &hints)
        .await?
        .into_iter()
        .map(|m| ListedModel {
            manifest_url: format!("/api/models/{}", m.slug),
            page_url: format!("/m/{}", m.slug),
            slug: m.slug,
            title: m.title,
            version: m.version,
            levels: m.batch_count + 1,
        })
        .collect();
    Ok(no_store(Json(ModelList { models })))
}

#[derive(Serialize)]
struct Manifest<'a> {
    slug: &'a str,
    version: u32,
    title: &'a str,
    description: &'a str,
    compression_id: i64,
    quantization_bits: u8,
    has_colour: bool,
    /// Index of the full-resolution level (= number of batches).
    last_level: u32,
    good_enough_level: u32,
    levels: Vec<ManifestLevel>,
    /// Every level's quality against the original, when it was measured at
    /// ingest (`vitrine ingest --quality`); absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    quality: Option<Vec<ManifestQuality>>,
    /// How the model is coloured: `ccc` (textures through a cubic cell
    /// complex, shared by every level), `vertex` (colour in the stream) or
    /// `none`.
    colour: ManifestColour<'a>,
    textures: Vec<ManifestTexture<'a>>,
    visitor: ManifestVisitor,
    cap: ManifestCap,
}

#[derive(Serialize)]
struct ManifestLevel {
    level: u32,
    vertices: u32,
    faces: u32,
    bytes: u64,
    hausdorff: Option<f64>,
    rmse: Option<f64>,
    /// The payload that produces this level: the base for level 0.
    url: String,
    allowed: bool,
}

/// One point of the quality curve.
#[derive(Serialize)]
struct ManifestQuality {
    level: u32,
    vertices: u32,
    /// Symmetric Hausdorff distance over the bounding-box diagonal.
    hausdorff: f64,
    /// Roy et al. colour RMSE (0–255); null without colour.
    roy_rmse: Option<f64>,
    /// Lindstrom–Turk luma RMSE (0–255) over 24 views.
    image_rmse: f64,
}

#[derive(Serialize)]
struct ManifestTexture<'a> {
    id: i64,
    kind: &'a str,
    /// `cell`, `colour` or `colour_low`.
    role: &'a str,
    media_type: &'a str,
    bytes: u64,
    width: Option<u32>,
    height: Option<u32>,
    url: String,
}

#[derive(Serialize)]
struct ManifestCcc<'a> {
    parameters: &'a serde_json::Value,
    cell_texture: ManifestTexture<'a>,
    colour_texture: ManifestTexture<'a>,
    colour_texture_low: ManifestTexture<'a>,
}

#[derive(Serialize)]
#[serde(tag = "mode", rename_all = "lowercase")]
enum ManifestColour<'a> {
    /// Colour mapping through a cubic cell complex (`codec/colour/CCC.md`): the
    /// viewer loads the cell texture and the low-resolution colour texture
    /// after the base mesh, then the full-resolution one.
    Ccc(Box<ManifestCcc<'a>>),
    /// Per-vertex colour travels in the stream.
    Vertex,
    None,
}

#[derive(Serialize)]
struct ManifestVisitor {
    audience: Audience,
    device: DeviceClass,
    /// `"query"` when `?device=` was given, else `"hints"`.
    device_source: &'static str,
}

#[derive(Serialize)]
struct ManifestCap {
    level: u32,
    reason: Option<CapReason>,
    limits: LevelCap,
    /// When the cap is set by load: when to ask again.
    retry_after_s: Option<u64>,
    load_pressure: u8,
    load_steps: u8,
}

async fn manifest(
    State(state): State<AppState>,
    Path(slug): Path<String>,
    hints: VisitorHints,
) -> Result<Response, AppError> {
    if !valid_slug(&slug) {
        return Err(AppError::BadRequest(format!(
            "{slug:?} is not a model slug"
        )));
    }
    let record = state.record_by_slug(&slug).await?;
    let visitor = state.visitor(&hints, &record.slug).await?;
    state.ensure_servable(&record, &visitor)?;
    let cap = state.level_cap(&record, &visitor);
    Ok(no_store(Json(build_manifest(
        &state, &record, &visitor, cap,
    ))))
}

fn build_manifest<'a>(
    state: &AppState,
    record: &'a ModelRecord,
    visitor: &Visitor,
    cap: LevelCap,
) -> Manifest<'a> {
    let id = record.compression_id;
    let pressure = state.load().pressure();
    let levels = record
        .levels
        .iter()
        .enumerate()
        .map(|(k, l)| ManifestLevel {
            level: k as u32,
            vertices: l.vertices,
            faces: l.faces,
            bytes: l.bytes,
            hausdorff: l.hausdorff,
            rmse: l.rmse,
            url: if k == 0 {
                format!("/api/compressions/{id}/base")
            } else {
                format!("/api/compressions/{id}/batches/{k}")
            },
            allowed: k as u32 <= cap.level,
        })
        .collect();
    let quality = record
        .levels
        .iter()
        .enumerate()
        .map(|(k, l)| {
            l.metrics().map(|m| ManifestQuality {
                level: k as u32,
                vertices: l.vertices,
                hausdorff: m.hausdorff,
                roy_rmse: m.roy_rmse,
                image_rmse: m.image_rmse,
            })
        })
        .collect();
    let texture = |t: &'a TextureRef| ManifestTexture {
        id: t.id,
        kind: &t.kind,
        role: &t.role,
        media_type: &t.media_type,
        bytes: t.bytes,
        width: t.width,
        height: t.height,
        url: format!("/api/textures/{}", t.id),
    };
    let textures = record.textures.iter().map(texture).collect();
    let role = |r: &str| record.textures.iter().find(|t| t.role == r).map(texture);
    let colour = match (
        &record.mapping,
        role("cell"),
        role("colour"),
        role("colour_low"),
    ) {
        (Some(mapping), Some(cell_texture), Some(colour_texture), Some(colour_texture_low)) => {
            ManifestColour::Ccc(Box::new(ManifestCcc {
                parameters: &mapping.parameters,
                cell_texture,
                colour_texture,
                colour_texture_low,
            }))
        }
        _ if record.has_colour => ManifestColour::Vertex,
        _ => ManifestColour::None,
    };
    Manifest {
        slug: &record.slug,
        version: record.version,
        title: &record.title,
        description: &record.description,
        compression_id: id,
        quantization_bits: record.quantization_bits,
        has_colour: record.has_colour,
        last_level: record.batch_count(),
        good_enough_level: good_enough_level(record, &state.config().caps),
        levels,
        quality,
        colour,
        textures,
        visitor: ManifestVisitor {
            audience: visitor.audience,
            device: visitor.device,
            device_source: if visitor.device_explicit {
                "query"
            } else {
                "hints"
            },
        },
        cap: ManifestCap {
            level: cap.level,
            reason: cap.reason,
            limits: cap,
            retry_after_s: (cap.reason == Some(CapReason::Load))
                .then(|| state.load().config().retry_after.as_secs().max(1)),
            load_pressure: pressure.level,
            load_steps: pressure.steps,
        },
    }
}

/// Manifests and lists depend on load and on the visitor: never cache them.
fn no_store(body: impl IntoResponse) -> Response {
    let mut response = body.into_response();
    response
        .headers_mut()
        .insert(header::CACHE_CONTROL, HeaderValue::from_static("no-store"));
    response
}
