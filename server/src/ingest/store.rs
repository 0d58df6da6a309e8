//! The transaction: the model, its compression with the base mesh and every
//! refinement batch, and the colour mapping, staged together and committed.

use super::mapping::new_mapping;
use super::{
    threshold_name, Curated, FeatureSummary, IngestOptions, IngestReport, MeasuredQuality,
    ModelMeta, SourceInfo,
};
use crate::storage::{
    LevelMetrics, ModelKind, NewCompression, NewLevel, NewModel, PartRecord, SplitRecord, Storage,
    StoredModel,
};
use anyhow::{bail, Context};
use serde_json::json;
use std::ops::Range;
use std::time::Duration;
use vitrine_codec::{BaseTarget, Encoded, StreamIndex};
use vitrine_colour::ccc::{CccReport, TextureMapping};
use vitrine_colour::ColourMode;
use vitrine_quality::LevelQuality;

/// What an ingest made of the mesh: the stream, and what was built and
/// measured beside it.
pub(super) struct Product<'a> {
    pub encoded: &'a Encoded,
    pub encode_time: Duration,
    pub mapping: Option<&'a TextureMapping>,
    pub quality: Option<MeasuredQuality>,
    pub features: Option<FeatureSummary>,
    /// Up axis, bounds, sampled Hausdorff distances and thumbnail.
    pub curated: Option<Curated>,
}

pub(super) async fn store(
    storage: &dyn Storage,
    product: Product<'_>,
    meta: ModelMeta,
    source: SourceInfo,
    options: &IngestOptions,
) -> anyhow::Result<IngestReport> {
    let mapping = product
        .mapping
        .map(new_mapping)
        .transpose()
        .context("the colour mapping is not storable")?;
    let index = StreamIndex::parse(&product.encoded.bytes)
        .context("encoder produced an unreadable stream")?;
    check_levels(&index, &meta, product.quality.as_ref())?;
    let (parts, splits) = super::parts::measure(&product.encoded.bytes, &index).await?;
    let (mapping, ccc) = mapping.unzip();
    let curated = product.curated.as_ref();
    let new = NewModel {
        slug: meta.slug.clone(),
        title: meta.title.clone(),
        description: meta.description.clone(),
        policy: meta.policy.clone(),
        kind: ModelKind::Mesh,
        good_enough_level: meta.good_enough_level,
        on_existing: meta.on_existing,
        source_name: (!source.name.is_empty()).then(|| source.name.clone()),
        source_vertices: source.vertices,
        source_faces: source.faces,
        compression: compression(
            &product,
            &index,
            ccc.as_ref(),
            &source,
            options,
            (parts, splits),
        ),
        mapping,
        up_axis: curated.map(|c| c.up),
        unit: meta.unit.clone(),
        rights: meta.rights.clone(),
        language: meta.language.clone(),
        bounds: curated.map(|c| c.bounds),
        thumbnail: curated.and_then(|c| c.thumbnail.clone()),
    };
    let stored = stage_and_commit(storage, &new, options.pause_before_commit).await?;
    let levels = &index.header.levels;
    Ok(IngestReport {
        stored,
        levels: levels.len(),
        base_vertices: levels[0].vertices,
        full_vertices: index.header.final_level().vertices,
        stream_bytes: product.encoded.bytes.len(),
        encode_time: product.encode_time,
        ccc,
        quality: product.quality,
        features: product.features,
        curation_time: curated.map(|c| c.time),
    })
}

/// The good-enough level and the quality curve, if any, must fit the stream.
fn check_levels(
    index: &StreamIndex,
    meta: &ModelMeta,
    quality: Option<&MeasuredQuality>,
) -> anyhow::Result<()> {
    let levels = &index.header.levels;
    if let Some(level) = meta.good_enough_level {
        if level as usize >= levels.len() {
            bail!(
                "good-enough level {level} is past the last level {}",
                levels.len() - 1
            );
        }
    }
    if let Some(q) = quality {
        let counts = |l: &LevelQuality| (l.vertices, l.faces);
        let measured: Vec<_> = q.levels.iter().map(counts).collect();
        let stored: Vec<_> = levels
            .iter()
            .map(|l| (l.vertices as usize, l.faces as usize))
            .collect();
        if measured != stored {
            bail!("the quality curve does not match the stream's levels");
        }
    }
    Ok(())
}

fn compression(
    product: &Product<'_>,
    index: &StreamIndex,
    ccc: Option<&CccReport>,
    source: &SourceInfo,
    options: &IngestOptions,
    (parts, splits): (Vec<PartRecord>, Vec<SplitRecord>),
) -> NewCompression {
    let bytes = &product.encoded.bytes;
    let level = |k: usize, range: &Range<usize>| new_level(product, index, k, range);
    NewCompression {
        codec_version: index.header.version,
        options: options_json(options).to_string(),
        stats: stats_json(product, index, ccc, source).to_string(),
        quantization_bits: index.header.quantization.bits,
        has_colour: index.header.has_colour,
        stream_bytes: bytes.len() as u64,
        encode_ms: product.encode_time.as_millis() as u64,
        base: level(0, &index.base),
        batches: index
            .batches
            .iter()
            .enumerate()
            .map(|(k, r)| level(k + 1, r))
            .collect(),
        parts,
        splits,
    }
}

/// Level `k`: its counts, its bytes of the stream, and its quality if measured.
fn new_level(
    product: &Product<'_>,
    index: &StreamIndex,
    k: usize,
    range: &Range<usize>,
) -> NewLevel {
    let levels = &index.header.levels;
    NewLevel {
        vertices: levels[k].vertices,
        faces: levels[k].faces,
        bytes: product.encoded.bytes[range.clone()].to_vec(),
        metrics: product.quality.as_ref().map(|q| LevelMetrics {
            hausdorff: q.levels[k].hausdorff,
            image_rmse: q.levels[k].image_rmse,
            roy_rmse: q.levels[k].roy_rmse,
        }),
        hausdorff: product
            .curated
            .as_ref()
            .and_then(|c| c.hausdorff.as_ref())
            .and_then(|h| h.get(k).copied()),
    }
}

fn stats_json(
    product: &Product<'_>,
    index: &StreamIndex,
    ccc: Option<&CccReport>,
    source: &SourceInfo,
) -> serde_json::Value {
    let full = index.header.final_level();
    json!({
        "bits_per_vertex": product.encoded.bytes.len() as f64 * 8.0 / f64::from(full.vertices.max(1)),
        "encode_ms": product.encode_time.as_millis() as u64,
        "repair": source.repair,
        "ccc": ccc,
        "features": product.features,
        // The curve itself is in the level rows.
        "quality": product.quality.as_ref().map(|q| json!({
            "image_size": q.options.image_size,
            "hausdorff_samples": q.options.hausdorff_samples,
            "ms": q.time.as_millis() as u64,
        })),
    })
}

pub(super) async fn stage_and_commit(
    storage: &dyn Storage,
    new: &NewModel,
    pause_before_commit: Option<Duration>,
) -> anyhow::Result<StoredModel> {
    let staged = storage
        .stage_model(new)
        .await
        .with_context(|| format!("storing {:?}", new.slug))?;
    if let Some(pause) = pause_before_commit {
        tracing::info!(?pause, "pausing before commit");
        eprintln!(
            "vitrine: staged {:?}, pausing {} ms before commit",
            new.slug,
            pause.as_millis()
        );
        tokio::time::sleep(pause).await;
    }
    staged
        .commit()
        .await
        .with_context(|| format!("committing {:?}", new.slug))
}

/// The options as recorded with the compression: the encoder's, the
/// colour mode's and the guards'.
fn options_json(options: &IngestOptions) -> serde_json::Value {
    let (o, colour, ccc) = (&options.encode, options.colour, &options.ccc);
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
        "guards": options.guards.names(),
        "feature_threshold": options.guards.features.map(threshold_name),
        "feature_setting": options.guards.features.map(|_| options.guards.feature_setting.name()),
        "colour": colour.map(ColourMode::name),
        "ccc": (colour == Some(ColourMode::Ccc)).then(|| json!({
            "cell_size": ccc.cell_size,
            "tile_size": ccc.tile_size,
            "jpeg_quality": ccc.jpeg_quality,
            "low_res_factor": ccc.low_res_factor,
            "max_atlas_side": ccc.max_atlas_side,
        })),
    })
}
