//! Colour for Vitrine's progressive meshes.
//!
//! - [`ccc`]: the cubic cell complex (thesis ch. 5; Apaza-Agüero, Silva &
//!   Bellon 2011): one colour texture, reached through a grid of cubes
//!   around the surface, shared by every level of the stream, with the
//!   decimation guard that keeps each level inside the cubes (`CCC.md`).
//! - [`border_guard`]: per-vertex colour instead, with Lee, Lavoué & Dupont's
//!   guard against decimating across colour borders.
//! - [`encode_coloured`]: a mesh encoded with its colour carried in any of
//!   the [`ColourMode`]s.
#![forbid(unsafe_code)]

pub mod border_guard;
pub mod ccc;
mod coloured;

pub use coloured::{encode_coloured, vertex_colours_from_texture, ColourMode};
