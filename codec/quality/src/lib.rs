//! How far each level of a Vitrine stream is from its original.
//!
//! - [`metrics`]: Hausdorff distance (Metro), Roy's per-vertex colour RMSE,
//!   Lindstrom–Turk's 24-view image RMSE, and the deterministic CPU
//!   rasteriser, BVH and kd-tree behind them.
//! - [`stream_quality`]: those metrics for every level of a stream, the
//!   curve the thesis compares colour modes with and the model page plots.
//! - [`TextureShader`] and the cell complex as surface shaders, so a level is
//!   rendered with the colour a viewer would show.
#![forbid(unsafe_code)]

mod levels;
pub mod metrics;
mod shaders;

pub use levels::*;
pub use shaders::TextureShader;
