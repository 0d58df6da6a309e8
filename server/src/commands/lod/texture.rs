//! What `vitrine lod` puts beside the positions: an MD2's skin with its
//! texture coordinates, or a scan's textured surface welded into the
//! vertices Melax collapses (each corner keeping its surface vertex as its
//! texture coordinate id), the image re-encoded as PNG for the GLB.

use anyhow::Context;
use std::path::Path;
use vitrine_mesh::import::md2::Md2;
use vitrine_mesh::import::{import_path_textured, ImportOptions, TexturedSurface};

/// A texture for the GLB: coordinates by id, and the surface whose image
/// it is.
pub(super) struct Texture {
    pub(super) uvs: Vec<[f32; 2]>,
    pub(super) surface: TexturedSurface,
}

/// The MD2's skin as found by the importer, with the MD2's coordinates.
pub(super) fn md2_texture(path: &Path, model: &Md2) -> anyhow::Result<Option<Texture>> {
    let imported = import_path_textured(path, &ImportOptions::default())
        .with_context(|| format!("reading {}", path.display()))?;
    for w in &imported.warnings {
        eprintln!("warning: {}: {w}", path.display());
    }
    let Some(surface) = imported.texture else {
        return Ok(None);
    };
    let (w, h) = (model.skin_width as f32, model.skin_height as f32);
    Ok(Some(Texture {
        uvs: model
            .st
            .iter()
            .map(|&[s, t]| [f32::from(s) / w, f32::from(t) / h])
            .collect(),
        surface,
    }))
}

/// A textured surface welded by position (exactly equal coordinates):
/// positions, triangles (those a weld makes degenerate dropped) and the
/// surface vertex of each corner.
pub(super) type Welded = (Vec<[f32; 3]>, Vec<[u32; 3]>, Vec<[u32; 3]>);

pub(super) fn weld(surface: &TexturedSurface) -> Welded {
    let mut index = std::collections::HashMap::new();
    let mut positions = Vec::new();
    let welded: Vec<u32> = surface
        .positions
        .iter()
        .map(|p| {
            *index.entry(p.map(f32::to_bits)).or_insert_with(|| {
                positions.push(*p);
                (positions.len() - 1) as u32
            })
        })
        .collect();
    let (mut triangles, mut corners) = (Vec::new(), Vec::new());
    for t in &surface.triangles {
        let w = t.map(|v| welded[v as usize]);
        if w[0] != w[1] && w[1] != w[2] && w[0] != w[2] {
            triangles.push(w);
            corners.push(*t);
        }
    }
    (positions, triangles, corners)
}
