//! Point clouds (issue 21): which files are clouds, reading them, and
//! storing one as a progressive point stream (VPTS, `codec/points/FORMAT.md`)
//! in the tables a mesh stream is stored in: the header with the first
//! level as the base row, every further level as a refinement batch (see
//! the migration `model_kind`). Missing normals are estimated here, once,
//! rather than in every visitor's viewer
//! (docs/bench-log/2026-12-02-session-12-points.md).

use super::{check_slug, check_unit, curation, stage_and_commit, IngestOptions, IngestReport};
use super::{ModelMeta, SourceInfo};
use crate::storage::{ModelKind, NewCompression, NewLevel, NewModel, Storage};
use anyhow::{bail, Context};
use serde_json::json;
use std::io::Read;
use std::path::Path;
use std::time::{Duration, Instant};
use vitrine_points::stream::{self, EncodedPoints};
use vitrine_points::PointCloud;

/// Most points a cloud file may declare (the stream decoder's own budget).
pub fn max_points() -> usize {
    stream::Limits::default().max_points as usize
}

/// How much of a PLY file is read to find its header.
const PLY_HEADER_BYTES: u64 = 64 * 1024;

/// What a file holds, from its name and, for PLY, its header: LAS and LAZ
/// are point clouds, a PLY is one when it declares no faces (nor triangle
/// strips), every other format is a mesh. A PLY whose header cannot be read
/// is left to the mesh importer, whose message says what is wrong.
pub fn detect_kind(path: &Path) -> anyhow::Result<ModelKind> {
    let extension = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    match extension.as_deref() {
        Some("las" | "laz") => Ok(ModelKind::Points),
        Some("ply") => {
            let mut head = Vec::new();
            std::fs::File::open(path)
                .and_then(|f| f.take(PLY_HEADER_BYTES).read_to_end(&mut head))
                .with_context(|| format!("reading {}", path.display()))?;
            Ok(match ply_declares_faces(&head) {
                Some(false) => ModelKind::Points,
                _ => ModelKind::Mesh,
            })
        }
        _ => Ok(ModelKind::Mesh),
    }
}

/// Whether a PLY header declares at least one face or triangle strip;
/// `None` when `head` holds no complete header.
fn ply_declares_faces(head: &[u8]) -> Option<bool> {
    let end = head.windows(10).position(|w| w == b"end_header")?;
    let header = std::str::from_utf8(&head[..end]).ok()?;
    let mut faces = false;
    for line in header.lines() {
        let mut words = line.split_whitespace();
        if words.next() != Some("element") {
            continue;
        }
        let (name, count) = (words.next()?, words.next()?);
        if matches!(name, "face" | "tristrips") && count.parse::<u64>().ok()? > 0 {
            faces = true;
        }
    }
    Some(faces)
}

/// Reads a point cloud file (PLY vertices, faces ignored; LAS; LAZ).
pub fn load_cloud(path: &Path) -> anyhow::Result<PointCloud> {
    vitrine_points::import::import_path(path, max_points())
        .with_context(|| format!("reading {}", path.display()))
}

/// The stream, how long the normals and encoding took, and whether the
/// normals were estimated.
struct Encoding {
    encoded: EncodedPoints,
    normals_estimated: bool,
    normals_time: Duration,
    encode_time: Duration,
    bounds: crate::storage::Bounds,
    thumbnail: crate::storage::NewThumbnail,
}

/// Encodes `cloud` as a point stream (estimating normals when it has none)
/// and stores it as a new model or model version of kind `points`.
pub async fn ingest_points(
    storage: &dyn Storage,
    cloud: PointCloud,
    meta: ModelMeta,
    options: &IngestOptions,
) -> anyhow::Result<IngestReport> {
    check_slug(&meta.slug)?;
    check_unit(meta.unit.as_deref())?;
    cloud
        .validate()
        .context("the point cloud is not encodable")?;
    if cloud.is_empty() {
        bail!("the point cloud has no points");
    }
    let source = meta.source.clone().unwrap_or_else(|| SourceInfo {
        name: String::new(),
        vertices: cloud.len() as u64,
        faces: 0,
        repair: None,
    });
    let up = meta
        .up
        .unwrap_or_else(|| curation::detect_up_of(Some(Path::new(&source.name)), &cloud.positions));
    let task_options = options.clone();
    let encoding = tokio::task::spawn_blocking(move || encode(cloud, up, &task_options))
        .await
        .context("encoder task failed")??;
    let encoded = &encoding.encoded;
    let levels = encoded.level_points.len();
    if let Some(level) = meta.good_enough_level {
        if level as usize >= levels {
            bail!(
                "good-enough level {level} is past the last level {}",
                levels - 1
            );
        }
    }
    options.report("storing", 0.9);
    let new = NewModel {
        slug: meta.slug.clone(),
        title: meta.title.clone(),
        description: meta.description.clone(),
        policy: meta.policy.clone(),
        kind: ModelKind::Points,
        good_enough_level: meta.good_enough_level,
        on_existing: meta.on_existing,
        source_name: (!source.name.is_empty()).then(|| source.name.clone()),
        source_vertices: source.vertices,
        source_faces: source.faces,
        compression: compression(&encoding, options),
        mapping: None,
        up_axis: Some(up),
        unit: meta.unit.clone(),
        rights: meta.rights.clone(),
        language: meta.language.clone(),
        bounds: Some(encoding.bounds),
        thumbnail: Some(encoding.thumbnail.clone()),
    };
    let stored = stage_and_commit(storage, &new, options.pause_before_commit).await?;
    Ok(IngestReport {
        stored,
        levels,
        base_vertices: encoded.level_points[0],
        full_vertices: encoded.header.points,
        stream_bytes: encoded.bytes.len(),
        encode_time: encoding.encode_time,
        ccc: None,
        quality: None,
        features: None,
        curation_time: None,
    })
}

fn encode(
    mut cloud: PointCloud,
    up: crate::storage::UpAxis,
    options: &IngestOptions,
) -> anyhow::Result<Encoding> {
    options.report("estimating normals", 0.1);
    let started = Instant::now();
    let normals_estimated = cloud.normals.is_none() && options.points.normals;
    if normals_estimated {
        cloud.normals = Some(vitrine_points::estimate_normals(
            &cloud.positions,
            vitrine_points::DEFAULT_K,
        ));
    }
    let normals_time = started.elapsed();
    options.report("encoding", 0.3);
    let started = Instant::now();
    let encoded = stream::encode(&cloud, &options.points).context("encoding failed")?;
    let encode_time = started.elapsed();
    options.report("measuring", 0.7);
    // Read back as a visitor will: the bounds are the decoded positions'.
    let decoded = stream::decode(&encoded.bytes, None, stream::Limits::default())
        .context("reading the point stream back")?;
    options.report("rendering the thumbnail", 0.8);
    let thumbnail = curation::render_point_thumbnail(
        decoded.positions(),
        decoded.normals(),
        decoded.colours(),
        up,
    )?;
    Ok(Encoding {
        thumbnail,
        bounds: curation::bounds_of_positions(decoded.positions()),
        encoded,
        normals_estimated,
        normals_time,
        encode_time,
    })
}

/// The stream cut into the rows a mesh stream is stored in: header and
/// level 0 as the base, level k as batch k; `vertices` counts points.
fn compression(encoding: &Encoding, options: &IngestOptions) -> NewCompression {
    let encoded = &encoding.encoded;
    let header = &encoded.header;
    let level = |k: usize, bytes: &[u8]| NewLevel {
        vertices: encoded.level_points[k],
        faces: 0,
        bytes: bytes.to_vec(),
        metrics: None,
        hausdorff: None,
    };
    let chunks = &encoded.chunks;
    let base_end = chunks.first().map_or(encoded.bytes.len(), |c| c.end);
    let points = &options.points;
    NewCompression {
        codec_version: header.version,
        options: json!({
            "kind": "points",
            "bits": points.bits,
            "normal_bits": points.normal_bits,
            "base_points": points.base_points,
            "normals": points.normals,
            "colours": points.colours,
            "predict_attributes": header.predicted_attributes,
        })
        .to_string(),
        stats: json!({
            "points": header.points,
            "bits_per_point": encoded.bytes.len() as f64 * 8.0 / f64::from(header.points.max(1)),
            "normals": if encoding.normals_estimated { "estimated" } else if header.has_normals() { "file" } else { "none" },
            "normals_ms": encoding.normals_time.as_millis() as u64,
            "encode_ms": encoding.encode_time.as_millis() as u64,
            "level_depths": header.level_depths,
        })
        .to_string(),
        quantization_bits: header.bits,
        has_colour: header.has_colours,
        stream_bytes: encoded.bytes.len() as u64,
        encode_ms: encoding.encode_time.as_millis() as u64,
        base: level(0, &encoded.bytes[..base_end]),
        batches: chunks
            .iter()
            .enumerate()
            .skip(1)
            .map(|(k, r)| level(k, &encoded.bytes[r.clone()]))
            .collect(),
        parts: Vec::new(),
        splits: Vec::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::ply_declares_faces;

    #[test]
    fn faces_are_read_from_the_ply_header() {
        let cloud = b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\n";
        let empty = b"ply\nformat ascii 1.0\nelement vertex 3\nelement face 0\nend_header\n";
        let mesh = b"ply\nformat ascii 1.0\nelement vertex 3\nelement face 1\nend_header\n";
        assert_eq!(ply_declares_faces(cloud), Some(false));
        assert_eq!(ply_declares_faces(empty), Some(false));
        assert_eq!(ply_declares_faces(mesh), Some(true));
        assert_eq!(ply_declares_faces(b"ply\nformat ascii 1.0\n"), None);
    }
}
