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
use vitrine_quality::metrics::views::{bounding_sphere_of, FOV_Y};
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

/// Metres in one of [`UNITS`] (glTF's unit is the metre: a download in
/// millimetres is scaled by this, or an AR viewer shows a bust 1,000 times
/// its size).
pub fn metres_per_unit(unit: &str) -> Option<f32> {
    match unit {
        "mm" => Some(0.001),
        "cm" => Some(0.01),
        "m" => Some(1.0),
        "in" => Some(0.0254),
        _ => None,
    }
}

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
    thumbnail_camera_of(&mesh.positions, up)
}

/// [`thumbnail_camera`] for bare positions (a point cloud).
fn thumbnail_camera_of(positions: &[[f32; 3]], up: UpAxis) -> Camera {
    let (center, radius) = bounding_sphere_of(positions);
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
    png_thumbnail(&frame)
}

/// Most points drawn into a point model's thumbnail: a prefix of the stream
/// (every prefix is an even subsample of the cloud), ample at 512².
pub const THUMBNAIL_POINTS: usize = 200_000;

/// Renders a point cloud (in stream order) as a PNG, framed as a mesh's:
/// each point of a prefix becomes a square splat in its tangent plane (the
/// area of a disc of its splat radius, grown by a fifth so that neighbours
/// overlap with no holes), facing the camera when the cloud has no normals,
/// coloured by its colour or clay.
pub fn render_point_thumbnail(
    positions: &[[f32; 3]],
    normals: Option<&[[f32; 3]]>,
    colours: Option<&[[u8; 3]]>,
    up: UpAxis,
) -> anyhow::Result<NewThumbnail> {
    let m = positions.len().min(THUMBNAIL_POINTS);
    let centres = &positions[..m];
    let camera = thumbnail_camera_of(centres, up);
    let splats = point_splat_mesh(centres, normals, colours, camera.eye);
    let vertex;
    let shader: &dyn SurfaceShader = match VertexColours::new(&splats) {
        Some(v) => {
            vertex = v;
            &vertex
        }
        None => &ConstantColour::CLAY,
    };
    let frame = render(
        &splats,
        shader,
        &camera,
        &RenderOptions::square(THUMBNAIL_SIZE),
    );
    png_thumbnail(&frame)
}

/// Squares of side √π · 1.2 · r_i (r_i the splat radius: the mean distance
/// to the 5 nearest points), two triangles each, wound counter-clockwise
/// about the point's normal.
fn point_splat_mesh(
    centres: &[[f32; 3]],
    normals: Option<&[[f32; 3]]>,
    colours: Option<&[[u8; 3]]>,
    eye: Vec3,
) -> IndexedMesh {
    let radii = vitrine_points::splat::splat_radii(centres);
    let half_side = 0.5 * std::f32::consts::PI.sqrt() * 1.2;
    let mut mesh = IndexedMesh {
        positions: Vec::with_capacity(4 * centres.len()),
        colors: colours.map(|_| Vec::with_capacity(4 * centres.len())),
        triangles: Vec::with_capacity(2 * centres.len()),
    };
    for (i, (&c, &r)) in centres.iter().zip(&radii).enumerate() {
        let centre = Vec3::from(c);
        let n = normals
            .and_then(|n| n.get(i))
            .map(|&n| Vec3::from(n))
            .filter(|n| n.is_finite() && n.length_squared() > 0.5)
            .unwrap_or_else(|| (eye - centre).normalize_or(Vec3::Z));
        let (t, b) = n.any_orthonormal_pair();
        let h = half_side * r;
        let first = mesh.positions.len() as u32;
        for corner in [-t - b, t - b, t + b, -t + b] {
            mesh.positions.push((centre + corner * h).to_array());
        }
        if let (Some(out), Some(colours)) = (&mut mesh.colors, colours) {
            let colour = colours.get(i).copied().unwrap_or([200; 3]);
            out.extend([colour; 4]);
        }
        mesh.triangles.push([first, first + 1, first + 2]);
        mesh.triangles.push([first, first + 2, first + 3]);
    }
    mesh
}

fn png_thumbnail(frame: &vitrine_quality::metrics::Frame) -> anyhow::Result<NewThumbnail> {
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

    #[test]
    fn point_thumbnail_covers_what_the_mesh_covers() {
        // The vertices of a sphere with their normals, against the sphere:
        // the same silhouette (no holes, no halo), shaded, not background.
        let sphere = vitrine_samples::icosphere(5);
        let normals: Vec<[f32; 3]> = sphere
            .positions
            .iter()
            .map(|p| Vec3::from(*p).normalize().to_array())
            .collect();
        let mask = |png: &[u8]| -> Vec<bool> {
            let image = image::load_from_memory(png).unwrap().to_rgb8();
            image.pixels().map(|p| p.0 != [33, 36, 41]).collect()
        };
        let mesh = mask(&render_thumbnail(&sphere, None, UpAxis::Y).unwrap().bytes);
        let with_normals =
            render_point_thumbnail(&sphere.positions, Some(&normals), None, UpAxis::Y);
        let without = render_point_thumbnail(&sphere.positions, None, None, UpAxis::Y);
        let covered = mesh.iter().filter(|&&c| c).count();
        assert!(covered > 50_000, "{covered}");
        // Splats facing the camera stick out of the silhouette by their
        // radius (a halo a few pixels wide) but leave no holes either.
        for (what, points, percent) in [
            ("normals", with_normals, 3),
            ("facing the camera", without, 15),
        ] {
            let points = mask(&points.unwrap().bytes);
            let differ = mesh.iter().zip(&points).filter(|(a, b)| a != b).count();
            let holes = mesh
                .iter()
                .zip(&points)
                .filter(|(a, b)| **a && !**b)
                .count();
            assert!(
                differ * 100 < covered * percent,
                "{what}: {differ} of {covered} pixels differ"
            );
            assert!(holes * 1000 < covered, "{what}: {holes} hole pixels");
        }
    }
}
