//! One mesh, its colour carried the way a [`ColourMode`] says.

use serde::{Deserialize, Serialize};
use vitrine_codec::{Encoded, Encoder, Error, IndexedMesh, Result};
use vitrine_mesh::import::TexturedSurface;
use vitrine_mesh::texel::sample_bilinear;

use crate::border_guard::ColourBorderGuard;
use crate::ccc::{encode_with_ccc, CccOptions, ColourSource, TextureMapping};

/// How colour travels: the thesis' three approaches on one codec, or none.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ColourMode {
    /// Cubic cell complex texture shared by every level, guarded decimation.
    Ccc,
    /// Per-vertex colour in the stream.
    Vertex,
    /// Per-vertex colour plus the Lee–Lavoué–Dupont 2012 colour metric guard.
    VertexMetric,
    /// Geometry only.
    None,
}

impl ColourMode {
    pub const ALL: [ColourMode; 4] = [
        ColourMode::Ccc,
        ColourMode::Vertex,
        ColourMode::VertexMetric,
        ColourMode::None,
    ];

    pub fn name(self) -> &'static str {
        match self {
            ColourMode::Ccc => "ccc",
            ColourMode::Vertex => "vertex",
            ColourMode::VertexMetric => "vertex-metric",
            ColourMode::None => "none",
        }
    }
}

impl std::fmt::Display for ColourMode {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for ColourMode {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        ColourMode::ALL
            .into_iter()
            .find(|m| m.name() == s)
            .ok_or_else(|| {
                Error::Parameter(format!(
                    "colour mode must be ccc, vertex, vertex-metric or none, got {s:?}"
                ))
            })
    }
}

/// The texture's colour at each mesh vertex (bilinear through the file's
/// UVs), matched by position: welding and repair keep positions exactly.
/// A vertex on a UV seam takes the first side's colour.
pub fn vertex_colours_from_texture(mesh: &IndexedMesh, texture: &TexturedSurface) -> Vec<[u8; 3]> {
    let key = |p: [f32; 3]| p.map(f32::to_bits);
    let mut by_position = std::collections::HashMap::with_capacity(texture.positions.len());
    for (p, uv) in texture.positions.iter().zip(&texture.uvs) {
        by_position.entry(key(*p)).or_insert(*uv);
    }
    mesh.positions
        .iter()
        .map(|p| match by_position.get(&key(*p)) {
            Some(uv) => {
                sample_bilinear(&texture.image, glam::DVec2::new(uv[0] as f64, uv[1] as f64))
                    .map(|c| c.round().clamp(0.0, 255.0) as u8)
            }
            None => [128, 128, 128],
        })
        .collect()
}

/// Encodes a mesh with its colour carried the way `mode` says. The colour
/// comes from `texture` when given, else from the mesh's per-vertex colour.
/// The guards `encoder` already has run beside the colour mode's own.
pub fn encode_coloured(
    mesh: &IndexedMesh,
    texture: Option<&TexturedSurface>,
    mode: ColourMode,
    ccc: &CccOptions,
    encoder: Encoder<'_>,
) -> Result<(Encoded, Option<TextureMapping>)> {
    let no_colour = || {
        Error::Parameter(format!(
            "colour mode {mode} needs colour, and the mesh has neither a texture nor per-vertex colour"
        ))
    };
    let with_vertex_colours = || -> Result<IndexedMesh> {
        let colors = match texture {
            Some(t) => vertex_colours_from_texture(mesh, t),
            None => mesh.colors.clone().ok_or_else(no_colour)?,
        };
        Ok(IndexedMesh {
            colors: Some(colors),
            ..mesh.clone()
        })
    };
    match mode {
        ColourMode::Ccc => {
            let source = match texture {
                Some(t) => ColourSource::Texture(t),
                None if mesh.colors.is_some() => ColourSource::PerVertex(mesh),
                None => return Err(no_colour()),
            };
            let (encoded, mapping) = encode_with_ccc(mesh, source, ccc, encoder)?;
            Ok((encoded, Some(mapping)))
        }
        ColourMode::Vertex => Ok((encoder.encode(&with_vertex_colours()?)?, None)),
        ColourMode::VertexMetric => {
            let guard = ColourBorderGuard::default();
            Ok((encoder.guard(&guard).encode(&with_vertex_colours()?)?, None))
        }
        ColourMode::None => {
            let geometry = IndexedMesh {
                colors: None,
                ..mesh.clone()
            };
            Ok((encoder.encode(&geometry)?, None))
        }
    }
}
