//! Cubic cell complex colour mapping (thesis ch. 5; Apaza-Agüero, Silva &
//! Bellon 2011): colour lives in one texture shared by every level, reached
//! through a grid of cubes around the surface. The layout is in `codec/colour/CCC.md`.

mod build;
mod grid;
mod guard;
mod images;
mod lookup;
mod projection;

use serde::{Deserialize, Serialize};

pub use guard::CellGuard;
pub use lookup::CellComplex;

use vitrine_codec::{Encoded, Encoder, IndexedMesh, Quantization, Result};
use vitrine_mesh::import::TexturedSurface;

/// Everything a viewer needs besides the two images (`CCC.md`, "Parameters").
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CccParameters {
    pub version: u32,
    pub origin: [f32; 3],
    pub cell_size: f32,
    pub dims: [u32; 3],
    pub cells: u32,
    pub cell_texture: CellTextureLayout,
    pub tile_size: u32,
    pub gutter: u32,
    pub atlas: AtlasLayout,
    pub low_res_factor: u32,
    pub fallback_colour: [u8; 3],
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct CellTextureLayout {
    pub width: u32,
    pub height: u32,
    pub cells_offset: u32,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct AtlasLayout {
    pub width: u32,
    pub height: u32,
    pub tiles_per_row: u32,
    pub tiles: u32,
}

/// How well the complex fits the surface.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct CccReport {
    pub cells: u32,
    pub tiles: u32,
    /// Texels whose ray met the surface more than once inside the cube.
    pub ambiguous_texels: u64,
    /// Texels whose ray met the surface at all.
    pub covered_texels: u64,
    pub cell_texture_bytes: u64,
    pub colour_texture_bytes: u64,
    pub colour_texture_low_bytes: u64,
}

/// A built mapping, ready to store: parameters plus the encoded images.
#[derive(Clone, Debug)]
pub struct TextureMapping {
    pub parameters: CccParameters,
    /// PNG, 8-bit RGB.
    pub cell_png: Vec<u8>,
    /// JPEG atlas at full resolution.
    pub colour_jpeg: Vec<u8>,
    /// JPEG atlas at `1 / low_res_factor` of the resolution.
    pub colour_low_jpeg: Vec<u8>,
    pub report: CccReport,
}

/// Where the full-resolution colour comes from.
#[derive(Clone, Copy, Debug)]
pub enum ColourSource<'a> {
    /// Per-vertex colour of the mesh itself.
    PerVertex(&'a IndexedMesh),
    /// A photographic texture through the file's UVs.
    Texture(&'a TexturedSurface),
}

/// Choices for building a complex; `Default` picks sizes from the geometry.
#[derive(Clone, Debug, PartialEq)]
pub struct CccOptions {
    /// Cube edge in model units; `None`: from the bounding box and vertex count.
    pub cell_size: Option<f32>,
    /// Tile interior in texels per side; `None`: from the vertex count.
    pub tile_size: Option<u32>,
    pub jpeg_quality: u8,
    pub low_res_factor: u32,
    /// Largest atlas side in texels.
    pub max_atlas_side: u32,
}

impl Default for CccOptions {
    fn default() -> Self {
        CccOptions {
            cell_size: None,
            tile_size: None,
            jpeg_quality: 90,
            low_res_factor: 4,
            max_atlas_side: 4096,
        }
    }
}

/// Builds the complex of a mesh (before encoding; the same quantization as
/// the stream) and the guard that keeps every level inside it.
pub fn build(
    mesh: &IndexedMesh,
    quantization: &Quantization,
    source: ColourSource<'_>,
    options: &CccOptions,
) -> Result<(TextureMapping, CellGuard)> {
    let built = build::build_cells(mesh, quantization, source, options)?;
    let images = images::write(&built, options)?;
    let guard = CellGuard::new(built.grid, &built.cell_of_cube, *quantization);
    let report = CccReport {
        cells: images.parameters.cells,
        tiles: images.parameters.atlas.tiles,
        ambiguous_texels: built.ambiguous_texels,
        covered_texels: built.covered_texels,
        cell_texture_bytes: images.cell_png.len() as u64,
        colour_texture_bytes: images.colour_jpeg.len() as u64,
        colour_texture_low_bytes: images.colour_low_jpeg.len() as u64,
    };
    drop(images.atlas);
    Ok((
        TextureMapping {
            parameters: images.parameters,
            cell_png: images.cell_png,
            colour_jpeg: images.colour_jpeg,
            colour_low_jpeg: images.colour_low_jpeg,
            report,
        },
        guard,
    ))
}

/// Encodes a mesh in `ccc` mode: the complex is built from `source`, the
/// stream carries geometry and connectivity only (no per-vertex colour),
/// and every decimation is guarded by the complex.
pub fn encode_with_ccc(
    mesh: &IndexedMesh,
    source: ColourSource<'_>,
    ccc: &CccOptions,
    encoder: Encoder<'_>,
) -> Result<(Encoded, TextureMapping)> {
    let bits = encoder.options().quantization_bits;
    let quantization = Quantization::for_positions(&mesh.positions, bits)?;
    let (mapping, guard) = build(mesh, &quantization, source, ccc)?;
    let geometry_only = IndexedMesh {
        positions: mesh.positions.clone(),
        colors: None,
        triangles: mesh.triangles.clone(),
    };
    let encoded = encoder.guard(&guard).encode(&geometry_only)?;
    Ok((encoded, mapping))
}
