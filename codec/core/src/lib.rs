//! Vitrine's progressive mesh codec: Alliez–Desbrun 2001 valence-driven
//! coding, lossless at the chosen quantization.
//!
//! ```
//! use vitrine_codec::{decode, encode, EncodeOptions, IndexedMesh, Limits};
//! # fn demo(mesh: &IndexedMesh) -> vitrine_codec::Result<()> {
//! let encoded = encode(mesh, &EncodeOptions::default())?;
//! // Base mesh plus every refinement batch:
//! let decoder = decode(&encoded.bytes, None, Limits::default())?;
//! assert_eq!(decoder.vertex_count(), mesh.positions.len());
//! # Ok(()) }
//! ```
//! A server splits the stream with [`StreamIndex`]; a viewer feeds the
//! pieces to a [`Decoder`] one batch at a time.
#![forbid(unsafe_code)]

mod base_mesh;
mod bits;
mod charts;
mod contexts;
mod decoder;
pub mod edges;
mod encoder;
pub mod entropy;
mod error;
mod format;
mod frenet;
mod gates;
mod halfedge;
mod inspect;
mod mesh;
mod meter;
mod parts;
mod patch;
mod predict;
mod priors;
mod quantize;
mod room;
mod training;

pub use bits::bit_budget;
pub use charts::nested::{Shape as NestedShape, MAX_PHASE_CHARTS};
pub use charts::MAX_CHARTS;
pub use decoder::{decode, ChartLevel, ChartView, Decoder, Limits, NestedView};
pub use encoder::{
    encode, BaseTarget, CandidatePatch, Charts, EncodeOptions, EncodeProgress, Encoded, Encoder,
    PatchGuard,
};
pub use error::{Error, Result};
pub use format::{
    BatchChunk, Header, LevelInfo, StreamIndex, CHARTED_VERSION, MAGIC, NESTED_VERSION, VERSION,
};
pub use gates::GateStatistics;
pub use inspect::{breakdown, LevelBreakdown};
pub use mesh::IndexedMesh;
pub use meter::PassBits;
pub use parts::{
    nested_part_table, part_table, NestedLayout, NestedPartTable, NestedSummary, PartRecord,
    PartedLayout, SplitRecord, BULK_SHARE,
};
pub use quantize::Quantization;

#[cfg(test)]
#[path = "../../samples/src/shapes.rs"]
// The generated meshes of `vitrine-samples`, compiled into the unit tests
// (a dev-dependency on that crate would give them a second `IndexedMesh`).
#[allow(dead_code)] // the unit tests use a few of the shapes
mod samples;
