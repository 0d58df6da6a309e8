//! The image-space luminance RMSE of Lindstrom and Turk (2000).

use super::parallel_map;
use super::raster::{render, RenderOptions, SurfaceShader};
use super::views::{bounding_sphere, rhombicuboctahedron};
use crate::IndexedMesh;

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
    let per_view = image_rmse_per_view(reference, approx, &RenderOptions::square(size));
    (per_view.iter().map(|e| e * e).sum::<f64>() / per_view.len() as f64).sqrt()
}

/// The luma RMSE of each of the 24 views, with any image size, background and
/// lighting. [`image_rmse`] is the root mean square of these.
pub fn image_rmse_per_view(
    reference: (&IndexedMesh, &dyn SurfaceShader),
    approx: (&IndexedMesh, &dyn SurfaceShader),
    options: &RenderOptions,
) -> [f64; 24] {
    let (center, radius) = bounding_sphere(reference.0);
    let cameras = rhombicuboctahedron(center, radius);
    let errors = parallel_map(cameras.len(), |i| {
        let a = render(reference.0, reference.1, &cameras[i], options);
        let b = render(approx.0, approx.1, &cameras[i], options);
        let sum: f64 = a
            .luminance
            .iter()
            .zip(&b.luminance)
            .map(|(x, y)| f64::from(x - y).powi(2))
            .sum();
        (sum / a.luminance.len().max(1) as f64).sqrt()
    });
    std::array::from_fn(|i| errors[i])
}
