//! Ingest: encode a mesh and store the model, its compression, base mesh and
//! every refinement batch in one transaction. Nothing is visible until the
//! commit; a crash or kill before it leaves no trace. With
//! [`IngestOptions::quality`], every level is measured against the original
//! first (outside the transaction) and the curve is stored in the level rows.
//! Point clouds take the same road through [`points::ingest_points`].

pub mod curation;
mod guards;
mod mapping;
mod parts;
pub mod points;
mod store;

pub use guards::{threshold_name, FeatureSetting, FeatureSummary, GuardOptions, Guards};

use crate::source::{default_colour_mode, read_back, QualityReference};
use crate::storage::{
    valid_slug, Bounds, NewThumbnail, OnExisting, Rights, Storage, StoredModel, UpAxis,
};
use anyhow::{bail, Context};
use std::path::Path;
use std::sync::Arc;
use std::time::{Duration, Instant};
use store::{stage_and_commit, store, Product};
use vitrine_codec::{EncodeOptions, Encoded, IndexedMesh, Limits};
use vitrine_colour::ccc::{CccOptions, CccReport, TextureMapping};
use vitrine_colour::{encode_coloured, ColourMode};
use vitrine_mesh::import::TexturedSurface;
use vitrine_quality::{LevelQuality, QualityOptions};

/// What a model is called and who may see it.
#[derive(Clone, Debug)]
pub struct ModelMeta {
    pub slug: String,
    pub title: String,
    pub description: String,
    /// Name of an audience policy: `exhibition` (default), `open`, `researchers`.
    pub policy: String,
    /// From a quality study; `None` uses the 20 % rule.
    pub good_enough_level: Option<u32>,
    pub on_existing: OnExisting,
    /// The file it came from, as imported (before repair).
    pub source: Option<SourceInfo>,
    /// Which model axis points up; `None`: [`curation::detect_up`].
    pub up: Option<UpAxis>,
    /// The unit of model coordinates (`mm`, `cm`, `m`, `in`), if known.
    pub unit: Option<String>,
    /// Credit line and licence.
    pub rights: Rights,
    /// The BCP 47 tag of the title, description and credit, if stated.
    pub language: Option<String>,
}

impl ModelMeta {
    pub fn new(slug: impl Into<String>, title: impl Into<String>) -> ModelMeta {
        ModelMeta {
            slug: slug.into(),
            title: title.into(),
            description: String::new(),
            policy: "exhibition".into(),
            good_enough_level: None,
            on_existing: OnExisting::Refuse,
            source: None,
            up: None,
            unit: None,
            rights: Rights::default(),
            language: None,
        }
    }
}

#[derive(Clone, Debug)]
pub struct SourceInfo {
    /// File name only; the file itself is never stored.
    pub name: String,
    pub vertices: u64,
    pub faces: u64,
    /// What repair changed, as text.
    pub repair: Option<String>,
}

#[derive(Clone, Debug, Default)]
pub struct IngestOptions {
    pub encode: EncodeOptions,
    /// The point stream's options, for a point cloud ([`points`]).
    pub points: vitrine_points::stream::EncodeOptions,
    /// How colour travels (`ccc`, `vertex`, `vertex-metric`, `none`; see
    /// `vitrine_colour::ColourMode`). `None`: `vertex` when the mesh has
    /// colour or a texture, else `none`.
    pub colour: Option<ColourMode>,
    /// The cell complex's options, in `ccc` mode.
    pub ccc: CccOptions,
    /// Decimation guards beside the colour mode's own (the feature guard).
    /// Only [`ingest_coloured`] and [`ingest_mesh`] build them; for
    /// [`ingest_encoded`] they only say what the caller encoded with.
    pub guards: GuardOptions,
    /// Measure every level against the original before storing
    /// (`vitrine_quality::stream_quality`: Hausdorff, Roy colour RMSE,
    /// 24-view image RMSE). About a second per level at 50k vertices, so off
    /// by default. Only [`ingest_coloured`] and [`ingest_mesh`] can measure:
    /// [`ingest_encoded`] has no original.
    pub quality: Option<QualityOptions>,
    /// Test hook: wait this long inside the open transaction before committing.
    pub pause_before_commit: Option<Duration>,
    /// Leave out the sampled Hausdorff distance of every level that ingest
    /// measures by default (its time grows with levels × vertices: seconds
    /// at 20k vertices on a small machine); bounds and thumbnail stay.
    pub skip_hausdorff: bool,
    /// Told each stage as the ingest reaches it (an upload job's progress).
    pub progress: Option<ProgressHook>,
}

/// Called with a stage label and the fraction done (0–1).
#[derive(Clone)]
pub struct ProgressHook(pub Arc<dyn Fn(&'static str, f64) + Send + Sync>);

impl std::fmt::Debug for ProgressHook {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("ProgressHook")
    }
}

impl IngestOptions {
    fn report(&self, stage: &'static str, done: f64) {
        if let Some(hook) = &self.progress {
            (hook.0)(stage, done);
        }
    }
}

/// What [`curation`] measured and rendered, stored with the version.
#[derive(Clone, Debug)]
pub struct Curated {
    pub up: UpAxis,
    pub bounds: Bounds,
    /// Every level's sampled Hausdorff distance over the diagonal, when
    /// there was an original to measure against.
    pub hausdorff: Option<Vec<f64>>,
    pub thumbnail: Option<NewThumbnail>,
    /// How long measuring and rendering took.
    pub time: Duration,
}

#[derive(Clone, Debug)]
pub struct IngestReport {
    pub stored: StoredModel,
    /// Levels including the base.
    pub levels: usize,
    pub base_vertices: u32,
    pub full_vertices: u32,
    pub stream_bytes: usize,
    pub encode_time: Duration,
    /// The complex, in `ccc` mode.
    pub ccc: Option<CccReport>,
    /// The quality curve, when it was measured.
    pub quality: Option<MeasuredQuality>,
    /// What the feature guard kept, when it ran.
    pub features: Option<FeatureSummary>,
    /// How long the default Hausdorff distances and the thumbnail took.
    pub curation_time: Option<Duration>,
}

/// Every level's quality against the original, and how it was measured.
#[derive(Clone, Debug)]
pub struct MeasuredQuality {
    /// One entry per level, base first.
    pub levels: Vec<LevelQuality>,
    pub options: QualityOptions,
    pub time: Duration,
}

/// Encodes `mesh` (already repaired: see `vitrine_mesh::repair::prepare`)
/// and stores it as a new model or model version.
pub async fn ingest_mesh(
    storage: &dyn Storage,
    mesh: IndexedMesh,
    meta: ModelMeta,
    options: &IngestOptions,
) -> anyhow::Result<IngestReport> {
    ingest_coloured(storage, mesh, None, meta, options).await
}

/// [`ingest_mesh`] for a mesh with its file's colour texture, if any: in
/// `ccc` mode the complex samples the texture (else the per-vertex colour),
/// stores its three images and parameters in the same transaction as the
/// model, and the stream carries geometry only; the vertex modes sample the
/// texture at the vertices (`vitrine_colour::encode_coloured`).
pub async fn ingest_coloured(
    storage: &dyn Storage,
    mesh: IndexedMesh,
    texture: Option<TexturedSurface>,
    meta: ModelMeta,
    options: &IngestOptions,
) -> anyhow::Result<IngestReport> {
    check_slug(&meta.slug)?;
    check_unit(meta.unit.as_deref())?;
    let source = source_info(&meta, &mesh);
    let up = meta
        .up
        .unwrap_or_else(|| curation::detect_up(Some(Path::new(&source.name)), &mesh));
    let mode = options
        .colour
        .unwrap_or_else(|| default_colour_mode(&mesh, texture.as_ref()));
    let mut options = options.clone();
    options.colour = Some(mode);
    let task_options = options.clone();
    let encoding =
        tokio::task::spawn_blocking(move || encode_and_measure(mesh, texture, up, &task_options))
            .await
            .context("encoder task failed")??;
    let product = Product {
        encoded: &encoding.encoded,
        encode_time: encoding.encode_time,
        mapping: encoding.mapping.as_ref(),
        quality: encoding.quality,
        features: encoding.features,
        curated: Some(encoding.curated),
    };
    options.report("storing", 0.9);
    store(storage, product, meta, source, &options).await
}

/// The stream, its mapping in `ccc` mode, how long encoding took, the
/// quality curve when asked for, and what the feature guard kept.
struct Encoding {
    encoded: Encoded,
    mapping: Option<TextureMapping>,
    encode_time: Duration,
    quality: Option<MeasuredQuality>,
    features: Option<FeatureSummary>,
    curated: Curated,
}

/// Encodes in `options.colour` (already resolved) under the guards asked
/// for, then measures the levels if asked.
fn encode_and_measure(
    mesh: IndexedMesh,
    texture: Option<TexturedSurface>,
    up: UpAxis,
    options: &IngestOptions,
) -> anyhow::Result<Encoding> {
    let started = Instant::now();
    options.report("encoding", 0.2);
    let mode = options.colour.unwrap_or(ColourMode::None);
    let guards = Guards::new(&mesh, &options.guards, &options.encode)
        .context("building the decimation guards")?;
    let features = guards.features();
    if let Some(f) = &features {
        tracing::info!(
            threshold_degrees = f.threshold_degrees,
            feature_vertices = f.vertices,
            share = f.share,
            relief_gate = f.relief_gate,
            searched = f.searched,
            "{}",
            f.describe()
        );
    }
    let encoder = guards.apply(vitrine_codec::Encoder::new(options.encode.clone()));
    let (encoded, mapping) = encode_coloured(&mesh, texture.as_ref(), mode, &options.ccc, encoder)
        .context("encoding failed")?;
    let encode_time = started.elapsed();
    options.report("measuring", 0.6);
    let curating = Instant::now();
    let complex = mapping
        .as_ref()
        .map(read_back)
        .transpose()
        .context("reading back the cell complex")?;
    let (bounds, hausdorff, full) = if options.skip_hausdorff {
        let full = vitrine_codec::decode(&encoded.bytes, None, Limits::default())
            .context("reading the stream back")?
            .to_mesh();
        (curation::bounds_of(&full), None, full)
    } else {
        let (bounds, distances, full) =
            curation::measure_levels(&encoded.bytes, &mesh, curation::DEFAULT_HAUSDORFF_SAMPLES)?;
        (bounds, Some(distances), full)
    };
    options.report("rendering the thumbnail", 0.8);
    let thumbnail = curation::render_thumbnail(&full, complex.as_ref(), up)?;
    let curated = Curated {
        up,
        bounds,
        hausdorff,
        thumbnail: Some(thumbnail),
        time: curating.elapsed(),
    };
    // Before the transaction: measuring takes seconds, and a write
    // transaction should not stay open (SQLite holds its one writer lock).
    let quality = options
        .quality
        .map(|q| measure_quality(&encoded.bytes, complex, mesh, texture, &q))
        .transpose()
        .context("measuring quality")?;
    Ok(Encoding {
        encoded,
        mapping,
        encode_time,
        quality,
        features,
        curated,
    })
}

/// Measures every level of `stream` against the original: the repaired mesh
/// with per-vertex colour (sampled from the texture for a textured scan), and
/// the texture itself for the image metric. In `ccc` mode colour at a level
/// is the complex's lookup, read back from the stored images as the viewer
/// reads them.
fn measure_quality(
    stream: &[u8],
    complex: Option<vitrine_colour::ccc::CellComplex>,
    mesh: IndexedMesh,
    texture: Option<TexturedSurface>,
    options: &QualityOptions,
) -> anyhow::Result<MeasuredQuality> {
    let started = Instant::now();
    let reference = QualityReference::new(mesh, texture);
    let levels = reference.measure(stream, complex.as_ref(), options)?;
    Ok(MeasuredQuality {
        levels,
        options: *options,
        time: started.elapsed(),
    })
}

/// Stores a stream the caller encoded, with its CCC colour mapping if it has
/// one (built for the same mesh and quantization, and the stream encoded
/// under its guard: `vitrine_colour::ccc::encode_with_ccc`). The mapping's
/// three images and parameters go into the same transaction as the model;
/// they are checked against the parameters first.
pub async fn ingest_encoded(
    storage: &dyn Storage,
    encoded: &Encoded,
    encode_time: Duration,
    mapping: Option<&TextureMapping>,
    meta: ModelMeta,
    options: &IngestOptions,
) -> anyhow::Result<IngestReport> {
    check_slug(&meta.slug)?;
    check_unit(meta.unit.as_deref())?;
    let final_level = encoded.header.final_level();
    let source = meta.source.clone().unwrap_or(SourceInfo {
        name: String::new(),
        vertices: u64::from(final_level.vertices),
        faces: u64::from(final_level.faces),
        repair: None,
    });
    let product = Product {
        encoded,
        encode_time,
        mapping,
        quality: None,
        features: None,
        curated: None,
    };
    store(storage, product, meta, source, options).await
}

fn check_unit(unit: Option<&str>) -> anyhow::Result<()> {
    match unit {
        Some(u) if !curation::UNITS.contains(&u) => {
            bail!("unit {u:?} must be one of mm, cm, m, in")
        }
        _ => Ok(()),
    }
}

fn check_slug(slug: &str) -> anyhow::Result<()> {
    if !valid_slug(slug) {
        bail!("slug {slug:?} must be 1–64 of a-z, 0-9 and '-', not starting or ending with '-'");
    }
    Ok(())
}

fn source_info(meta: &ModelMeta, mesh: &IndexedMesh) -> SourceInfo {
    meta.source.clone().unwrap_or_else(|| SourceInfo {
        name: String::new(),
        vertices: mesh.vertex_count() as u64,
        faces: mesh.face_count() as u64,
        repair: None,
    })
}
