//! PCX skins (Quake II's), through the `pcx` crate: the `image` crate does
//! not read PCX. The dimensions in the header are checked against the pixel
//! budget before any pixel memory is taken.

use image::RgbImage;

use crate::{Error, Result};

const WHAT: &str = "PCX image";

/// Whether `bytes` start like a PCX file: the ZSoft manufacturer byte 10,
/// a known version, RLE or no encoding.
pub(super) fn is_pcx(bytes: &[u8]) -> bool {
    matches!(bytes, [10, 0 | 2 | 3 | 4 | 5, 0 | 1, 1 | 2 | 4 | 8, ..])
}

/// Decodes a paletted or 24-bit PCX into 8-bit RGB.
pub(super) fn decode(bytes: &[u8], name: &str, max_pixels: u64) -> Result<RgbImage> {
    let bad = |e: std::io::Error| Error::input(WHAT, format!("{name}: {e}"));
    let mut reader = pcx::Reader::from_mem(bytes).map_err(bad)?;
    let (w, h) = reader.dimensions();
    let pixels = u64::from(w) * u64::from(h);
    if pixels == 0 {
        return Err(Error::input(WHAT, format!("{name}: image is {w} × {h}")));
    }
    if pixels > max_pixels {
        return Err(Error::Limit(format!(
            "{name}: texture is {w} × {h} = {pixels} pixels, more than the limit of {max_pixels}"
        )));
    }
    // RLE expands at most 63 times: a header claiming more pixels than the
    // file can hold is refused before the buffers exist.
    if pixels > 63 * bytes.len() as u64 {
        return Err(Error::input(
            WHAT,
            format!(
                "{name}: {w} × {h} pixels cannot fit in {} bytes",
                bytes.len()
            ),
        ));
    }
    let (w, h) = (usize::from(w), usize::from(h));
    let mut rgb = vec![0u8; 3 * w * h];
    if reader.is_paletted() {
        let mut indices = vec![0u8; w * h];
        for row in indices.chunks_exact_mut(w) {
            reader.next_row_paletted(row).map_err(bad)?;
        }
        let mut palette = [0u8; 256 * 3];
        let colours = reader.read_palette(&mut palette).map_err(bad)?;
        for (px, &i) in rgb.chunks_exact_mut(3).zip(&indices) {
            let i = usize::from(i);
            if i >= colours {
                return Err(Error::input(
                    WHAT,
                    format!("{name}: pixel uses colour {i} of a {colours}-colour palette"),
                ));
            }
            px.copy_from_slice(&palette[3 * i..3 * i + 3]);
        }
    } else {
        for row in rgb.chunks_exact_mut(3 * w) {
            reader.next_row_rgb(row).map_err(bad)?;
        }
    }
    RgbImage::from_raw(w as u32, h as u32, rgb)
        .ok_or_else(|| Error::input(WHAT, format!("{name}: pixel buffer size")))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paletted_pcx_decodes_through_its_palette() {
        let (w, h) = (5u16, 3u16);
        let mut bytes = Vec::new();
        let mut writer = pcx::WriterPaletted::new(&mut bytes, (w, h), (72, 72)).unwrap();
        for y in 0..h {
            let row: Vec<u8> = (0..w).map(|x| (x + y) as u8).collect();
            writer.write_row(&row).unwrap();
        }
        let palette: Vec<u8> = (0..=255u8).flat_map(|i| [i, 255 - i, i / 2]).collect();
        writer.write_palette(&palette).unwrap();
        assert!(is_pcx(&bytes));
        let image = decode(&bytes, "t", 1 << 20).unwrap();
        assert_eq!(image.dimensions(), (5, 3));
        assert_eq!(image.get_pixel(4, 2).0, [6, 249, 3]);
        let e = decode(&bytes, "t", 10).unwrap_err().to_string();
        assert!(e.contains("limit"), "{e}");
    }

    #[test]
    fn mutated_headers_are_errors_not_panics() {
        let mut bytes = Vec::new();
        let mut writer = pcx::WriterRgb::new(&mut bytes, (6, 4), (72, 72)).unwrap();
        for _ in 0..4 {
            writer.write_row(&[7u8; 18]).unwrap();
        }
        writer.finish().unwrap();
        // Every value of every header byte (the header is 128 bytes).
        for at in 0..128 {
            for value in 0..=255u8 {
                let mut b = bytes.clone();
                b[at] = value;
                let r = std::panic::catch_unwind(|| decode(&b, "t", 1 << 16).is_ok());
                assert!(r.is_ok(), "byte {at} = {value} panics");
            }
        }
    }
}
