//! Meshes generated in code for Vitrine's tests, benchmarks and demo model
//! (the project ships no third-party scans), and the check every lossless
//! round trip makes. Not a dependency of the shipped codec.
#![forbid(unsafe_code)]

pub mod golden;
mod lossless;
mod shapes;

pub use lossless::final_level_mismatch;
pub use shapes::*;

// `shapes.rs` names the mesh type `crate::IndexedMesh`: it is also compiled
// into the codec core's own unit tests, where that is the core's type.
use vitrine_codec::IndexedMesh;
