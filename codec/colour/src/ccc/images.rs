//! Writing the complex as its two images (`CCC.md`): the cell texture (PNG)
//! and the colour atlas (JPEG, full and low resolution).

use image::codecs::jpeg::JpegEncoder;
use image::codecs::png::{CompressionType, FilterType, PngEncoder};
use image::{ExtendedColorType, ImageEncoder, RgbImage};

use super::build::Built;
use super::{AtlasLayout, CccOptions, CccParameters, CellTextureLayout};
use vitrine_codec::{Error, Result};

/// Texels around each tile's interior, copies of its edge.
pub const GUTTER: u32 = 1;
/// Texels per cell record in the cell texture.
pub const CELL_TEXELS: u32 = 4;

pub(crate) struct Images {
    pub parameters: CccParameters,
    pub cell_png: Vec<u8>,
    pub atlas: RgbImage,
    pub colour_jpeg: Vec<u8>,
    pub colour_low_jpeg: Vec<u8>,
}

pub(crate) fn write(built: &Built, options: &CccOptions) -> Result<Images> {
    let tiles: u32 = built
        .cells
        .iter()
        .map(|c| c.tiles.iter().flatten().count() as u32)
        .sum();
    if tiles >= 1 << 24 {
        return Err(Error::Limit(format!(
            "{tiles} tiles do not fit 24-bit tile numbers"
        )));
    }
    let t = built.tile_size;
    let side = t + 2 * GUTTER;
    let per_row = (tiles.max(1) as f64).sqrt().ceil() as u32;
    let rows = tiles.max(1).div_ceil(per_row);
    let (width, height) = (per_row * side, rows * side);
    if width > options.max_atlas_side || height > options.max_atlas_side {
        return Err(Error::Limit(format!(
            "colour atlas {width}×{height} exceeds {} texels a side; choose a smaller tile or larger cell size",
            options.max_atlas_side
        )));
    }

    // Cell texture: the grid, then four texels per cell.
    let cubes = built.grid.cube_count() as u32;
    let texels = cubes as u64 + CELL_TEXELS as u64 * built.cells.len() as u64;
    let cell_width = ((texels as f64).sqrt().ceil() as u32)
        .next_power_of_two()
        .clamp(64, 4096);
    let cell_height = (texels.div_ceil(cell_width as u64)) as u32;
    if cell_height > 4096 {
        return Err(Error::Limit(format!(
            "cell texture needs {texels} texels, more than 4096²"
        )));
    }
    let mut cell_tex = vec![0u8; (cell_width as usize) * (cell_height as usize) * 3];
    let mut put = |i: u64, rgb: [u8; 3]| {
        let o = i as usize * 3;
        cell_tex[o..o + 3].copy_from_slice(&rgb);
    };
    let number = |n: u32| [(n & 255) as u8, ((n >> 8) & 255) as u8, (n >> 16) as u8];
    for (i, &c) in built.cell_of_cube.iter().enumerate() {
        if c != u32::MAX {
            put(i as u64, number(c + 1));
        }
    }

    let mut atlas = RgbImage::new(width, height);
    let mut next_tile = 0u32;
    let (mut sum, mut n) = ([0u64; 3], 0u64);
    for (ci, cell) in built.cells.iter().enumerate() {
        let base = cubes as u64 + CELL_TEXELS as u64 * ci as u64;
        let mut mask = 0u8;
        put(base, cell.centre);
        put(base + 1, number(next_tile));
        for (face, tile) in cell.tiles.iter().enumerate() {
            let Some(tile) = tile else { continue };
            mask |= 1 << face;
            let (x0, y0) = ((next_tile % per_row) * side, (next_tile / per_row) * side);
            for y in 0..side {
                for x in 0..side {
                    // Gutter texels repeat the nearest interior texel.
                    let ix = x.saturating_sub(GUTTER).min(t - 1);
                    let iy = y.saturating_sub(GUTTER).min(t - 1);
                    atlas.put_pixel(x0 + x, y0 + y, image::Rgb(tile[(iy * t + ix) as usize]));
                }
            }
            next_tile += 1;
        }
        put(base + 2, [mask, 0, 0]);
        put(base + 3, cell.mean);
        (0..3).for_each(|k| sum[k] += cell.mean[k] as u64);
        n += 1;
    }
    let fallback = sum.map(|s| (s / n.max(1)) as u8);

    let mut cell_png = Vec::new();
    PngEncoder::new_with_quality(&mut cell_png, CompressionType::Best, FilterType::Adaptive)
        .write_image(&cell_tex, cell_width, cell_height, ExtendedColorType::Rgb8)
        .map_err(image_error)?;
    let factor = options.low_res_factor.max(1);
    let low = image::imageops::resize(
        &atlas,
        width.div_ceil(factor),
        height.div_ceil(factor),
        image::imageops::FilterType::Triangle,
    );
    let colour_jpeg = jpeg(&atlas, options.jpeg_quality)?;
    let colour_low_jpeg = jpeg(&low, options.jpeg_quality)?;
    let g = &built.grid;
    Ok(Images {
        parameters: CccParameters {
            version: 1,
            origin: g.origin.as_vec3().to_array(),
            cell_size: g.cell_size as f32,
            dims: g.dims.as_uvec3().to_array(),
            cells: built.cells.len() as u32,
            cell_texture: CellTextureLayout {
                width: cell_width,
                height: cell_height,
                cells_offset: cubes,
            },
            tile_size: t,
            gutter: GUTTER,
            atlas: AtlasLayout {
                width,
                height,
                tiles_per_row: per_row,
                tiles,
            },
            low_res_factor: factor,
            fallback_colour: fallback,
        },
        cell_png,
        atlas,
        colour_jpeg,
        colour_low_jpeg,
    })
}

fn jpeg(image: &RgbImage, quality: u8) -> Result<Vec<u8>> {
    let mut out = Vec::new();
    JpegEncoder::new_with_quality(&mut out, quality.clamp(1, 100))
        .encode_image(image)
        .map_err(image_error)?;
    Ok(out)
}

pub(crate) fn image_error(e: image::ImageError) -> Error {
    Error::input("texture", e.to_string())
}
