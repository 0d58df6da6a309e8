//! Texture images (PNG, JPEG) for [`super::import_path_textured`].
//!
//! The image is hostile input like the mesh: its dimensions are read from
//! the header and checked against [`super::ImportOptions::max_texture_pixels`]
//! before anything is decoded, and the decoder then runs under an
//! [`image::Limits`] allocation budget sized for those dimensions. A header
//! that claims 100 000 × 100 000 pixels is refused without allocating.
//!
//! Texture references are only followed inside the model's folder (see
//! [`resolve`]).

use std::io::{BufRead, Cursor, Seek};
use std::path::{Component, Path, PathBuf};

use image::{ImageError, ImageFormat, ImageReader, Limits, RgbImage};

use crate::{Error, Result};

const WHAT: &str = "texture image";

/// Decoder working memory allowed on top of the decoded pixels.
const SLACK_BYTES: u64 = 64 << 20;

/// Where a texture's bytes come from.
pub(super) enum Source<'a> {
    File(&'a Path),
    Bytes(&'a [u8]),
}

/// Decodes a PNG, JPEG, TGA or PCX into 8-bit RGB (grey is replicated, alpha dropped,
/// 16-bit channels scaled). `name` says which texture, for messages.
///
/// `Ok(Err(warning))` is for textures that are absent or in a format this
/// build does not read: the geometry is still good. Malformed and oversized
/// images are errors.
pub(super) fn load(
    src: Source<'_>,
    name: &str,
    max_pixels: u64,
) -> Result<std::result::Result<RgbImage, String>> {
    match src {
        Source::Bytes(b) if super::pcx::is_pcx(b) => {
            super::pcx::decode(b, name, max_pixels).map(Ok)
        }
        Source::Bytes(b) => decode(|| Ok(Cursor::new(b)), None, name, max_pixels),
        Source::File(path) => {
            let open = || std::fs::File::open(path).map(std::io::BufReader::new);
            match open() {
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(Err(format!(
                    "{name}: texture file {} not found; imported without texture",
                    path.display()
                ))),
                Err(e) => Err(Error::Io(std::io::Error::new(
                    e.kind(),
                    format!("{name}: {}: {e}", path.display()),
                ))),
                Ok(_) if path.is_dir() => Ok(Err(format!(
                    "{name}: {} is a folder, not a texture image; imported without texture",
                    path.display()
                ))),
                Ok(_) if starts_like_pcx(path) => {
                    let bytes = std::fs::read(path).map_err(|e| {
                        Error::Io(std::io::Error::new(
                            e.kind(),
                            format!("{name}: {}: {e}", path.display()),
                        ))
                    })?;
                    super::pcx::decode(&bytes, name, max_pixels).map(Ok)
                }
                // TGA has no signature: its extension says what it is.
                Ok(_) => decode(open, ImageFormat::from_path(path).ok(), name, max_pixels),
            }
        }
    }
}

/// PCX has no magic `image` knows: peek at the first bytes.
fn starts_like_pcx(path: &Path) -> bool {
    use std::io::Read;
    let mut head = [0u8; 4];
    std::fs::File::open(path)
        .and_then(|mut f| f.read_exact(&mut head))
        .is_ok_and(|()| super::pcx::is_pcx(&head))
}

fn decode<R: BufRead + Seek>(
    open: impl Fn() -> std::io::Result<R>,
    hint: Option<ImageFormat>,
    name: &str,
    max_pixels: u64,
) -> Result<std::result::Result<RgbImage, String>> {
    let io = |e: std::io::Error| Error::Io(std::io::Error::new(e.kind(), format!("{name}: {e}")));
    let reader = ImageReader::new(open().map_err(io)?)
        .with_guessed_format()
        .map_err(io)?;
    let guessed = match (reader.format(), hint) {
        (None, Some(ImageFormat::Tga)) => Some(ImageFormat::Tga),
        (f, _) => f,
    };
    let format = match guessed {
        Some(f @ (ImageFormat::Png | ImageFormat::Jpeg | ImageFormat::Tga)) => f,
        Some(f) => {
            return Ok(Err(format!(
                "{name}: {f:?} textures are not read (only PNG, JPEG, TGA and PCX); \
                 imported without texture"
            )))
        }
        None => {
            return Err(Error::input(
                WHAT,
                format!("{name}: not a PNG or JPEG file (unrecognised signature)"),
            ))
        }
    };
    // Header only: no pixel memory yet.
    let reader = ImageReader::with_format(open().map_err(io)?, format);
    let (w, h) = reader.into_dimensions().map_err(|e| image_error(e, name))?;
    let pixels = w as u64 * h as u64;
    if pixels == 0 {
        return Err(Error::input(WHAT, format!("{name}: image is {w} × {h}")));
    }
    if pixels > max_pixels {
        return Err(Error::Limit(format!(
            "{name}: texture is {w} × {h} = {pixels} pixels, more than the limit of {max_pixels}"
        )));
    }
    let mut limits = Limits::default();
    limits.max_image_width = Some(w);
    limits.max_image_height = Some(h);
    // Pixels at up to 16 bits × 4 channels, twice over for the decoder's own
    // buffers, plus a fixed allowance.
    limits.max_alloc = Some(pixels * 16 + SLACK_BYTES);
    let mut reader = ImageReader::with_format(open().map_err(io)?, format);
    reader.limits(limits);
    let image = reader.decode().map_err(|e| image_error(e, name))?;
    Ok(Ok(image.into_rgb8()))
}

fn image_error(e: ImageError, name: &str) -> Error {
    match e {
        ImageError::Limits(l) => Error::Limit(format!("{name}: {l}")),
        ImageError::IoError(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => {
            Error::input(WHAT, format!("{name}: truncated: {e}"))
        }
        ImageError::IoError(e) => Error::Io(std::io::Error::new(e.kind(), format!("{name}: {e}"))),
        ImageError::Unsupported(u) => Error::Unsupported(format!("{name}: {u}")),
        e => Error::input(WHAT, format!("{name}: {e}")),
    }
}

/// A texture reference resolved inside `base` (the model's folder).
pub(super) enum Resolved {
    /// The reference as written, inside the folder.
    Inside(PathBuf),
    /// The reference was absolute or climbed out of the folder; only its
    /// file name is looked for beside the model. Carries a warning.
    FileNameOnly(PathBuf, String),
    /// Nothing can be followed (the warning says why).
    Refused(String),
}

/// Resolves a file reference from an OBJ/MTL file (`mtllib`, `map_Kd`)
/// against the OBJ's folder. OBJ exporters often write the author's own
/// absolute path (`C:\scans\vase\vase.jpg`), so an absolute or escaping
/// reference is not followed: its file name alone is looked for in `base`.
/// Backslashes are taken as separators.
pub(super) fn resolve(base: &Path, reference: &str, name: &str) -> Resolved {
    let cleaned = reference.replace('\\', "/");
    let is_absolute = cleaned.starts_with('/')
        || cleaned.as_bytes().get(1) == Some(&b':')
        || cleaned.contains("://");
    let rel = PathBuf::from(&cleaned);
    let escapes = rel
        .components()
        .any(|c| !matches!(c, Component::Normal(_) | Component::CurDir));
    if !is_absolute && !escapes {
        return Resolved::Inside(base.join(rel));
    }
    let file_name = cleaned.rsplit('/').next().unwrap_or_default();
    if file_name.is_empty() || file_name == ".." || file_name == "." {
        return Resolved::Refused(format!(
            "{name}: {reference:?} points outside the model's folder; not followed"
        ));
    }
    Resolved::FileNameOnly(
        base.join(file_name),
        format!(
            "{name}: {reference:?} points outside the model's folder; \
             looked for {file_name:?} beside the model instead"
        ),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn references_stay_inside() {
        let b = Path::new("/m");
        assert!(
            matches!(resolve(b, "t.png", "x"), Resolved::Inside(p) if p == Path::new("/m/t.png"))
        );
        assert!(
            matches!(resolve(b, "sub\\t.png", "x"), Resolved::Inside(p) if p == Path::new("/m/sub/t.png"))
        );
        for r in [
            "../t.png",
            "/etc/t.png",
            "C:\\scans\\t.png",
            "a/../../t.png",
        ] {
            match resolve(b, r, "x") {
                Resolved::FileNameOnly(p, w) => {
                    assert_eq!(p, Path::new("/m/t.png"));
                    assert!(w.contains("outside"), "{w}");
                }
                _ => panic!("{r}"),
            }
        }
        assert!(matches!(resolve(b, "../..", "x"), Resolved::Refused(_)));
    }

    #[test]
    fn unknown_signature_is_an_error() {
        let e = load(Source::Bytes(b"not an image at all"), "t", 1 << 20).unwrap_err();
        assert!(e.to_string().contains("not a PNG or JPEG"), "{e}");
    }
}
