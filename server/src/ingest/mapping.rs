//! A cell complex made storable: its three images checked against its
//! parameters (from their headers, without decoding) and made into rows.

use crate::storage::{NewTexture, NewTextureMapping};
use anyhow::{bail, Context};
use vitrine_colour::ccc::{CccParameters, CccReport, TextureMapping};

/// The rows of a mapping, after checking that each image is what the
/// parameters say: a PNG of the cell texture's size (8-bit RGB) and two
/// JPEGs of the atlas's full and reduced size.
pub(super) fn new_mapping(m: &TextureMapping) -> anyhow::Result<(NewTextureMapping, CccReport)> {
    let p: &CccParameters = &m.parameters;
    check_parameters(p)?;
    let (w, h, depth, colour_type) =
        image_size::png(&m.cell_png).context("the cell texture is not a PNG")?;
    if (w, h) != (p.cell_texture.width, p.cell_texture.height) || (depth, colour_type) != (8, 2) {
        bail!(
            "the cell texture is {w}×{h} (bit depth {depth}, colour type {colour_type}); \
             the parameters say {}×{} 8-bit RGB",
            p.cell_texture.width,
            p.cell_texture.height
        );
    }
    let full = (p.atlas.width, p.atlas.height);
    let low = (
        p.atlas.width.div_ceil(p.low_res_factor),
        p.atlas.height.div_ceil(p.low_res_factor),
    );
    for (what, bytes, want) in [
        ("colour texture", &m.colour_jpeg, full),
        ("low-resolution colour texture", &m.colour_low_jpeg, low),
    ] {
        let size = image_size::jpeg(bytes).with_context(|| format!("the {what} is not a JPEG"))?;
        if size != want {
            bail!(
                "the {what} is {}×{}; the parameters say {}×{}",
                size.0,
                size.1,
                want.0,
                want.1
            );
        }
    }
    let texture = |kind, media_type, (width, height): (u32, u32), bytes: &Vec<u8>| NewTexture {
        kind,
        media_type,
        width,
        height,
        bytes: bytes.clone(),
    };
    Ok((
        NewTextureMapping {
            parameters: serde_json::to_string(p)?,
            cell: texture("cell", "image/png", (w, h), &m.cell_png),
            colour: texture("colour", "image/jpeg", full, &m.colour_jpeg),
            colour_low: texture("colour", "image/jpeg", low, &m.colour_low_jpeg),
        },
        m.report,
    ))
}

/// The parameters agree with themselves: a version this build reads, and a
/// cell texture large enough for the grid and the cells after it.
fn check_parameters(p: &CccParameters) -> anyhow::Result<()> {
    if p.version != 1 {
        bail!("CCC version {} is not supported (1 is)", p.version);
    }
    if p.low_res_factor == 0 || p.cell_size.is_nan() || p.cell_size <= 0.0 {
        bail!("CCC parameters have a zero low-resolution factor or cell size");
    }
    let grid = u64::from(p.dims[0]) * u64::from(p.dims[1]) * u64::from(p.dims[2]);
    let cell_texels = u64::from(p.cell_texture.width) * u64::from(p.cell_texture.height);
    if u64::from(p.cell_texture.cells_offset) != grid || grid + 4 * u64::from(p.cells) > cell_texels
    {
        bail!(
            "cell texture {}×{} cannot hold a {}×{}×{} grid and {} cells at offset {}",
            p.cell_texture.width,
            p.cell_texture.height,
            p.dims[0],
            p.dims[1],
            p.dims[2],
            p.cells,
            p.cell_texture.cells_offset
        );
    }
    Ok(())
}

/// Image sizes from the headers, without decoding.
mod image_size {
    use anyhow::{bail, Context};

    /// Width, height, bit depth and colour type from the IHDR chunk.
    pub fn png(bytes: &[u8]) -> anyhow::Result<(u32, u32, u8, u8)> {
        const SIGNATURE: &[u8] = b"\x89PNG\r\n\x1a\n";
        if bytes.len() < 33 || &bytes[..8] != SIGNATURE || &bytes[12..16] != b"IHDR" {
            bail!("no PNG signature and IHDR chunk");
        }
        let be = |at: usize| {
            u32::from_be_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]])
        };
        Ok((be(16), be(20), bytes[24], bytes[25]))
    }

    /// Width and height from the first start-of-frame marker.
    pub fn jpeg(bytes: &[u8]) -> anyhow::Result<(u32, u32)> {
        if bytes.get(..2) != Some(&[0xff, 0xd8]) {
            bail!("no start-of-image marker");
        }
        let mut at = 2;
        loop {
            let marker = bytes.get(at..at + 4).context("no start-of-frame marker")?;
            if marker[0] != 0xff {
                bail!("damaged marker at byte {at}");
            }
            if marker[1] == 0xff {
                at += 1; // fill byte
                continue;
            }
            let len = usize::from(u16::from_be_bytes([marker[2], marker[3]]));
            // SOF0–SOF15 except DHT (C4), JPG (C8) and DAC (CC).
            if (0xc0..=0xcf).contains(&marker[1]) && ![0xc4, 0xc8, 0xcc].contains(&marker[1]) {
                let frame = bytes
                    .get(at + 5..at + 9)
                    .context("truncated start of frame")?;
                let height = u32::from(u16::from_be_bytes([frame[0], frame[1]]));
                let width = u32::from(u16::from_be_bytes([frame[2], frame[3]]));
                return Ok((width, height));
            }
            at += 2 + len;
        }
    }
}
