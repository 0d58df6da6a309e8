//! Ingest: encode a mesh and store the model, its compression, base mesh and
//! every refinement batch in one transaction. Nothing is visible until the
//! commit; a crash or kill before it leaves no trace. With
//! [`IngestOptions::quality`], every level is measured against the original
//! first (outside the transaction) and the curve is stored in the level rows.

use crate::source::{default_colour_mode, read_back, QualityReference};
use crate::storage::{
    valid_slug, LevelMetrics, NewCompression, NewLevel, NewModel, NewTexture, NewTextureMapping,
    OnExisting, Storage, StoredModel,
};
use anyhow::{bail, Context};
use serde_json::json;
use std::time::{Duration, Instant};
use vitrine_codec::{BaseTarget, EncodeOptions, Encoded, IndexedMesh, StreamIndex};
use vitrine_colour::ccc::{CccOptions, CccParameters, CccReport, TextureMapping};
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
    /// How colour travels (`ccc`, `vertex`, `vertex-metric`, `none`; see
    /// `vitrine_colour::ColourMode`). `None`: `vertex` when the mesh has
    /// colour or a texture, else `none`.
    pub colour: Option<ColourMode>,
    /// The cell complex's options, in `ccc` mode.
    pub ccc: CccOptions,
    /// Measure every level against the original before storing
    /// (`vitrine_quality::stream_quality`: Hausdorff, Roy colour RMSE,
    /// 24-view image RMSE). About a second per level at 50k vertices, so off
    /// by default. Only [`ingest_coloured`] and [`ingest_mesh`] can measure:
    /// [`ingest_encoded`] has no original.
    pub quality: Option<QualityOptions>,
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
    /// The complex, in `ccc` mode.
    pub ccc: Option<CccReport>,
    /// The quality curve, when it was measured.
    pub quality: Option<MeasuredQuality>,
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
    let source = source_info(&meta, &mesh);
    let mode = options
        .colour
        .unwrap_or_else(|| default_colour_mode(&mesh, texture.as_ref()));
    let (encode_options, ccc) = (options.encode.clone(), options.ccc.clone());
    let quality_options = options.quality;
    let (encoded, mapping, encode_time, quality) =
        tokio::task::spawn_blocking(move || -> anyhow::Result<_> {
            let started = Instant::now();
            let (encoded, mapping) = encode_coloured(
                &mesh,
                texture.as_ref(),
                mode,
                &ccc,
                vitrine_codec::Encoder::new(encode_options),
            )
            .context("encoding failed")?;
            let encode_time = started.elapsed();
            // Before the transaction: measuring takes seconds, and a write
            // transaction should not stay open (SQLite holds its one writer lock).
            let quality = quality_options
                .map(|q| measure_quality(&encoded.bytes, mapping.as_ref(), mesh, texture, &q))
                .transpose()
                .context("measuring quality")?;
            Ok((encoded, mapping, encode_time, quality))
        })
        .await
        .context("encoder task failed")??;
    let mut options = options.clone();
    options.colour = Some(mode);
    store(
        storage,
        &encoded,
        encode_time,
        mapping.as_ref(),
        quality,
        meta,
        source,
        &options,
    )
    .await
}

/// Measures every level of `stream` against the original: the repaired mesh
/// with per-vertex colour (sampled from the texture for a textured scan), and
/// the texture itself for the image metric. In `ccc` mode colour at a level
/// is the complex's lookup, read back from the stored images as the viewer
/// reads them.
fn measure_quality(
    stream: &[u8],
    mapping: Option<&TextureMapping>,
    mesh: IndexedMesh,
    texture: Option<TexturedSurface>,
    options: &QualityOptions,
) -> anyhow::Result<MeasuredQuality> {
    let started = Instant::now();
    let complex = mapping
        .map(read_back)
        .transpose()
        .context("reading back the cell complex")?;
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
    let final_level = encoded.header.final_level();
    let source = meta.source.clone().unwrap_or(SourceInfo {
        name: String::new(),
        vertices: u64::from(final_level.vertices),
        faces: u64::from(final_level.faces),
        repair: None,
    });
    store(
        storage,
        encoded,
        encode_time,
        mapping,
        None,
        meta,
        source,
        options,
    )
    .await
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

#[allow(clippy::too_many_arguments)]
async fn store(
    storage: &dyn Storage,
    encoded: &Encoded,
    encode_time: Duration,
    mapping: Option<&TextureMapping>,
    quality: Option<MeasuredQuality>,
    meta: ModelMeta,
    source: SourceInfo,
    options: &IngestOptions,
) -> anyhow::Result<IngestReport> {
    let mapping = mapping
        .map(new_mapping)
        .transpose()
        .context("the colour mapping is not storable")?;
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
    if let Some(q) = &quality {
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
    let full = index.header.final_level();
    let level = |k: usize, range: &std::ops::Range<usize>| NewLevel {
        vertices: levels[k].vertices,
        faces: levels[k].faces,
        bytes: encoded.bytes[range.clone()].to_vec(),
        metrics: quality.as_ref().map(|q| LevelMetrics {
            hausdorff: q.levels[k].hausdorff,
            image_rmse: q.levels[k].image_rmse,
            roy_rmse: q.levels[k].roy_rmse,
        }),
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
            options: encode_options_json(&options.encode, options.colour, &options.ccc).to_string(),
            stats: json!({
                "bits_per_vertex": encoded.bytes.len() as f64 * 8.0 / f64::from(full.vertices.max(1)),
                "encode_ms": encode_time.as_millis() as u64,
                "repair": source.repair,
                "ccc": mapping.as_ref().map(|m| m.1),
                // The curve itself is in the level rows.
                "quality": quality.as_ref().map(|q| json!({
                    "image_size": q.options.image_size,
                    "hausdorff_samples": q.options.hausdorff_samples,
                    "ms": q.time.as_millis() as u64,
                })),
            })
            .to_string(),
            quantization_bits: index.header.quantization.bits,
            has_colour: index.header.has_colour,
            stream_bytes: encoded.bytes.len() as u64,
            encode_ms: encode_time.as_millis() as u64,
            base: level(0, &index.base),
            batches: index.batches.iter().enumerate().map(|(k, r)| level(k + 1, r)).collect(),
        },
        mapping: mapping.as_ref().map(|m| m.0.clone()),
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
        ccc: mapping.map(|m| m.1),
        quality,
    })
}

fn encode_options_json(
    o: &EncodeOptions,
    colour: Option<ColourMode>,
    ccc: &CccOptions,
) -> serde_json::Value {
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

/// The rows of a mapping, after checking that each image is what the
/// parameters say: a PNG of the cell texture's size (8-bit RGB) and two
/// JPEGs of the atlas's full and reduced size.
fn new_mapping(
    m: &TextureMapping,
) -> anyhow::Result<(NewTextureMapping, vitrine_colour::ccc::CccReport)> {
    let p: &CccParameters = &m.parameters;
    if p.version != 1 {
        bail!("CCC version {} is not supported (1 is)", p.version);
    }
    if p.low_res_factor == 0 || p.cell_size.is_nan() || p.cell_size <= 0.0 {
        bail!("CCC parameters have a zero low-resolution factor or cell size");
    }
    let grid = u64::from(p.dims[0]) * u64::from(p.dims[1]) * u64::from(p.dims[2]);
    let cell_texels = u64::from(p.cell_texture.width) * u64::from(p.cell_texture.height);
    if u64::from(p.cell_texture.cells_offset) != grid || grid + 4 * u64::from(p.cells) > cell_texels
    {
        bail!(
            "cell texture {}×{} cannot hold a {}×{}×{} grid and {} cells at offset {}",
            p.cell_texture.width,
            p.cell_texture.height,
            p.dims[0],
            p.dims[1],
            p.dims[2],
            p.cells,
            p.cell_texture.cells_offset
        );
    }
    let (w, h, depth, colour_type) =
        image_size::png(&m.cell_png).context("the cell texture is not a PNG")?;
    if (w, h) != (p.cell_texture.width, p.cell_texture.height) || (depth, colour_type) != (8, 2) {
        bail!(
            "the cell texture is {w}×{h} (bit depth {depth}, colour type {colour_type}); \
             the parameters say {}×{} 8-bit RGB",
            p.cell_texture.width,
            p.cell_texture.height
        );
    }
    let full = (p.atlas.width, p.atlas.height);
    let low = (
        p.atlas.width.div_ceil(p.low_res_factor),
        p.atlas.height.div_ceil(p.low_res_factor),
    );
    for (what, bytes, want) in [
        ("colour texture", &m.colour_jpeg, full),
        ("low-resolution colour texture", &m.colour_low_jpeg, low),
    ] {
        let size = image_size::jpeg(bytes).with_context(|| format!("the {what} is not a JPEG"))?;
        if size != want {
            bail!(
                "the {what} is {}×{}; the parameters say {}×{}",
                size.0,
                size.1,
                want.0,
                want.1
            );
        }
    }
    let texture = |kind, media_type, (width, height): (u32, u32), bytes: &Vec<u8>| NewTexture {
        kind,
        media_type,
        width,
        height,
        bytes: bytes.clone(),
    };
    Ok((
        NewTextureMapping {
            parameters: serde_json::to_string(p)?,
            cell: texture("cell", "image/png", (w, h), &m.cell_png),
            colour: texture("colour", "image/jpeg", full, &m.colour_jpeg),
            colour_low: texture("colour", "image/jpeg", low, &m.colour_low_jpeg),
        },
        m.report,
    ))
}

/// Image sizes from the headers, without decoding.
mod image_size {
    use anyhow::{bail, Context};

    /// Width, height, bit depth and colour type from the IHDR chunk.
    pub fn png(bytes: &[u8]) -> anyhow::Result<(u32, u32, u8, u8)> {
        const SIGNATURE: &[u8] = b"\x89PNG\r\n\x1a\n";
        if bytes.len() < 33 || &bytes[..8] != SIGNATURE || &bytes[12..16] != b"IHDR" {
            bail!("no PNG signature and IHDR chunk");
        }
        let be = |at: usize| {
            u32::from_be_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]])
        };
        Ok((be(16), be(20), bytes[24], bytes[25]))
    }

    /// Width and height from the first start-of-frame marker.
    pub fn jpeg(bytes: &[u8]) -> anyhow::Result<(u32, u32)> {
        if bytes.get(..2) != Some(&[0xff, 0xd8]) {
            bail!("no start-of-image marker");
        }
        let mut at = 2;
        loop {
            let marker = bytes.get(at..at + 4).context("no start-of-frame marker")?;
            if marker[0] != 0xff {
                bail!("damaged marker at byte {at}");
            }
            if marker[1] == 0xff {
                at += 1; // fill byte
                continue;
            }
            let len = usize::from(u16::from_be_bytes([marker[2], marker[3]]));
            // SOF0–SOF15 except DHT (C4), JPG (C8) and DAC (CC).
            if (0xc0..=0xcf).contains(&marker[1]) && ![0xc4, 0xc8, 0xcc].contains(&marker[1]) {
                let frame = bytes
                    .get(at + 5..at + 9)
                    .context("truncated start of frame")?;
                let height = u32::from(u16::from_be_bytes([frame[0], frame[1]]));
                let width = u32::from(u16::from_be_bytes([frame[2], frame[3]]));
                return Ok((width, height));
            }
            at += 2 + len;
        }
    }
}
