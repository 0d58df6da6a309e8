//! Quality metrics for a level against the original.
//!
//! - [`hausdorff`]: the symmetric Hausdorff distance between two surfaces,
//!   estimated Metro-style by dense area-uniform surface sampling (Cignoni,
//!   Rocchini, Scopigno, "Metro: measuring error on simplified surfaces",
//!   Computer Graphics Forum 17(2), 1998).
//! - [`roy_colour_rmse`]: the per-vertex colour RMSE of Roy, Foufou and
//!   Truchetet, "Mesh comparison using attribute deviation metric" (IJIG 4(1), 2004):
//!   every vertex of the original against the nearest vertex of the approximation.
//! - [`image_rmse`]: the image-space luminance RMSE of Lindstrom and Turk,
//!   "Image-driven simplification" (ACM TOG 19(3), 2000): 24 snapshots from the
//!   vertices of a small rhombicuboctahedron ([`views::rhombicuboctahedron`]),
//!   rendered by the CPU rasterizer in [`raster`] so no GPU is needed.
//!
//! Everything is deterministic: sampling uses a fixed seed, and the work split
//! over threads does not change any result.

mod bvh;
mod colour;
mod hausdorff;
mod image_rmse;
mod kdtree;
pub mod raster;
mod sampling;
pub mod views;

pub use colour::{roy_colour_rmse, ColourError};
pub use hausdorff::{distances_to_surface, hausdorff, Hausdorff, HausdorffReference};
pub use image_rmse::{image_rmse, image_rmse_per_view, ImageReference};
pub use raster::{
    default_shader, render, Camera, ConstantColour, Frame, Lighting, RenderOptions, SurfaceShader,
    VertexColours,
};

use rayon::prelude::*;

/// `f(0..n)` on rayon's pool (every core, or `RAYON_NUM_THREADS`), results
/// in index order; each result is computed alone, so the split never
/// changes a number.
pub(crate) fn parallel_map<T: Send>(n: usize, f: impl Fn(usize) -> T + Sync + Send) -> Vec<T> {
    (0..n).into_par_iter().map(f).collect()
}
