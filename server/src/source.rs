//! The codec commands: encode, decode, inspect, bench.

pub mod bench;
pub mod colour_bench;
pub mod decode;
pub mod dump;
pub mod encode;
pub mod inspect;
pub mod sample;

use anyhow::Context;
use std::path::{Path, PathBuf};
use vitrine_codec::IndexedMesh;
use vitrine_mesh::import::{import_path, import_path_textured, ImportOptions, TexturedSurface};
use vitrine_mesh::repair::{prepare, RepairOptions, RepairReport};

/// Reads any supported mesh file and repairs it into an encodable manifold.
pub fn load_mesh(path: &Path) -> anyhow::Result<(IndexedMesh, RepairReport)> {
    let mesh = import_path(path, &ImportOptions::default())
        .with_context(|| format!("reading {}", path.display()))?;
    prepare(mesh, &RepairOptions::default())
        .with_context(|| format!("repairing {}", path.display()))
}

/// Reads a mesh file with its colour texture when it has one (OBJ+MTL,
/// glTF), repaired; texture problems are warnings, not errors.
pub fn load_coloured_mesh(
    path: &Path,
) -> anyhow::Result<(IndexedMesh, Option<TexturedSurface>, RepairReport)> {
    let imported = import_path_textured(path, &ImportOptions::default())
        .with_context(|| format!("reading {}", path.display()))?;
    for w in &imported.warnings {
        eprintln!("warning: {}: {w}", path.display());
    }
    let (mesh, report) = prepare(imported.mesh, &RepairOptions::default())
        .with_context(|| format!("repairing {}", path.display()))?;
    Ok((mesh, imported.texture, report))
}

/// Where `vitrine encode --colour ccc` puts the complex beside a stream.
pub struct CccFiles {
    pub parameters: PathBuf,
    pub cell: PathBuf,
    pub colour: PathBuf,
    pub colour_low: PathBuf,
}

impl CccFiles {
    pub fn beside(stream: &Path) -> CccFiles {
        let with = |suffix: &str| {
            let mut name = stream.as_os_str().to_owned();
            name.push(suffix);
            PathBuf::from(name)
        };
        CccFiles {
            parameters: with(".ccc.json"),
            cell: with(".cell.png"),
            colour: with(".colour.jpg"),
            colour_low: with(".colour-low.jpg"),
        }
    }
}

/// Human summary of what repair changed, or `None` when nothing did.
pub fn describe_repair(r: &RepairReport) -> Option<String> {
    let parts: Vec<String> = [
        (r.welded_vertices, "vertices welded"),
        (r.degenerate_faces, "degenerate faces dropped"),
        (r.duplicate_faces, "duplicate faces dropped"),
        (r.non_manifold_edges, "non-manifold edges split"),
        (r.non_manifold_vertices, "non-manifold vertices split"),
        (r.unreferenced_vertices, "unreferenced vertices dropped"),
        (r.flipped_faces, "faces reoriented"),
    ]
    .iter()
    .filter(|(n, _)| *n > 0)
    .map(|(n, what)| format!("{n} {what}"))
    .collect();
    (!parts.is_empty()).then(|| parts.join(", "))
}
