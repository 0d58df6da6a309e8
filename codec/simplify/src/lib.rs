//! Simplification that keeps what a visitor looks at: sharp features.
//!
//! - [`deviation`]: each vertex's average normal deviation θ (Ceballos,
//!   Hernández & Prieto, seed 004): the angle between its normal and the
//!   area-weighted normal of the triangles within two rings of it. Flat
//!   regions have θ ≈ 0; ridges, inscriptions and tool marks stand out.
//! - [`FeatureGuard`]: θ as a decimation guard for the progressive encoder
//!   (`vitrine_codec::Encoder::guard`), beside the cell complex's: a vertex
//!   near a feature stays until the finer levels.
#![forbid(unsafe_code)]

pub mod deviation;
mod feature_guard;

pub use deviation::{border_vertices, normal_deviation, one_ring_max, VertexFaces};
pub use feature_guard::{FeatureGuard, FeatureThreshold, DEFAULT_FEATURE_SHARE};
