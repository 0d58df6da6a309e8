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
pub mod colour_metric;
mod decoder;
mod edges;
mod encoder;
mod entropy;
mod error;
mod format;
mod frenet;
mod gates;
mod halfedge;
mod inspect;
mod mesh;
mod patch;
mod predict;
mod priors;
mod quantize;
pub mod samples;

pub use decoder::{decode, Decoder, Limits};
pub use encoder::{
    encode, encode_guarded, encode_with_progress, BaseTarget, CandidatePatch, EncodeOptions,
    EncodeProgress, Encoded, PatchGuard,
};
pub use error::{Error, Result};
pub use format::{Header, LevelInfo, StreamIndex, MAGIC, VERSION};
pub use gates::GateStatistics;
pub use inspect::{breakdown, LevelBreakdown};
pub use mesh::IndexedMesh;
pub use quantize::Quantization;

// --- import/repair/export (helper) ---
#[cfg(feature = "import")]
pub mod ccc;
#[cfg(feature = "import")]
pub mod export;
#[cfg(feature = "import")]
pub mod import;
#[cfg(feature = "import")]
pub mod metrics;
#[cfg(feature = "import")]
pub mod quality;
pub mod repair;
// --- end ---
