//! Generated inputs shared by the colour crate's integration tests.

use vitrine_codec::IndexedMesh;
use vitrine_samples as samples;

/// A torus with a procedurally painted photograph: a 512² image of checks
/// and soft bands, reached through the torus' angular UVs (unwrapped per
/// triangle, the sampler repeats).
pub fn textured_torus() -> (IndexedMesh, vitrine_mesh::import::TexturedSurface) {
    let (rings, sides) = (96u32, 48u32);
    let mesh = samples::torus(rings, sides, 1.0, 0.35);
    let image = image::RgbImage::from_fn(512, 512, |x, y| {
        let check = ((x / 64) + (y / 64)) % 2 == 0;
        let band = 0.5 + 0.5 * (y as f32 / 512.0 * std::f32::consts::TAU).sin();
        if check {
            image::Rgb([220, (80.0 + 150.0 * band) as u8, 40])
        } else {
            image::Rgb([30, 60, (120.0 + 130.0 * band) as u8])
        }
    });
    let uv_of = |v: u32| {
        [
            (v / sides) as f32 / rings as f32,
            (v % sides) as f32 / sides as f32,
        ]
    };
    let (mut positions, mut uvs, mut triangles) = (Vec::new(), Vec::new(), Vec::new());
    for t in &mesh.triangles {
        let corner = t.map(uv_of);
        let base = positions.len() as u32;
        for (k, &v) in t.iter().enumerate() {
            let mut uv = corner[k];
            // Unwrap across the seam so the triangle's UVs stay contiguous.
            for d in 0..2 {
                if corner[0][d] - uv[d] > 0.5 {
                    uv[d] += 1.0;
                }
                if uv[d] - corner[0][d] > 0.5 {
                    uv[d] -= 1.0;
                }
            }
            positions.push(mesh.positions[v as usize]);
            uvs.push(uv);
        }
        triangles.push([base, base + 1, base + 2]);
    }
    let surface = vitrine_mesh::import::TexturedSurface {
        positions,
        uvs,
        triangles,
        image,
    };
    (mesh, surface)
}
