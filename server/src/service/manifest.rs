//! A model's manifest: what the viewer loads, level by level, and how far
//! this visitor may go now. The types are the response and, through
//! `ToSchema`, its OpenAPI description.

use super::cap::{good_enough_level, Audience, CapReason, DeviceClass, LevelCap};
use super::{AppState, Visitor};
use crate::storage::{Licence, ModelKind, ModelRecord, TextureRef, Translations};
use serde::Serialize;
use utoipa::ToSchema;
use vitrine_mesh::export::glb_bin_bytes;

#[derive(Serialize, ToSchema)]
pub struct Manifest<'a> {
    slug: &'a str,
    version: u32,
    title: &'a str,
    description: &'a str,
    /// BCP 47 tag of `title`, `description` and `rights.credit`, or null
    /// when not stated.
    language: Option<&'a str>,
    /// The texts in other languages, per BCP 47 tag: `{"title",
    /// "description", "credit"}`, each present only where it replaces the
    /// default (the viewer shows the visitor's language, else the default).
    #[schema(value_type = Object)]
    translations: &'a Translations,
    /// `mesh`: the payloads are the mesh stream's base and batches
    /// (`codec/core/FORMAT.md`); `points`: a point cloud, the payloads are
    /// the point stream's header with its first level, then one level each
    /// (`codec/points/FORMAT.md`, VPTS), concatenated in order to decode.
    kind: ModelKind,
    compression_id: i64,
    /// The stream's format version (`codec/core/FORMAT.md`): for a mesh 4
    /// (plain) or 5 (charted: a viewer may refine its charts on several
    /// workers at once); for a point cloud its VPTS version.
    stream_format: u8,
    /// Position bits per axis (for a point cloud, the octree's depth).
    quantization_bits: u8,
    has_colour: bool,
    /// Index of the full-resolution level (= number of batches).
    last_level: u32,
    /// Where load caps stop falling.
    good_enough_level: u32,
    levels: Vec<ManifestLevel>,
    /// For a charted stream (`stream_format` 5): its part index
    /// (`/api/compressions/{id}/parts`), for a viewer that refines the
    /// charts in view further than the others; absent for a plain stream.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    parts: Option<String>,
    /// For a nested stream (`stream_format` 6): its part index, the same
    /// endpoint with each part's phase and parent and the split entries.
    /// Apart from `parts` because a viewer that reads `parts` refines flat
    /// charts (format 5) and would misread a nested stream's.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    nested_parts: Option<String>,
    /// Every level's quality against the original, when it was measured at
    /// ingest (`vitrine ingest --quality`, codec/quality/src/levels.rs);
    /// absent otherwise. The model page plots it.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    quality: Option<Vec<LevelQuality>>,
    /// The quality study's answers per level (`/api/study/{slug}/results`),
    /// when a study was begun on this version; absent otherwise, so a page
    /// never asks for results that cannot exist.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    study_results: Option<String>,
    colour: Colour<'a>,
    /// Every image of the colour mapping (also under `colour`).
    textures: Vec<Texture<'a>>,
    visitor: ManifestVisitor,
    cap: ManifestCap,
    /// Which model axis points up (`x`, `y`, `z`, `-x`, `-y`, `-z`); `y`
    /// for versions ingested before it was recorded.
    #[schema(value_type = String, pattern = "^-?[xyz]$")]
    up: &'static str,
    /// The unit of model coordinates (`mm`, `cm`, `m`, `in`), or null.
    unit: Option<&'a str>,
    /// Bounds of the decoded positions (model coordinates: those of the
    /// stream, which annotations and measurements use); null for versions
    /// ingested before they were recorded.
    bounds: Option<ManifestBounds>,
    /// `/api/models/{slug}/thumbnail?v={version}`, or null.
    thumbnail: Option<String>,
    /// Who made the scan and on what terms it may be reused: the viewer
    /// shows them under the model.
    rights: ManifestRights<'a>,
    /// Where the policy lets this visitor download a mesh level as GLB:
    /// the level the cap allows now. Null otherwise (no downloads under the
    /// policy, or a point cloud).
    download: Option<ManifestDownload>,
}

#[derive(Serialize, ToSchema)]
struct ManifestDownload {
    /// `/api/models/{slug}/download.glb?level={level}`; add the viewer's
    /// `token` and `device` as for every API request.
    url: String,
    /// The level the file holds (this visitor's cap now).
    level: u32,
    /// Size of the file within a few kilobytes (its binary chunk exactly).
    bytes: u64,
}

#[derive(Serialize, ToSchema)]
struct ManifestRights<'a> {
    /// Credit line, or null.
    credit: Option<&'a str>,
    /// Licence or rights statement, or null.
    licence: Option<&'static Licence>,
}

#[derive(Serialize, ToSchema)]
struct ManifestBounds {
    min: [f64; 3],
    max: [f64; 3],
}

#[derive(Serialize, ToSchema)]
struct ManifestLevel {
    level: u32,
    /// Vertices of the mesh at this level; for a point cloud, its points.
    vertices: u32,
    /// 0 for a point cloud.
    faces: u32,
    /// Points after this level (cumulative: every level is a prefix of the
    /// next), for a point cloud; absent for a mesh.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    points: Option<u32>,
    bytes: u64,
    /// Symmetric Hausdorff distance to the original over its bounding-box
    /// diagonal, measured at ingest (sampled by default, with `--quality`
    /// as in `quality`); null for versions ingested before it was.
    hausdorff: Option<f64>,
    /// Lindstrom–Turk image RMSE (luma, 0–255, 24 views) against the
    /// original, when measured at ingest; also in `quality`.
    rmse: Option<f64>,
    /// The payload that produces this level: the base for level 0 (for a
    /// point cloud, the stream header with level 0).
    url: String,
    /// Within this visitor's cap now.
    allowed: bool,
}

/// One point of the quality curve.
#[derive(Serialize, ToSchema)]
struct LevelQuality {
    /// 0 is the base mesh.
    level: u32,
    vertices: u32,
    /// Symmetric Hausdorff distance over the bounding-box diagonal.
    hausdorff: f64,
    /// Roy et al. colour RMSE (0–255); null without colour.
    roy_rmse: Option<f64>,
    /// Lindstrom–Turk luma RMSE (0–255) over 24 views.
    image_rmse: f64,
}

#[derive(Serialize, ToSchema)]
struct Texture<'a> {
    id: i64,
    /// `cell` or `colour`.
    kind: &'a str,
    /// Which image of the mapping: `cell`, `colour` or `colour_low`.
    role: &'a str,
    /// `image/png` or `image/jpeg`.
    media_type: &'a str,
    bytes: u64,
    width: Option<u32>,
    height: Option<u32>,
    url: String,
}

/// How the model is coloured.
#[derive(Serialize, ToSchema)]
#[serde(tag = "mode", rename_all = "lowercase")]
#[allow(
    clippy::large_enum_variant,
    reason = "one per manifest, serialised at once; a boxed variant would be described as allOf"
)]
enum Colour<'a> {
    /// Colour textures reached through a cubic cell complex
    /// (`codec/colour/CCC.md`), the same for every level: the viewer loads
    /// the cell texture and the low-resolution colour texture after the base
    /// mesh, then the full-resolution one.
    Ccc {
        #[schema(value_type = CccParameters)]
        parameters: &'a serde_json::Value,
        cell_texture: Texture<'a>,
        colour_texture: Texture<'a>,
        colour_texture_low: Texture<'a>,
    },
    /// Per-vertex colour travels in the stream.
    Vertex,
    None,
}

// Served as ingest stored it, from `vitrine_colour::ccc::CccParameters`:
// these types only describe it (the codec crate knows nothing of OpenAPI),
// and tests/service/spec.rs checks real manifests against them.
/// The cubic cell complex: grid, cell texture layout, tiles and atlas
/// (`codec/colour/CCC.md`, "Parameters").
#[derive(ToSchema)]
#[allow(dead_code)]
struct CccParameters {
    version: u32,
    /// World position of the grid's minimum corner.
    origin: [f32; 3],
    /// Edge of one cube, model units.
    cell_size: f32,
    dims: [u32; 3],
    cells: u32,
    cell_texture: CellTextureLayout,
    tile_size: u32,
    gutter: u32,
    atlas: AtlasLayout,
    low_res_factor: u32,
    fallback_colour: [u8; 3],
}

#[derive(ToSchema)]
#[allow(dead_code)]
struct CellTextureLayout {
    width: u32,
    height: u32,
    cells_offset: u32,
}

#[derive(ToSchema)]
#[allow(dead_code)]
struct AtlasLayout {
    width: u32,
    height: u32,
    tiles_per_row: u32,
    tiles: u32,
}

#[derive(Serialize, ToSchema)]
struct ManifestVisitor {
    audience: Audience,
    device: DeviceClass,
    device_source: DeviceSource,
}

/// `query` when `?device=` was given, else `hints`.
#[derive(Serialize, ToSchema)]
#[serde(rename_all = "lowercase")]
enum DeviceSource {
    Query,
    Hints,
}

#[derive(Serialize, ToSchema)]
struct ManifestCap {
    level: u32,
    reason: Option<CapReason>,
    limits: LevelCap,
    /// Set when load sets the cap: when to fetch the manifest again.
    retry_after_s: Option<u64>,
    load_pressure: u8,
    load_steps: u8,
}

pub fn build<'a>(
    state: &AppState,
    record: &'a ModelRecord,
    visitor: &Visitor,
    cap: LevelCap,
) -> Manifest<'a> {
    let pressure = state.load().pressure();
    Manifest {
        slug: &record.slug,
        version: record.version,
        title: &record.title,
        description: &record.description,
        language: record.texts.language.as_deref(),
        translations: &record.texts.translations,
        kind: record.kind,
        compression_id: record.compression_id,
        stream_format: record.stream_format,
        quantization_bits: record.quantization_bits,
        has_colour: record.has_colour,
        last_level: record.batch_count(),
        good_enough_level: good_enough_level(record, &state.config().caps),
        levels: levels(record, cap),
        parts: (record.kind == ModelKind::Mesh
            && record.stream_format == vitrine_codec::CHARTED_VERSION)
            .then(|| format!("/api/compressions/{}/parts", record.compression_id)),
        nested_parts: (record.kind == ModelKind::Mesh
            && record.stream_format == vitrine_codec::NESTED_VERSION)
            .then(|| format!("/api/compressions/{}/parts", record.compression_id)),
        quality: quality(record),
        study_results: record
            .has_study
            .then(|| format!("/api/study/{}/results", record.slug)),
        colour: colour(record),
        textures: record.textures.iter().map(texture).collect(),
        visitor: ManifestVisitor {
            audience: visitor.audience,
            device: visitor.device,
            device_source: if visitor.device_explicit {
                DeviceSource::Query
            } else {
                DeviceSource::Hints
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
        up: record.curation.up_axis.map_or("y", |a| a.name()),
        unit: record.curation.unit.as_deref(),
        bounds: record.curation.bounds.map(|b| ManifestBounds {
            min: b.min,
            max: b.max,
        }),
        thumbnail: record
            .curation
            .thumbnail_sha256
            .is_some()
            .then(|| super::curator::thumbnail::url(&record.slug, record.version)),
        rights: ManifestRights {
            credit: record.curation.rights.credit.as_deref(),
            licence: record.curation.rights.licence,
        },
        download: download(record, cap.level),
    }
}

/// The GLB a visitor may take: the capped level, sized as the writer lays
/// it out plus its JSON chunk's allowance.
fn download(record: &ModelRecord, level: u32) -> Option<ManifestDownload> {
    if !record.policy.downloads || record.kind != ModelKind::Mesh {
        return None;
    }
    let l = record.levels.get(level as usize)?;
    let bin = glb_bin_bytes(l.vertices as usize, l.faces as usize, record.has_colour);
    Some(ManifestDownload {
        url: format!("/api/models/{}/download.glb?level={level}", record.slug),
        level,
        bytes: bin as u64 + GLB_JSON_ALLOWANCE,
    })
}

/// About what a download's JSON chunk and headers take (the accessors,
/// names, rights and the XMP packet): 1–2 KB.
const GLB_JSON_ALLOWANCE: u64 = 2048;

fn levels(record: &ModelRecord, cap: LevelCap) -> Vec<ManifestLevel> {
    let id = record.compression_id;
    record
        .levels
        .iter()
        .enumerate()
        .map(|(k, l)| ManifestLevel {
            level: k as u32,
            vertices: l.vertices,
            faces: l.faces,
            points: (record.kind == ModelKind::Points).then_some(l.vertices),
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
        .collect()
}

/// Every level's point, or none when any level was not measured.
fn quality(record: &ModelRecord) -> Option<Vec<LevelQuality>> {
    record
        .levels
        .iter()
        .enumerate()
        .map(|(k, l)| {
            l.metrics().map(|m| LevelQuality {
                level: k as u32,
                vertices: l.vertices,
                hausdorff: m.hausdorff,
                roy_rmse: m.roy_rmse,
                image_rmse: m.image_rmse,
            })
        })
        .collect()
}

fn texture(t: &TextureRef) -> Texture<'_> {
    Texture {
        id: t.id,
        kind: &t.kind,
        role: &t.role,
        media_type: &t.media_type,
        bytes: t.bytes,
        width: t.width,
        height: t.height,
        url: format!("/api/textures/{}", t.id),
    }
}

fn colour(record: &ModelRecord) -> Colour<'_> {
    let role = |r: &str| record.textures.iter().find(|t| t.role == r).map(texture);
    match (
        &record.mapping,
        role("cell"),
        role("colour"),
        role("colour_low"),
    ) {
        (Some(mapping), Some(cell_texture), Some(colour_texture), Some(colour_texture_low)) => {
            Colour::Ccc {
                parameters: &mapping.parameters,
                cell_texture,
                colour_texture,
                colour_texture_low,
            }
        }
        _ if record.has_colour => Colour::Vertex,
        _ => Colour::None,
    }
}
