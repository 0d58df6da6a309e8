//! The viewer's colour lookup on the CPU, read back from the stored images:
//! for tests, the quality metrics and the CPU renderer.

use glam::{DVec3, Vec3};
use image::RgbImage;

use super::grid::Grid;
use super::images::CELL_TEXELS;
use super::projection::exit_face;
use super::CccParameters;
use vitrine_codec::{Error, Result};
use vitrine_mesh::texel::bilinear;

#[derive(Clone, Copy, Debug)]
struct CellRecord {
    centre: DVec3,
    first_tile: u32,
    mask: u8,
    mean: [f32; 3],
}

/// A complex decoded from its cell texture and one colour atlas.
#[derive(Clone, Debug)]
pub struct CellComplex {
    grid: Grid,
    cell_of_cube: Vec<u32>,
    cells: Vec<CellRecord>,
    atlas: RgbImage,
    /// Atlas texels per layout texel (1 for the full atlas, `1/f` for the low one).
    scale: f64,
    parameters: CccParameters,
}

impl CellComplex {
    /// Reads the images as a viewer would; `atlas` may be the full or the
    /// low-resolution JPEG.
    pub fn from_images(parameters: &CccParameters, cell_png: &[u8], atlas: &[u8]) -> Result<Self> {
        let p = parameters;
        let cell = image::load_from_memory_with_format(cell_png, image::ImageFormat::Png)
            .map_err(super::images::image_error)?
            .to_rgb8();
        let atlas = image::load_from_memory(atlas)
            .map_err(super::images::image_error)?
            .to_rgb8();
        let bad = |what: &str| Error::input("cell complex", what.to_string());
        if cell.width() != p.cell_texture.width || cell.height() != p.cell_texture.height {
            return Err(bad("cell texture size differs from its parameters"));
        }
        let cubes = p.dims.iter().map(|&d| d as u64).product::<u64>();
        let needed = cubes + CELL_TEXELS as u64 * p.cells as u64;
        if cubes != p.cell_texture.cells_offset as u64
            || needed > cell.width() as u64 * cell.height() as u64
        {
            return Err(bad("cell texture too small for its grid and cells"));
        }
        let texel = |i: u64| {
            let px = cell
                .get_pixel(
                    (i % cell.width() as u64) as u32,
                    (i / cell.width() as u64) as u32,
                )
                .0;
            px[0] as u32 | (px[1] as u32) << 8 | (px[2] as u32) << 16
        };
        let mut cell_of_cube = Vec::with_capacity(cubes as usize);
        for i in 0..cubes {
            let n = texel(i);
            if n > p.cells {
                return Err(bad("grid names a cell that does not exist"));
            }
            cell_of_cube.push(n.wrapping_sub(1));
        }
        let mut cells = Vec::with_capacity(p.cells as usize);
        for c in 0..p.cells as u64 {
            let base = cubes + CELL_TEXELS as u64 * c;
            let centre = texel(base).to_le_bytes();
            let mean = texel(base + 3).to_le_bytes();
            let first_tile = texel(base + 1);
            let mask = texel(base + 2) as u8;
            if first_tile + mask.count_ones() > p.atlas.tiles {
                return Err(bad("cell names a tile outside the atlas"));
            }
            cells.push(CellRecord {
                centre: DVec3::new(centre[0] as f64, centre[1] as f64, centre[2] as f64) / 256.0
                    + DVec3::splat(0.5 / 256.0),
                first_tile,
                mask,
                mean: [0, 1, 2].map(|k| mean[k] as f32 / 255.0),
            });
        }
        let scale = atlas.width() as f64 / p.atlas.width.max(1) as f64;
        Ok(CellComplex {
            grid: Grid {
                origin: Vec3::from(p.origin).as_dvec3(),
                cell_size: p.cell_size as f64,
                dims: glam::UVec3::from(p.dims).as_ivec3(),
            },
            cell_of_cube,
            cells,
            atlas,
            scale,
            parameters: p.clone(),
        })
    }

    /// Colour (sRGB, 0–1) at a world position, as the viewer's shader finds it.
    pub fn colour_at(&self, p: Vec3) -> [f32; 3] {
        let p = p.as_dvec3();
        let fallback = self.parameters.fallback_colour.map(|c| c as f32 / 255.0);
        let cube = self.grid.cube_of(p);
        if !self.grid.contains(cube) {
            return fallback;
        }
        let n = self.cell_of_cube[self.grid.index(cube)];
        let Some(cell) = self.cells.get(n as usize) else {
            return fallback;
        };
        let local = (p - self.grid.cube_min(cube)) / self.grid.cell_size;
        let Some((face, uv)) = exit_face(cell.centre, local) else {
            return cell.mean;
        };
        if cell.mask & (1 << face) == 0 {
            return cell.mean;
        }
        let tile = cell.first_tile + (cell.mask & ((1u8 << face) - 1)).count_ones();
        self.sample_tile(tile, uv)
    }

    fn sample_tile(&self, tile: u32, uv: [f64; 2]) -> [f32; 3] {
        let a = &self.parameters;
        let (t, g) = (a.tile_size as f64, a.gutter as f64);
        let side = t + 2.0 * g;
        let (col, row) = (
            (tile % a.atlas.tiles_per_row) as f64,
            (tile / a.atlas.tiles_per_row) as f64,
        );
        // Half a texel of the atlas being sampled inside the tile, so the
        // bilinear footprint stays in the tile at either resolution.
        let inset = (0.5 / self.scale).max(0.5).min(t / 2.0);
        let local = uv.map(|c| (g + c * t).clamp(g + inset, g + t - inset));
        let x = (col * side + local[0]) * self.scale;
        let y = (row * side + local[1]) * self.scale;
        let clamp = |i: i64, n: i64| i.clamp(0, n - 1);
        bilinear(&self.atlas, x, y, clamp).map(|c| (c / 255.0) as f32)
    }

    pub fn parameters(&self) -> &CccParameters {
        &self.parameters
    }
}
