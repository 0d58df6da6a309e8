//! Simplification that keeps what a visitor looks at: sharp features.
//!
//! - [`deviation`]: each vertex's average normal deviation θ (Ceballos,
//!   Hernández & Prieto, seed 004): the angle between its normal and the
//!   area-weighted normal of the triangles within two rings of it. Flat
//!   regions have θ ≈ 0; ridges, inscriptions and tool marks stand out.
//! - [`FeatureGuard`]: θ as a decimation guard for the progressive encoder
//!   (`vitrine_codec::Encoder::guard`), beside the cell complex's: a vertex
//!   near a feature stays until the finer levels;
//!   [`search_feature_guard`] picks its setting per scan, within a
//!   connectivity budget and without raising the image error.
//! - [`simplify`]: the standalone multiresolution (seed 004, Alg. 1, 4, 5):
//!   edge, half-edge or triangle collapses of the vertices off the borders
//!   and away from features, each checked (link condition, no flips), down
//!   to an exact vertex count.
//! - [`melax`]: Melax's progressive edge collapse (seed 003) for levels of
//!   detail: heap-ordered, checked like [`simplify`], seams and borders
//!   kept, one collapse order for every frame of an animated model.
//! - [`simplify_voronoi`]: the intrinsic Voronoi simplifier (Oliveira,
//!   seed 001): geodesic discs, their Voronoi diagram refined to the
//!   closed-ball property, and its dual; topology kept, its vertices input
//!   vertices or ([`VoronoiPlacement::Quadric`]) moved to their cells'
//!   quadric minimum.
//!
//! ```
//! use vitrine_simplify::{simplify, Collapse, SimplifyOptions, StopReason, Target};
//! # let mesh = vitrine_samples::torus(48, 24, 1.0, 0.3);
//! let options = SimplifyOptions {
//!     collapse: Collapse::Edge,
//!     target: Target::Fraction(0.25),
//!     ..SimplifyOptions::default()
//! };
//! let out = simplify(&mesh, &options)?;
//! assert_eq!(out.stopped, StopReason::Target);
//! assert_eq!(out.mesh.vertex_count(), 288);
//! # Ok::<(), vitrine_codec::Error>(())
//! ```
#![forbid(unsafe_code)]

mod collapse;
pub mod deviation;
mod feature_guard;
mod feature_search;
pub mod melax;
pub mod voronoi;

pub use collapse::{
    simplify, simplify_with, Cleanup, Collapse, Features, PassReport, Placement, Simplified,
    SimplifyOptions, StopReason, Target,
};
pub use deviation::{border_vertices, normal_deviation, one_ring_max, VertexFaces};
pub use feature_guard::{
    FeatureGuard, FeatureThreshold, DEFAULT_FEATURE_SHARE, DEFAULT_RELIEF_GATE,
};
pub use feature_search::{
    at_vertices, decoded_mesh, first_level_with, level_curve, search_feature_guard, FeatureProbe,
    GuardSearch, GuardSetting, LevelMeasure, DEFAULT_CONNECTIVITY_BUDGET, SEARCHED_SETTINGS,
};
pub use voronoi::{
    simplify_voronoi, Distance, Order, Radius, VoronoiOptions, VoronoiPlacement, VoronoiSimplified,
    VoronoiSpacing, SHARP_DEGREES,
};
