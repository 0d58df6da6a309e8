//! Vitrine's point clouds: scans that were never meshed (laser scans of
//! buildings, photogrammetry dense clouds).
//!
//! - [`PointCloud`]: positions with optional normals and colours;
//!   [`import`] reads PLY (vertices without faces) and LAS/LAZ.
//! - [`estimate_normals`]: PCA over the k nearest neighbours, consistently
//!   oriented, for clouds without normals.
//! - [`stream`]: the progressive point stream (see `FORMAT.md`): an octree
//!   in level order, range-coded, lossless at the chosen quantization; every
//!   level is a prefix and an even subsample of the whole.
//! - [`splat`]: splat preprocessing for the viewer's renderer (seed 002):
//!   radii, neighbour graph, sharp edges, clip partners, surface ids.
#![forbid(unsafe_code)]

mod cloud;
pub mod grid;
#[cfg(feature = "import")]
pub mod import;
mod normals;
pub mod splat;
pub mod stream;
#[doc(hidden)]
pub mod testing;

pub use cloud::PointCloud;
pub use normals::{estimate_normals, DEFAULT_K};
pub use vitrine_codec::{Error, Result};
