//! The mesh a command starts from: a file read with its colour texture and
//! repaired into an encodable manifold ([`load_coloured_mesh`]), and the
//! original that a stream's levels are measured against
//! ([`QualityReference`]).

use anyhow::Context;
use std::path::Path;
use vitrine_codec::IndexedMesh;
use vitrine_colour::ccc::{CellComplex, TextureMapping};
use vitrine_colour::{vertex_colours_from_texture, ColourMode};
use vitrine_mesh::import::{import_path_textured, ImportOptions, TexturedSurface};
use vitrine_mesh::repair::{prepare, RepairOptions, RepairReport};
use vitrine_quality::{stream_quality, LevelQuality, Original, QualityOptions};

/// A mesh file as read and repaired.
pub struct SourceMesh {
    /// Repaired: what the encoder is given.
    pub mesh: IndexedMesh,
    /// The file's colour texture (OBJ+MTL, glTF), when it has one.
    pub texture: Option<TexturedSurface>,
    pub repair: RepairReport,
    /// Vertices and faces as imported, before repair.
    pub imported_vertices: usize,
    pub imported_faces: usize,
}

/// Reads a mesh file (PLY, OBJ, OFF, glTF, GLB, MD2 frame 0) with its colour texture when
/// it has one, and repairs it. Texture problems are warnings on stderr, not
/// errors: the mesh is still encodable without its texture.
pub fn load_coloured_mesh(path: &Path) -> anyhow::Result<SourceMesh> {
    load_coloured_frame(path, 0)
}

/// [`load_coloured_mesh`] of animation frame `frame` (MD2; other formats
/// have one frame and ignore it).
pub fn load_coloured_frame(path: &Path, frame: usize) -> anyhow::Result<SourceMesh> {
    let options = ImportOptions {
        frame,
        ..ImportOptions::default()
    };
    let imported = import_path_textured(path, &options)
        .with_context(|| format!("reading {}", path.display()))?;
    for w in &imported.warnings {
        eprintln!("warning: {}: {w}", path.display());
    }
    let imported_vertices = imported.mesh.vertex_count();
    let imported_faces = imported.mesh.face_count();
    let (mesh, repair) = repaired(imported.mesh, path)?;
    Ok(SourceMesh {
        mesh,
        texture: imported.texture,
        repair,
        imported_vertices,
        imported_faces,
    })
}

/// Reads a mesh file's geometry and per-vertex colour only, never its
/// texture (which `bench` would count in the peak memory), and repairs it.
#[cfg(feature = "dev-tools")]
pub fn load_mesh(path: &Path) -> anyhow::Result<(IndexedMesh, RepairReport)> {
    let mesh = vitrine_mesh::import::import_path(path, &ImportOptions::default())
        .with_context(|| format!("reading {}", path.display()))?;
    repaired(mesh, path)
}

fn repaired(mesh: IndexedMesh, path: &Path) -> anyhow::Result<(IndexedMesh, RepairReport)> {
    prepare(mesh, &RepairOptions::default())
        .with_context(|| format!("repairing {}", path.display()))
}

/// How colour travels when not asked: a textured scan in a cubic cell
/// complex (the thesis' method, issue 22), per vertex when the mesh has
/// per-vertex colour only, else not at all.
pub fn default_colour_mode(mesh: &IndexedMesh, texture: Option<&TexturedSurface>) -> ColourMode {
    if texture.is_some() {
        ColourMode::Ccc
    } else if mesh.colors.is_some() {
        ColourMode::Vertex
    } else {
        ColourMode::None
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

/// The original a stream's levels are measured against: the repaired mesh
/// with per-vertex colour, sampled from the texture for a textured scan, and
/// the texture itself for the image metric.
pub struct QualityReference {
    pub mesh: IndexedMesh,
    pub texture: Option<TexturedSurface>,
}

impl QualityReference {
    pub fn new(mut mesh: IndexedMesh, texture: Option<TexturedSurface>) -> QualityReference {
        if let Some(t) = &texture {
            mesh.colors = Some(vertex_colours_from_texture(&mesh, t));
        }
        QualityReference { mesh, texture }
    }

    pub fn original(&self) -> Original<'_> {
        Original {
            mesh: &self.mesh,
            texture: self.texture.as_ref(),
        }
    }

    /// Every level of `stream` against the original; colour at a level is
    /// the complex's lookup when there is one, else the stream's own.
    pub fn measure(
        &self,
        stream: &[u8],
        complex: Option<&CellComplex>,
        options: &QualityOptions,
    ) -> anyhow::Result<Vec<LevelQuality>> {
        Ok(stream_quality(stream, complex, &self.original(), options)?)
    }
}

/// The complex a mapping describes, read back from its images as the viewer
/// reads them (the full-resolution atlas).
pub fn read_back(mapping: &TextureMapping) -> anyhow::Result<CellComplex> {
    Ok(CellComplex::from_images(
        &mapping.parameters,
        &mapping.cell_png,
        &mapping.colour_jpeg,
    )?)
}
