//! Mesh importers: PLY, OBJ, OFF/COFF, glTF 2.0 and GLB into an [`IndexedMesh`].
//!
//! Every importer treats its input as hostile: it never panics, never
//! allocates from a header count it has not checked against the bytes that
//! remain (and against [`ImportOptions`]), rejects non-finite coordinates and
//! out-of-range indices, and says in its error what went wrong and where
//! (line number for text formats, element index for binary ones).
//!
//! Importers do not clean the mesh: duplicate positions, degenerate faces and
//! non-manifold configurations come out as they are in the file. Run
//! [`crate::repair::prepare`] before encoding.
//!
//! [`import_path_textured`] also reads the colour texture of a scan (OBJ
//! `map_Kd`, glTF `baseColorTexture`) with the file's own texture
//! coordinates, as a [`TexturedSurface`].

use std::path::Path;

use crate::{Error, IndexedMesh, Result};

mod gltf;
pub mod md2;
mod obj;
mod off;
mod pcx;
mod ply;
mod texture;

pub(crate) use gltf::srgb_u8_to_linear;
pub use ply::points::{import_ply_points, PlyPoints};

/// The mesh file formats [`import_path`] and [`import_bytes`] read.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum MeshFormat {
    /// Stanford PLY: ascii, binary little- or big-endian; faces or triangle strips.
    Ply,
    /// Wavefront OBJ (geometry only; `v x y z r g b` vertex colours).
    Obj,
    /// Geomview OFF and COFF (per-vertex colours).
    Off,
    /// glTF 2.0 JSON, with embedded (data URI) or external buffers.
    Gltf,
    /// glTF 2.0 binary container.
    Glb,
    /// Quake II model: one frame ([`ImportOptions::frame`]), skin as texture.
    Md2,
}

impl MeshFormat {
    /// The format a file name's extension stands for (case-insensitive), if any.
    pub fn from_path(p: &Path) -> Option<Self> {
        let ext = p.extension()?.to_str()?.to_ascii_lowercase();
        Some(match ext.as_str() {
            "ply" => MeshFormat::Ply,
            "obj" => MeshFormat::Obj,
            "off" | "coff" => MeshFormat::Off,
            "gltf" => MeshFormat::Gltf,
            "glb" => MeshFormat::Glb,
            "md2" => MeshFormat::Md2,
            _ => return None,
        })
    }

    /// Guesses the format from the first bytes of a file.
    pub fn sniff(bytes: &[u8]) -> Option<Self> {
        if bytes.starts_with(b"glTF") {
            return Some(MeshFormat::Glb);
        }
        if bytes.starts_with(&md2::MD2_MAGIC) {
            return Some(MeshFormat::Md2);
        }
        if bytes.starts_with(b"ply\n") || bytes.starts_with(b"ply\r") {
            return Some(MeshFormat::Ply);
        }
        let head = &bytes[..bytes.len().min(4096)];
        let first = head
            .iter()
            .position(|b| !b.is_ascii_whitespace())
            .map(|i| head[i]);
        if first == Some(b'{') {
            return Some(MeshFormat::Gltf);
        }
        // First line that is not blank or a comment.
        let line = head
            .split(|&b| b == b'\n')
            .map(|l| l.trim_ascii())
            .find(|l| !l.is_empty() && !l.starts_with(b"#"))?;
        let word = line
            .split(|b| b.is_ascii_whitespace())
            .next()
            .unwrap_or_default();
        if off::is_off_keyword(word) {
            return Some(MeshFormat::Off);
        }
        if head.split(|&b| b == b'\n').any(|l| {
            let l = l.trim_ascii_start();
            l.starts_with(b"v ") || l.starts_with(b"v\t") || l.starts_with(b"f ")
        }) {
            return Some(MeshFormat::Obj);
        }
        None
    }

    /// Short human name, used in error messages.
    pub fn name(self) -> &'static str {
        match self {
            MeshFormat::Ply => "PLY file",
            MeshFormat::Obj => "OBJ file",
            MeshFormat::Off => "OFF file",
            MeshFormat::Gltf => "glTF file",
            MeshFormat::Glb => "GLB file",
            MeshFormat::Md2 => "MD2 file",
        }
    }
}

/// Budgets an importer checks before it allocates.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ImportOptions {
    /// Most vertices a file may declare or hold (default 50 million).
    pub max_vertices: usize,
    /// Most faces a file may declare, and most triangles it may produce (default 100 million).
    pub max_faces: usize,
    /// The animation frame read from formats with several (MD2; default 0).
    pub frame: usize,
}

impl Default for ImportOptions {
    fn default() -> Self {
        ImportOptions {
            max_vertices: 50_000_000,
            max_faces: 100_000_000,
            frame: 0,
        }
    }
}

/// Reads a mesh file. The format comes from the extension, or when that is
/// unknown from the file's first bytes. A `.gltf` file's external buffers
/// (`.bin`) are read from beside it; image files are never read.
pub fn import_path(path: &Path, opts: &ImportOptions) -> Result<IndexedMesh> {
    let bytes = std::fs::read(path).map_err(|e| with_path(e, path))?;
    let format = detect_format(path, &bytes)?;
    match format {
        MeshFormat::Gltf | MeshFormat::Glb => {
            let base = path.parent().unwrap_or_else(|| Path::new("."));
            gltf::read(&bytes, format, Some(base), opts)
        }
        _ => import_bytes(&bytes, format, opts),
    }
}

/// Budgets for the texture image of [`import_path_textured_with`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TextureOptions {
    /// Most pixels (width × height) a texture may have (default 64 Mpx =
    /// 8192²). Checked against the image header before decoding; the
    /// decoder then runs under an allocation budget sized for the image.
    pub max_texture_pixels: u64,
}

impl Default for TextureOptions {
    fn default() -> Self {
        TextureOptions {
            max_texture_pixels: 8192 * 8192,
        }
    }
}

/// A mesh file read with its colour texture, by [`import_path_textured`].
#[derive(Clone, Debug)]
pub struct Imported {
    /// Exactly what [`import_path`] returns for the same file.
    pub mesh: IndexedMesh,
    /// The colour texture with the file's texture coordinates; `None` for
    /// formats without textures (PLY, OFF), models without one, and
    /// textures that could not be found (see `warnings`).
    pub texture: Option<TexturedSurface>,
    /// What was skipped and why, in words: a missing texture or material
    /// file, an image format that is not read, triangles left out of the
    /// textured surface, a reference that pointed outside the model's folder.
    pub warnings: Vec<String>,
}

/// [`import_path`] plus the model's colour texture, with default
/// [`TextureOptions`].
///
/// * OBJ: the `mtllib` files (beside the OBJ), the materials' `map_Kd`
///   image (options such as `-s 1 1 1` before the name are skipped; names
///   may hold spaces or be quoted), `vt` and the corners' `vt` indices. `v`
///   is flipped to the image convention.
/// * glTF/GLB: the primitives' material `pbrMetallicRoughness.baseColorTexture`
///   image (a file beside the `.gltf`, a `data:` URI, or a buffer view), read
///   through `TEXCOORD_n` with the texture's `texCoord`. `KHR_texture_transform`
///   is ignored: the UVs are those of the file.
///
/// A model has one texture here: when materials use several images, the
/// one covering the most triangles is read and the other triangles are left
/// out of [`TexturedSurface::triangles`] (with a warning).
///
/// Geometry comes first: `mesh` is always what [`import_path`] gives, and a
/// missing texture or material file, an image in a format other than PNG
/// and JPEG, or unusable texture coordinates (an OBJ `vt` index out of
/// range, a glTF `TEXCOORD_n` that is not one VEC2 per vertex) give
/// `texture: None` (or leave those triangles out) and a warning.
/// A texture that is present but malformed, or larger than
/// [`TextureOptions::max_texture_pixels`], is an error, as is a glTF image
/// URI that is absolute or leaves the model's folder (`..`), like its
/// buffers. OBJ/MTL files often carry the exporting machine's absolute path
/// (`C:\scans\vase.jpg`): such a reference, or one with `..`, is never
/// followed; only its file name is looked for beside the OBJ, with a warning.
pub fn import_path_textured(path: &Path, opts: &ImportOptions) -> Result<Imported> {
    import_path_textured_with(path, opts, &TextureOptions::default())
}

/// [`import_path_textured`] with explicit texture budgets.
pub fn import_path_textured_with(
    path: &Path,
    opts: &ImportOptions,
    tex: &TextureOptions,
) -> Result<Imported> {
    let bytes = std::fs::read(path).map_err(|e| with_path(e, path))?;
    let format = detect_format(path, &bytes)?;
    let base = path.parent().unwrap_or_else(|| Path::new("."));
    let base = if base.as_os_str().is_empty() {
        Path::new(".")
    } else {
        base
    };
    let mut warnings = Vec::new();
    let (mesh, texture) = match format {
        MeshFormat::Obj => {
            obj::read_textured(&bytes, opts, base, tex.max_texture_pixels, &mut warnings)?
        }
        MeshFormat::Gltf | MeshFormat::Glb => gltf::read_textured(
            &bytes,
            format,
            base,
            opts,
            tex.max_texture_pixels,
            &mut warnings,
        )?,
        MeshFormat::Md2 => {
            md2::read_textured(&bytes, opts, base, tex.max_texture_pixels, &mut warnings)?
        }
        _ => (import_bytes(&bytes, format, opts)?, None),
    };
    Ok(Imported {
        mesh,
        texture,
        warnings,
    })
}

fn detect_format(path: &Path, bytes: &[u8]) -> Result<MeshFormat> {
    Ok(match MeshFormat::from_path(path) {
        // A GLB named .gltf (or the reverse) is read as what it is.
        Some(MeshFormat::Gltf | MeshFormat::Glb) if bytes.starts_with(b"glTF") => MeshFormat::Glb,
        Some(MeshFormat::Glb) if MeshFormat::sniff(bytes) == Some(MeshFormat::Gltf) => {
            MeshFormat::Gltf
        }
        Some(f) => f,
        None => MeshFormat::sniff(bytes).ok_or_else(|| {
            Error::Unsupported(format!(
                "{}: unknown mesh format (expected .ply, .obj, .off, .gltf, .glb or .md2)",
                path.display()
            ))
        })?,
    })
}

/// Reads a mesh from memory. glTF JSON input must be self-contained (buffers
/// in the GLB binary chunk or in `data:` URIs); use [`import_path`] for
/// external buffers.
pub fn import_bytes(bytes: &[u8], format: MeshFormat, opts: &ImportOptions) -> Result<IndexedMesh> {
    let mesh = match format {
        MeshFormat::Ply => ply::read(bytes, opts)?,
        MeshFormat::Obj => obj::read(bytes, opts)?,
        MeshFormat::Off => off::read(bytes, opts)?,
        MeshFormat::Gltf | MeshFormat::Glb => gltf::read(bytes, format, None, opts)?,
        MeshFormat::Md2 => md2::read(bytes, opts)?,
    };
    debug_assert!(mesh
        .triangles
        .iter()
        .all(|t| t.iter().all(|&i| (i as usize) < mesh.positions.len())));
    Ok(mesh)
}

fn with_path(e: std::io::Error, path: &Path) -> Error {
    Error::Io(std::io::Error::new(
        e.kind(),
        format!("{}: {e}", path.display()),
    ))
}

/// Shared by the importers: a declared element count checked against the
/// options and against what the remaining bytes can hold.
pub(crate) fn check_count(
    what: &'static str,
    element: &str,
    count: u64,
    min_bytes_each: u64,
    remaining: usize,
    limit: usize,
) -> Result<usize> {
    if min_bytes_each > 0 && count.saturating_mul(min_bytes_each) > remaining as u64 {
        return Err(Error::input(
            what,
            format!("declares {count} {element} but only {remaining} bytes remain"),
        ));
    }
    if count > limit as u64 {
        return Err(Error::Limit(format!(
            "{what} declares {count} {element}, more than the limit of {limit}"
        )));
    }
    usize::try_from(count).map_err(|_| Error::Limit(format!("{what}: {count} {element}")))
}

/// Float colour channel (0–1) to 8 bits, rounding; out-of-range values clamp.
pub(crate) fn unit_to_u8(v: f64) -> u8 {
    // NaN casts to 0.
    (v * 255.0).round().clamp(0.0, 255.0) as u8
}

/// Pushes one triangle, enforcing the face budget.
#[inline]
pub(crate) fn push_triangle(
    tris: &mut Vec<[u32; 3]>,
    t: [u32; 3],
    what: &'static str,
    max_faces: usize,
) -> Result<()> {
    if tris.len() >= max_faces {
        return Err(Error::Limit(format!(
            "{what} produces more than {max_faces} triangles"
        )));
    }
    tris.push(t);
    Ok(())
}

/// The common last step: reject meshes without triangles.
pub(crate) fn finish(what: &'static str, mesh: IndexedMesh) -> Result<IndexedMesh> {
    if mesh.positions.is_empty() {
        return Err(Error::input(what, "contains no vertices"));
    }
    if mesh.triangles.is_empty() {
        return Err(Error::input(what, "contains no faces (empty mesh)"));
    }
    Ok(mesh)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn format_from_extension_and_magic() {
        assert_eq!(
            MeshFormat::from_path(Path::new("a/b.PLY")),
            Some(MeshFormat::Ply)
        );
        assert_eq!(
            MeshFormat::from_path(Path::new("x.glb")),
            Some(MeshFormat::Glb)
        );
        assert_eq!(MeshFormat::from_path(Path::new("x.txt")), None);
        assert_eq!(
            MeshFormat::sniff(b"ply\nformat ascii 1.0\n"),
            Some(MeshFormat::Ply)
        );
        assert_eq!(MeshFormat::sniff(b"glTF\x02\0\0\0"), Some(MeshFormat::Glb));
        assert_eq!(
            MeshFormat::sniff(b"  {\"asset\":{}}"),
            Some(MeshFormat::Gltf)
        );
        assert_eq!(
            MeshFormat::sniff(b"# c\nCOFF\n1 0 0\n"),
            Some(MeshFormat::Off)
        );
        assert_eq!(
            MeshFormat::sniff(b"# c\nv 1 2 3\nf 1 1 1\n"),
            Some(MeshFormat::Obj)
        );
        assert_eq!(MeshFormat::sniff(b"\x00\x01garbage"), None);
    }

    #[test]
    fn unit_colour_rounding() {
        assert_eq!(unit_to_u8(0.0), 0);
        assert_eq!(unit_to_u8(1.0), 255);
        assert_eq!(unit_to_u8(2.0), 255);
        assert_eq!(unit_to_u8(-1.0), 0);
        assert_eq!(unit_to_u8(f64::NAN), 0);
        for c in 0..=255u8 {
            assert_eq!(unit_to_u8((c as f32 / 255.0) as f64), c);
        }
    }
}

/// A photographic colour texture and the file's own texture coordinates: the
/// colour source the cubic cell complex samples at full resolution. The
/// triangles are the file's, before welding and repair (a UV seam keeps its
/// two sides apart here).
#[derive(Clone, Debug)]
pub struct TexturedSurface {
    /// Model units, the same space as the imported mesh's positions.
    pub positions: Vec<[f32; 3]>,
    /// One per position. Image convention of glTF: `(0, 0)` is the image's
    /// top-left corner, `v` grows downward (OBJ's `v` is flipped on import).
    pub uvs: Vec<[f32; 2]>,
    pub triangles: Vec<[u32; 3]>,
    pub image: image::RgbImage,
}

impl TexturedSurface {
    /// The surface's own triangles as a mesh (no colour), for rendering with
    /// a shader that samples the texture (`vitrine_quality::TextureShader`).
    pub fn as_mesh(&self) -> IndexedMesh {
        IndexedMesh {
            positions: self.positions.clone(),
            colors: None,
            triangles: self.triangles.clone(),
        }
    }
}
