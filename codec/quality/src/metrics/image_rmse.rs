//! The image-space luminance RMSE of Lindstrom and Turk (2000).

use super::parallel_map;
use super::raster::{render, Camera, RenderOptions, SurfaceShader};
use super::views::{bounding_sphere, rhombicuboctahedron};
use vitrine_codec::IndexedMesh;

/// The image metric of Lindstrom and Turk, "Image-driven simplification"
/// (ACM TOG 19(3), 2000): both meshes are rendered `size × size` from the 24
/// cameras of [`super::views::rhombicuboctahedron`] around the bounding sphere
/// of the **reference** (so both get identical framing), lit like the viewer
/// ([`super::raster::Lighting::viewer`], its background colour), and the result
/// is the root mean square difference of pixel luma (Rec. 709, 0–255) over
/// every pixel of all 24 images, background pixels included.
///
/// Each mesh is coloured by its own shader (e.g. [`super::raster::VertexColours`],
/// a texture lookup, or [`super::raster::ConstantColour::CLAY`] for geometry
/// alone). Views render in parallel; the result does not depend on the thread count.
pub fn image_rmse(
    reference: (&IndexedMesh, &dyn SurfaceShader),
    approx: (&IndexedMesh, &dyn SurfaceShader),
    size: u32,
) -> f64 {
    ImageReference::new(reference.0, reference.1, &RenderOptions::square(size))
        .rmse(approx.0, approx.1)
}

/// The luma RMSE of each of the 24 views, with any image size, background and
/// lighting. [`image_rmse`] is the root mean square of these.
pub fn image_rmse_per_view(
    reference: (&IndexedMesh, &dyn SurfaceShader),
    approx: (&IndexedMesh, &dyn SurfaceShader),
    options: &RenderOptions,
) -> [f64; 24] {
    ImageReference::new(reference.0, reference.1, options).per_view(approx.0, approx.1)
}

/// The reference's 24 snapshots, rendered once, for measuring many
/// approximations against (every level of a stream).
pub struct ImageReference {
    cameras: [Camera; 24],
    options: RenderOptions,
    luminance: Vec<Vec<f32>>,
}

impl ImageReference {
    pub fn new(mesh: &IndexedMesh, shader: &dyn SurfaceShader, options: &RenderOptions) -> Self {
        let (center, radius) = bounding_sphere(mesh);
        let cameras = rhombicuboctahedron(center, radius);
        let luminance = parallel_map(cameras.len(), |i| {
            render(mesh, shader, &cameras[i], options).luminance
        });
        ImageReference {
            cameras,
            options: *options,
            luminance,
        }
    }

    /// Luma RMSE of each view of `mesh` against the reference's.
    pub fn per_view(&self, mesh: &IndexedMesh, shader: &dyn SurfaceShader) -> [f64; 24] {
        let errors = parallel_map(self.cameras.len(), |i| {
            let b = render(mesh, shader, &self.cameras[i], &self.options);
            let a = &self.luminance[i];
            let sum: f64 = a
                .iter()
                .zip(&b.luminance)
                .map(|(x, y)| f64::from(x - y).powi(2))
                .sum();
            (sum / a.len().max(1) as f64).sqrt()
        });
        std::array::from_fn(|i| errors[i])
    }

    /// [`image_rmse`] of `mesh` against the reference.
    pub fn rmse(&self, mesh: &IndexedMesh, shader: &dyn SurfaceShader) -> f64 {
        let per_view = self.per_view(mesh, shader);
        (per_view.iter().map(|e| e * e).sum::<f64>() / per_view.len() as f64).sqrt()
    }
}
