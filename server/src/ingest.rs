//! Ingest: encode a mesh and store the model, its compression, base mesh and
//! every refinement batch in one transaction. Nothing is visible until the
//! commit; a crash or kill before it leaves no trace.

use crate::storage::{
    valid_slug, NewCompression, NewLevel, NewModel, OnExisting, Storage, StoredModel,
};
use anyhow::{bail, Context};
use serde_json::json;
use std::time::{Duration, Instant};
use vitrine_codec::{BaseTarget, EncodeOptions, IndexedMesh, StreamIndex};

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
    /// Test hook: wait this long inside the open transaction before committing.
    pub pause_before_commit: Option<Duration>,
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
}

/// Encodes `mesh` (already repaired: see `vitrine_codec::repair::prepare`)
/// and stores it as a new model or model version.
pub async fn ingest_mesh(
    storage: &dyn Storage,
    mesh: IndexedMesh,
    meta: ModelMeta,
    options: &IngestOptions,
) -> anyhow::Result<IngestReport> {
    if !valid_slug(&meta.slug) {
        bail!(
            "slug {:?} must be 1–64 of a-z, 0-9 and '-', not starting or ending with '-'",
            meta.slug
        );
    }
    let source = meta.source.clone().unwrap_or_else(|| SourceInfo {
        name: String::new(),
        vertices: mesh.vertex_count() as u64,
        faces: mesh.face_count() as u64,
        repair: None,
    });
    let encode_options = options.encode.clone();
    let started = Instant::now();
    let encoded =
        tokio::task::spawn_blocking(move || vitrine_codec::encode(&mesh, &encode_options))
            .await
            .context("encoder task failed")?
            .context("encoding failed")?;
    let encode_time = started.elapsed();
    let index =
        StreamIndex::parse(&encoded.bytes).context("encoder produced an unreadable stream")?;
    let levels = &index.header.levels;
    if let Some(level) = meta.good_enough_level {
        if level as usize >= levels.len() {
            bail!(
                "good-enough level {level} is past the last level {}",
                levels.len() - 1
            );
        }
    }
    let full = index.header.final_level();
    let level = |k: usize, range: &std::ops::Range<usize>| NewLevel {
        vertices: levels[k].vertices,
        faces: levels[k].faces,
        bytes: encoded.bytes[range.clone()].to_vec(),
    };
    let new = NewModel {
        slug: meta.slug.clone(),
        title: meta.title.clone(),
        description: meta.description.clone(),
        policy: meta.policy.clone(),
        good_enough_level: meta.good_enough_level,
        on_existing: meta.on_existing,
        source_name: (!source.name.is_empty()).then(|| source.name.clone()),
        source_vertices: source.vertices,
        source_faces: source.faces,
        compression: NewCompression {
            codec_version: index.header.version,
            options: encode_options_json(&options.encode).to_string(),
            stats: json!({
                "bits_per_vertex": encoded.bytes.len() as f64 * 8.0 / f64::from(full.vertices.max(1)),
                "encode_ms": encode_time.as_millis() as u64,
                "repair": source.repair,
            })
            .to_string(),
            quantization_bits: index.header.quantization.bits,
            has_colour: index.header.has_colour,
            stream_bytes: encoded.bytes.len() as u64,
            encode_ms: encode_time.as_millis() as u64,
            base: level(0, &index.base),
            batches: index.batches.iter().enumerate().map(|(k, r)| level(k + 1, r)).collect(),
        },
    };
    let staged = storage
        .stage_model(&new)
        .await
        .with_context(|| format!("storing {:?}", meta.slug))?;
    if let Some(pause) = options.pause_before_commit {
        tracing::info!(?pause, "pausing before commit");
        eprintln!(
            "vitrine: staged {:?}, pausing {} ms before commit",
            meta.slug,
            pause.as_millis()
        );
        tokio::time::sleep(pause).await;
    }
    let stored = staged
        .commit()
        .await
        .with_context(|| format!("committing {:?}", meta.slug))?;
    Ok(IngestReport {
        stored,
        levels: levels.len(),
        base_vertices: levels[0].vertices,
        full_vertices: full.vertices,
        stream_bytes: encoded.bytes.len(),
        encode_time,
    })
}

fn encode_options_json(o: &EncodeOptions) -> serde_json::Value {
    let base = match o.base {
        BaseTarget::Vertices(n) => json!({ "vertices": n }),
        BaseTarget::Fraction(f) => json!({ "fraction": f }),
    };
    json!({
        "quantization_bits": o.quantization_bits,
        "base": base,
        "min_base_vertices": o.min_base_vertices,
        "max_layers": o.max_layers,
        "min_layer_fraction": o.min_layer_fraction,
        "geometric_guard": o.geometric_guard,
    })
}
