//! Rows as the service sees them.

use serde::Serialize;

pub use super::curator::{
    parse_credit, parse_licence, AnnotationRecord, AnnotationText, AnnotationTranslations, Bounds,
    JobRecord, JobState, Licence, NewAnnotation, NewJob, Rights, ThumbnailPayload, UpAxis,
    VersionRecord, LICENCES, MAX_CREDIT_BYTES,
};

/// Who may fetch how much of a model (table `audience_policy`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AudiencePolicy {
    pub name: String,
    /// Visitors without a token may see the model at all.
    pub public_access: bool,
    /// The public may reach the highest level with at most this fraction of
    /// the full level's vertices.
    pub public_max_vertex_fraction: f64,
    pub public_full_resolution: bool,
    pub token_full_resolution: bool,
    /// Levels within the visitor's cap may be downloaded as GLB.
    pub downloads: bool,
}

/// Counts after one level; level 0 is the base mesh.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LevelRecord {
    pub vertices: u32,
    pub faces: u32,
    /// Size of the payload that produces this level.
    pub bytes: u64,
    /// Hex SHA-256 of that payload: its strong ETag.
    pub sha256: String,
    /// Quality against the original, when measured at ingest (`--quality`):
    /// symmetric Hausdorff distance over the bounding-box diagonal.
    pub hausdorff: Option<f64>,
    /// Lindstrom–Turk image RMSE (0–255) over 24 views (column `rmse`).
    pub rmse: Option<f64>,
    /// Roy et al. colour RMSE (0–255), when both sides have colour.
    pub roy_rmse: Option<f64>,
}

impl LevelRecord {
    /// The level's measured quality, if it was measured.
    pub fn metrics(&self) -> Option<LevelMetrics> {
        Some(LevelMetrics {
            hausdorff: self.hausdorff?,
            image_rmse: self.rmse?,
            roy_rmse: self.roy_rmse,
        })
    }
}

/// One level's quality against the original (`vitrine_quality`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct LevelMetrics {
    /// Symmetric Hausdorff distance over the bounding-box diagonal.
    pub hausdorff: f64,
    /// Lindstrom–Turk luma RMSE (0–255) over 24 views.
    pub image_rmse: f64,
    /// Roy et al. colour RMSE (0–255), when both sides have colour.
    pub roy_rmse: Option<f64>,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TextureRef {
    pub id: i64,
    /// `"cell"` or `"colour"` (column `texture.kind`).
    pub kind: String,
    /// Which image of the mapping: `"cell"`, `"colour"` or `"colour_low"`.
    pub role: String,
    pub media_type: String,
    pub bytes: u64,
    pub width: Option<u32>,
    pub height: Option<u32>,
}

/// The colour mapping (cubic cell complex) a compression uses.
#[derive(Clone, Debug, PartialEq)]
pub struct MappingRecord {
    pub id: i64,
    /// The complex's parameters (`codec/colour/CCC.md`), as stored.
    pub parameters: serde_json::Value,
}

/// What a model version is (column `model.kind`): a mesh stream
/// (`codec/core/FORMAT.md`) or a point stream (`codec/points/FORMAT.md`),
/// stored in the same tables (see the migration `model_kind`).
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, utoipa::ToSchema, clap::ValueEnum,
)]
#[serde(rename_all = "lowercase")]
pub enum ModelKind {
    #[default]
    Mesh,
    Points,
}

impl ModelKind {
    pub fn name(self) -> &'static str {
        match self {
            ModelKind::Mesh => "mesh",
            ModelKind::Points => "points",
        }
    }

    pub fn parse(name: &str) -> Option<ModelKind> {
        match name {
            "mesh" => Some(ModelKind::Mesh),
            "points" => Some(ModelKind::Points),
            _ => None,
        }
    }

    /// The newest stream format version this build writes for this kind.
    pub fn reads(self) -> u8 {
        match self {
            ModelKind::Mesh => vitrine_codec::VERSION,
            ModelKind::Points => vitrine_points::stream::VERSION,
        }
    }

    /// Whether this build decodes streams of `version` for this kind (a
    /// mesh: the plain format, the charted one and the nested one).
    pub fn can_read(self, version: u8) -> bool {
        match self {
            ModelKind::Mesh => {
                version == vitrine_codec::VERSION
                    || version == vitrine_codec::CHARTED_VERSION
                    || version == vitrine_codec::NESTED_VERSION
            }
            ModelKind::Points => vitrine_points::stream::VERSIONS.contains(&version),
        }
    }
}

/// A visible model version and the compression the service serves for it.
#[derive(Clone, Debug, PartialEq)]
pub struct ModelRecord {
    pub model_id: i64,
    pub slug: String,
    pub version: u32,
    /// Mesh or point cloud.
    pub kind: ModelKind,
    pub title: String,
    pub description: String,
    pub policy: AudiencePolicy,
    /// Set by the quality study; `None` means the 20 % rule.
    pub good_enough_level: Option<u32>,
    pub created_at_ms: i64,
    pub compression_id: i64,
    pub quantization_bits: u8,
    pub has_colour: bool,
    /// Stream format version the payloads were encoded in (column
    /// `compression.codec_version`, `codec/core/FORMAT.md`).
    pub stream_format: u8,
    /// `levels[0]` is the base mesh, `levels[k]` the mesh after batch `k`
    /// (for a point cloud: `vertices` counts the points so far, `faces` is 0).
    pub levels: Vec<LevelRecord>,
    /// The CCC colour mapping, if the model has one.
    pub mapping: Option<MappingRecord>,
    /// Up axis, unit, bounds and thumbnail, when recorded at ingest.
    pub curation: Curation,
    /// The mapping's images, by id.
    pub textures: Vec<TextureRef>,
    /// The default language of the texts and their translations.
    pub texts: super::ModelTexts,
    /// A quality study was begun on this version (its results may be asked).
    pub has_study: bool,
}

/// What an ingest records for curators and the viewer beside the stream:
/// all `None` for versions ingested before issue 22.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Curation {
    /// Which model axis points up.
    pub up_axis: Option<UpAxis>,
    /// The unit of model coordinates (`mm`, `cm`, `m`, `in`).
    pub unit: Option<String>,
    /// Bounds of the stream's (dequantized) positions.
    pub bounds: Option<Bounds>,
    /// The thumbnail's digest, when the version has one.
    pub thumbnail_sha256: Option<String>,
    /// Credit line and licence, when recorded.
    pub rights: Rights,
}

impl ModelRecord {
    /// Number of refinement batches (= index of the full-resolution level).
    pub fn batch_count(&self) -> u32 {
        self.levels.len().saturating_sub(1) as u32
    }

    /// Whether this build's decoder (and so its viewer) reads the stored
    /// payloads: streams of another format version must be re-ingested.
    pub fn servable(&self) -> bool {
        self.kind.can_read(self.stream_format)
    }
}

/// One line of the model list.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ModelSummary {
    pub slug: String,
    pub title: String,
    pub version: u32,
    /// Mesh or point cloud.
    pub kind: ModelKind,
    #[serde(skip)]
    pub public_access: bool,
    pub batch_count: u32,
    pub created_at_ms: i64,
    /// Stream format version of its payloads (`compression.codec_version`).
    pub stream_format: u8,
    #[serde(skip)]
    pub has_thumbnail: bool,
    /// The visible version's licence identifier, when stated (as stored:
    /// `vitrine models` lists it for a rights audit).
    #[serde(skip)]
    pub licence: Option<String>,
    /// Its parts are recorded (`stream_part`): a charted stream ingested
    /// before they were has none, and streams whole batches only.
    #[serde(skip)]
    pub has_parts: bool,
    /// The BCP 47 tag of `title`, when stated.
    #[serde(skip)]
    pub language: Option<String>,
    /// The translated titles (only `title` is read for the list).
    #[serde(skip)]
    pub translations: super::Translations,
}

impl ModelSummary {
    /// See [`ModelRecord::servable`].
    pub fn servable(&self) -> bool {
        self.kind.can_read(self.stream_format)
    }
}

/// A texture and the model whose mapping uses it (a public one, if any).
#[derive(Clone, Debug)]
pub struct TexturePayload {
    pub media_type: String,
    pub sha256: String,
    pub bytes: Vec<u8>,
    pub model_slug: String,
    pub public_access: bool,
}

/// A live token.
#[derive(Clone, Debug, PartialEq)]
pub struct TokenGrant {
    pub id: i64,
    pub label: String,
    /// `None`: every model.
    pub model_slug: Option<String>,
    pub scope: TokenScope,
}

/// What a token lets its holder do (column `access_token.scope`). The scopes
/// are separate: a researcher token opens researcher-only levels and cannot
/// publish or annotate; a curator token publishes and annotates but sees
/// what the public sees.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, serde::Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum TokenScope {
    Researcher,
    Curator,
}

impl TokenScope {
    pub fn name(self) -> &'static str {
        match self {
            TokenScope::Researcher => "researcher",
            TokenScope::Curator => "curator",
        }
    }

    pub fn parse(name: &str) -> Option<TokenScope> {
        match name {
            "researcher" => Some(TokenScope::Researcher),
            "curator" => Some(TokenScope::Curator),
            _ => None,
        }
    }
}

impl TokenGrant {
    pub fn covers(&self, slug: &str) -> bool {
        self.model_slug.as_deref().is_none_or(|s| s == slug)
    }
}

#[derive(Clone, Debug)]
pub struct NewToken {
    pub token_sha256: String,
    pub scope: TokenScope,
    pub label: String,
    pub model_slug: Option<String>,
    pub expires_at_ms: Option<i64>,
}

/// What to do when the slug already has a version.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OnExisting {
    Refuse,
    NewVersion,
}

/// A payload that produces one level.
#[derive(Clone, Debug)]
pub struct NewLevel {
    pub vertices: u32,
    pub faces: u32,
    pub bytes: Vec<u8>,
    /// Quality against the original, when measured before storing.
    pub metrics: Option<LevelMetrics>,
    /// The sampled Hausdorff distance over the diagonal measured by default
    /// at ingest, stored when `metrics` is `None`.
    pub hausdorff: Option<f64>,
}

/// Everything one ingest writes.
#[derive(Clone, Debug)]
pub struct NewModel {
    pub slug: String,
    pub title: String,
    pub description: String,
    /// Name of an `audience_policy` row.
    pub policy: String,
    /// Mesh or point cloud: says what the compression's payloads are.
    pub kind: ModelKind,
    pub good_enough_level: Option<u32>,
    pub on_existing: OnExisting,
    pub source_name: Option<String>,
    pub source_vertices: u64,
    pub source_faces: u64,
    pub compression: NewCompression,
    /// A CCC colour mapping, stored in the same transaction.
    pub mapping: Option<NewTextureMapping>,
    pub up_axis: Option<UpAxis>,
    /// `mm`, `cm`, `m` or `in`.
    pub unit: Option<String>,
    pub bounds: Option<Bounds>,
    /// Credit line and licence.
    pub rights: Rights,
    /// The BCP 47 tag of the title, description and credit, if stated.
    pub language: Option<String>,
    /// A picture rendered at ingest, stored in the same transaction.
    pub thumbnail: Option<NewThumbnail>,
}

/// A rendered picture of a version (table `thumbnail`).
#[derive(Clone, Debug)]
pub struct NewThumbnail {
    pub media_type: &'static str,
    pub width: u32,
    pub height: u32,
    pub bytes: Vec<u8>,
}

/// An image to store in table `texture`.
#[derive(Clone, Debug)]
pub struct NewTexture {
    /// `"cell"` or `"colour"`.
    pub kind: &'static str,
    pub media_type: &'static str,
    pub width: u32,
    pub height: u32,
    pub bytes: Vec<u8>,
}

/// The three images of a CCC colour mapping and its parameters.
#[derive(Clone, Debug)]
pub struct NewTextureMapping {
    /// Parameters as JSON (`codec/colour/CCC.md`, "Parameters").
    pub parameters: String,
    pub cell: NewTexture,
    pub colour: NewTexture,
    pub colour_low: NewTexture,
}

#[derive(Clone, Debug)]
pub struct NewCompression {
    pub codec_version: u8,
    /// Encoder options as JSON.
    pub options: String,
    /// Statistics as JSON (bits per vertex, timings, repair report, how
    /// quality was measured).
    pub stats: String,
    pub quantization_bits: u8,
    pub has_colour: bool,
    pub stream_bytes: u64,
    pub encode_ms: u64,
    /// Header plus base chunk.
    pub base: NewLevel,
    pub batches: Vec<NewLevel>,
    /// A charted stream's parts (table `stream_part`); empty otherwise.
    pub parts: Vec<PartRecord>,
    /// A nested stream's split entries (table `stream_split`); empty
    /// otherwise.
    pub splits: Vec<SplitRecord>,
}

/// One chart's part of a parted batch (table `stream_part`): what a viewer
/// that refines where the visitor looks fetches instead of whole batches.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct PartRecord {
    /// The batch (1-based), as `refinement_batch.iteration`.
    pub iteration: u32,
    pub chart: u32,
    /// Bytes of the part alone, as served.
    pub bytes: u32,
    /// Vertices it inserts (0: the chart sits this batch out).
    pub inserted: u32,
    /// The largest distance, in model units, from a vertex it inserts to
    /// the chart's coarser surface: the bound occlusion needs.
    pub error: f64,
    /// The distance, in model units, within which 90 % of those vertices
    /// lie (`vitrine_codec::BULK_SHARE`): what a viewer refines by. `None`
    /// for a part measured before it was (the service sends `error`).
    pub bulk_error: Option<f64>,
    /// The chart's phase: 0 in a charted stream (format 5) and for a
    /// nested stream's top charts (format 6).
    pub phase: u32,
    /// The chart's parent, by its position in phase `phase − 1` (format 6,
    /// phase ≥ 1).
    pub parent: Option<u32>,
}

/// One split entry of a nested stream (table `stream_split`): what a viewer
/// fetches to cut a chart that has had all its phase's parts into its
/// children.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct SplitRecord {
    /// The batch whose head holds it: the first of the children's phase.
    pub iteration: u32,
    /// The chart split, by its position in the phase before.
    pub parent: u32,
    /// Its children: `first_child` … `first_child + children − 1` of the
    /// batch's phase.
    pub first_child: u32,
    pub children: u32,
    /// Bytes of the entry, as served.
    pub bytes: u32,
}

/// Ids of a written model version.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StoredModel {
    pub model_id: i64,
    pub compression_id: i64,
    pub version: u32,
}

/// Slugs are URL path segments: 1–64 of `a-z`, `0-9` and `-`, not starting or
/// ending with `-`.
pub fn valid_slug(slug: &str) -> bool {
    (1..=64).contains(&slug.len())
        && slug
            .bytes()
            .all(|b| b.is_ascii_lowercase() || b.is_ascii_digit() || b == b'-')
        && !slug.starts_with('-')
        && !slug.ends_with('-')
}
