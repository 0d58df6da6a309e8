//! Colour sources as shaders for the CPU rasterizer of [`crate::metrics`]:
//! the cell complex, and a scan's own texture through its UVs.

use glam::{DVec2, Vec3};

use vitrine_colour::ccc::CellComplex;
use vitrine_mesh::import::TexturedSurface;
use vitrine_mesh::texel::sample_bilinear;

use crate::metrics::SurfaceShader;

impl SurfaceShader for CellComplex {
    fn colour(&self, _triangle: usize, _barycentric: [f32; 3], world: Vec3) -> [f32; 3] {
        self.colour_at(world)
    }
}

/// A photographic texture through the file's UVs (render the surface's own
/// triangles: `TexturedSurface::as_mesh`).
pub struct TextureShader<'a>(pub &'a TexturedSurface);

impl SurfaceShader for TextureShader<'_> {
    fn colour(&self, triangle: usize, b: [f32; 3], _world: Vec3) -> [f32; 3] {
        let t = &self.0;
        let Some(tri) = t.triangles.get(triangle) else {
            return [0.5; 3];
        };
        let mut uv = DVec2::ZERO;
        for k in 0..3 {
            uv += b[k] as f64 * DVec2::from(t.uvs[tri[k] as usize].map(f64::from));
        }
        sample_bilinear(&t.image, uv).map(|c| (c / 255.0) as f32)
    }
}
