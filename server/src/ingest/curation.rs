//! What an ingest records beside the stream for curators and the viewer:
//! the up axis (given, or detected by [`detect_up`]), the bounds of the
//! decoded positions, every level's sampled Hausdorff distance, and a
//! thumbnail rendered with the model's colour by `vitrine_quality`'s
//! rasteriser, framed as the viewer frames it.

use crate::storage::{Bounds, NewThumbnail, UpAxis};
use anyhow::Context;
use glam::Vec3;
use std::io::Cursor;
use std::path::Path;
use vitrine_codec::{Decoder, IndexedMesh, Limits, StreamIndex};
use vitrine_colour::ccc::CellComplex;
use vitrine_quality::metrics::views::{bounding_sphere, FOV_Y};
use vitrine_quality::metrics::{
    render, Camera, ConstantColour, HausdorffReference, RenderOptions, SurfaceShader, VertexColours,
};

/// Area samples per mesh for the Hausdorff distance measured by default
/// (every vertex is a sample too): a tenth of `--quality`'s, enough for a
/// ± figure on the model page, and a fraction of a second at 50k vertices.
pub const DEFAULT_HAUSDORFF_SAMPLES: usize = 20_000;

/// Side of the thumbnail in pixels.
pub const THUMBNAIL_SIZE: u32 = 512;

/// The units `--unit` takes.
pub const UNITS: [&str; 4] = ["mm", "cm", "m", "in"];

/// The up axis when `--up` is not given, from the format's convention and
/// the shape:
///
/// - glTF and GLB: `y` (the glTF specification says +Y is up);
/// - MD2: `z` (Quake II's convention);
/// - PLY, OFF and OBJ have no convention. Scanners mostly write Z-up and
///   modelling tools Y-up, so the shape decides: `z` when the box is more
///   than 10 % taller along z than along y (an object standing in a Z-up
///   file), else `y`.
///
/// The sign is never guessed: `--up -z` says a model is upside down.
pub fn detect_up(path: Option<&Path>, mesh: &IndexedMesh) -> UpAxis {
    detect_up_of(path, &mesh.positions)
}

/// [`detect_up`] of positions alone (a point cloud's); LAS/LAZ, whose
/// coordinates are geographic, have z up.
pub fn detect_up_of(path: Option<&Path>, positions: &[[f32; 3]]) -> UpAxis {
    let extension = path
        .and_then(|p| p.extension())
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    match extension.as_deref() {
        Some("gltf" | "glb") => UpAxis::Y,
        Some("md2" | "las" | "laz") => UpAxis::Z,
        _ => {
            let (mut min, mut max) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
            for p in positions {
                min = min.min(Vec3::from(*p));
                max = max.max(Vec3::from(*p));
            }
            let extent = max - min;
            if extent.z > 1.1 * extent.y {
                UpAxis::Z
            } else {
                UpAxis::Y
            }
        }
    }
}

/// The full level's bounds and each level's Hausdorff distance to
/// `original` over the original's bounding-box diagonal, decoding the
/// stream once. The bounds are those of the decoded positions: the stream's
/// dequantized model coordinates, which the viewer and annotations use.
pub fn measure_levels(
    stream: &[u8],
    original: &IndexedMesh,
    samples: usize,
) -> anyhow::Result<(Bounds, Vec<f64>, IndexedMesh)> {
    let index = StreamIndex::parse(stream).context("reading the stream back")?;
    let reference = HausdorffReference::new(original, samples);
    let mut decoder = Decoder::new(&stream[index.base.clone()], Limits::default())?;
    let mut distances = Vec::with_capacity(index.batches.len() + 1);
    let mut mesh = decoder.to_mesh();
    distances.push(reference.distance_to(&mesh).relative());
    for batch in &index.batches {
        decoder.apply_batch(&stream[batch.clone()])?;
        mesh = decoder.to_mesh();
        distances.push(reference.distance_to(&mesh).relative());
    }
    Ok((bounds_of(&mesh), distances, mesh))
}

pub fn bounds_of(mesh: &IndexedMesh) -> Bounds {
    bounds_of_positions(&mesh.positions)
}

/// The bounds of `positions` (all zero when there are none).
pub fn bounds_of_positions(positions: &[[f32; 3]]) -> Bounds {
    let (mut min, mut max) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for p in positions {
        for i in 0..3 {
            min[i] = min[i].min(f64::from(p[i]));
            max[i] = max[i].max(f64::from(p[i]));
        }
    }
    if positions.is_empty() {
        return Bounds {
            min: [0.0; 3],
            max: [0.0; 3],
        };
    }
    Bounds { min, max }
}

/// The camera of the thumbnail: the viewer's 40° field of view and home
/// distance (the bounding sphere with a 10 % margin), `up` pointing up,
/// seen from the front and a little above and to the right.
pub fn thumbnail_camera(mesh: &IndexedMesh, up: UpAxis) -> Camera {
    let (center, radius) = bounding_sphere(mesh);
    let up_vector = Vec3::from(up.vector());
    // "Front" is +z for a Y-up or X-up model and -y for a Z-up one (the
    // usual conventions of modelling tools and scanners).
    let front = match up {
        UpAxis::Y | UpAxis::NegY | UpAxis::X | UpAxis::NegX => Vec3::Z,
        UpAxis::Z => Vec3::NEG_Y,
        UpAxis::NegZ => Vec3::Y,
    };
    let right = front.cross(up_vector).normalize_or_zero();
    let direction = (front + 0.35 * up_vector - 0.35 * right).normalize();
    let distance = 1.1 * radius / (FOV_Y * 0.5).sin();
    Camera {
        eye: center + direction * distance,
        target: center,
        up: up_vector,
        fov_y: FOV_Y,
        near: (distance - 2.0 * radius).max(distance / 1000.0),
    }
}

/// Renders `mesh` (the full level) as a PNG with the model's colour: the
/// cell complex's lookup, the per-vertex colour, or clay.
pub fn render_thumbnail(
    mesh: &IndexedMesh,
    complex: Option<&CellComplex>,
    up: UpAxis,
) -> anyhow::Result<NewThumbnail> {
    let vertex;
    let shader: &dyn SurfaceShader = match complex {
        Some(c) => c,
        None => match VertexColours::new(mesh) {
            Some(v) => {
                vertex = v;
                &vertex
            }
            None => &ConstantColour::CLAY,
        },
    };
    let options = RenderOptions::square(THUMBNAIL_SIZE);
    let frame = render(mesh, shader, &thumbnail_camera(mesh, up), &options);
    let mut bytes = Vec::new();
    frame
        .to_image()
        .write_to(&mut Cursor::new(&mut bytes), image::ImageFormat::Png)
        .context("encoding the thumbnail")?;
    Ok(NewThumbnail {
        media_type: "image/png",
        width: frame.width,
        height: frame.height,
        bytes,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tall_along(axis: usize) -> IndexedMesh {
        let mut mesh = vitrine_samples::icosphere(1);
        for p in &mut mesh.positions {
            p[axis] *= 3.0;
        }
        mesh
    }

    #[test]
    fn detection_rule() {
        let z_tall = tall_along(2);
        let y_tall = tall_along(1);
        let ply = Some(Path::new("scan.ply"));
        assert_eq!(detect_up(ply, &z_tall), UpAxis::Z);
        assert_eq!(detect_up(ply, &y_tall), UpAxis::Y);
        assert_eq!(detect_up(Some(Path::new("a.OBJ")), &z_tall), UpAxis::Z);
        // The format's convention wins over the shape.
        assert_eq!(detect_up(Some(Path::new("a.glb")), &z_tall), UpAxis::Y);
        assert_eq!(detect_up(Some(Path::new("a.md2")), &y_tall), UpAxis::Z);
        // A round shape has no tall axis: y.
        assert_eq!(detect_up(ply, &vitrine_samples::icosphere(1)), UpAxis::Y);
    }

    #[test]
    fn thumbnail_camera_looks_with_up_up() {
        let mesh = tall_along(2);
        let camera = thumbnail_camera(&mesh, UpAxis::Z);
        assert_eq!(camera.up, Vec3::Z);
        // From the front (-y) and above, at the viewer's home distance.
        assert!(camera.eye.y < 0.0 && camera.eye.z > 0.0);
        let thumb = render_thumbnail(&mesh, None, UpAxis::Z).unwrap();
        assert_eq!(&thumb.bytes[..8], b"\x89PNG\r\n\x1a\n");
        let image = image::load_from_memory(&thumb.bytes).unwrap().to_rgb8();
        // The tall sphere fills most of the picture's height, little of its width.
        let covered = |x: u32, y: u32| image.get_pixel(x, y).0 != [33, 36, 41];
        let rows = (0..THUMBNAIL_SIZE)
            .filter(|&y| covered(THUMBNAIL_SIZE / 2, y))
            .count();
        let cols = (0..THUMBNAIL_SIZE)
            .filter(|&x| covered(x, THUMBNAIL_SIZE / 2))
            .count();
        assert!(rows > cols * 2, "rows {rows}, columns {cols}: not upright");
    }
}
