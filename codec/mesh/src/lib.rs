//! Vitrine's mesh files: what a scan looks like before and after the codec.
//!
//! - [`import`]: PLY, OBJ, OFF/COFF, glTF 2.0 and GLB into an
//!   [`IndexedMesh`], and a scan's colour texture as a [`import::TexturedSurface`].
//!   Every importer treats its input as hostile.
//! - [`repair`]: welds, drops degenerate and duplicate faces and cuts
//!   non-manifold configurations until the codec can encode the mesh.
//! - [`export`]: a decoded level as PLY, OBJ or GLB.
//!
//! ```no_run
//! use vitrine_mesh::import::{import_path, ImportOptions};
//! use vitrine_mesh::repair::{prepare, RepairOptions};
//! # fn demo() -> vitrine_codec::Result<()> {
//! let scan = import_path("statue.ply".as_ref(), &ImportOptions::default())?;
//! let (manifold, report) = prepare(scan, &RepairOptions::default())?;
//! let stream = vitrine_codec::encode(&manifold, &Default::default())?;
//! # let _ = (report, stream); Ok(()) }
//! ```
#![forbid(unsafe_code)]

pub mod export;
pub mod import;
pub mod repair;
pub mod texel;

pub use vitrine_codec::{Error, IndexedMesh, Result};
