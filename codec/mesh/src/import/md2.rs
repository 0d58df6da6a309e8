//! Quake II MD2 models (seed 003; layout in SEEDS.md "003"): a 68-byte
//! little-endian header, skin names, texture coordinates, triangles with
//! separate vertex and texture indices, key frames of byte-packed vertices
//! and the optional OpenGL command list.
//!
//! [`Md2::parse`] keeps every field as the file has it, so that
//! `crate::export::write_md2` can write the model back; [`read`] turns one
//! frame into an [`IndexedMesh`] in Vitrine's Y-up frame.
//!
//! Hostile input: the magic *and* the version must match (the seed's reader
//! accepts a wrong magic when the version is 8), and every count and offset
//! is checked against the file size and the format's limits before
//! anything is allocated.

use std::path::Path;

use crate::{Error, IndexedMesh, Result};

use super::texture::{self, Resolved};
use super::{finish, ImportOptions, TexturedSurface};

const WHAT: &str = "MD2 file";

/// "IDP2", little-endian.
pub const MD2_MAGIC: [u8; 4] = *b"IDP2";
pub const MD2_VERSION: i32 = 8;
/// 17 int32 fields (the seed's text says 64; its offsets run to 64).
pub const MD2_HEADER_BYTES: usize = 68;
/// Bytes of a skin name, NUL-padded.
pub const MD2_SKIN_NAME_BYTES: usize = 64;
/// Bytes of a frame before its vertices: scale, translate, name.
pub const MD2_FRAME_HEADER_BYTES: usize = 40;

/// The format's limits (Quake II's `qfiles.h`, as the id tools and engines
/// enforce them). A file beyond them is refused, and the writer keeps to them.
pub const MD2_MAX_VERTICES: usize = 2048;
pub const MD2_MAX_TRIANGLES: usize = 4096;
pub const MD2_MAX_FRAMES: usize = 512;
pub const MD2_MAX_SKINS: usize = 32;
/// Not in the format: three per triangle is all a model can use.
pub const MD2_MAX_ST: usize = 3 * MD2_MAX_TRIANGLES;
/// Nor this: a skin larger than any engine uploads.
pub const MD2_MAX_SKIN_SIDE: i32 = 4096;
/// Quake II's frame rate for model animation (10 server frames per second).
pub const MD2_FRAMES_PER_SECOND: f32 = 10.0;

/// A triangle: three vertex indices and three texture-coordinate indices.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Md2Triangle {
    pub vertex: [u16; 3],
    pub st: [u16; 3],
}

/// One key frame: `position = scale · v + translate` (Quake's Z-up axes).
#[derive(Clone, Debug, PartialEq)]
pub struct Md2Frame {
    pub scale: [f32; 3],
    pub translate: [f32; 3],
    /// NUL-padded, as in the file.
    pub name: [u8; 16],
    /// Packed x, y, z and an index into the normal table.
    pub vertices: Vec<[u8; 4]>,
}

impl Md2Frame {
    /// The frame's name up to its first NUL, lossily as UTF-8.
    pub fn name(&self) -> String {
        c_string(&self.name)
    }

    /// Vertex `i` in Quake's axes: `scale · v + translate`, in f32 (a product then a sum).
    pub fn quake_position(&self, i: usize) -> [f32; 3] {
        let v = self.vertices[i];
        std::array::from_fn(|k| f32::from(v[k]) * self.scale[k] + self.translate[k])
    }

    /// Every vertex in Vitrine's Y-up axes (see [`quake_to_y_up`]).
    pub fn positions(&self) -> Vec<[f32; 3]> {
        (0..self.vertices.len())
            .map(|i| quake_to_y_up(self.quake_position(i)))
            .collect()
    }
}

/// Quake's Z-up (x forward, y left, z up) to glTF's Y-up: a rotation of
/// −90° about x, `(x, y, z) → (x, z, −y)`. Exact in floating point.
pub fn quake_to_y_up(p: [f32; 3]) -> [f32; 3] {
    [p[0], p[2], -p[1]]
}

/// The inverse of [`quake_to_y_up`].
pub fn y_up_to_quake(p: [f32; 3]) -> [f32; 3] {
    [p[0], -p[2], p[1]]
}

/// A whole MD2 file, field by field.
#[derive(Clone, Debug, PartialEq)]
pub struct Md2 {
    pub skin_width: i32,
    pub skin_height: i32,
    /// NUL-padded skin paths, as in the file (`models/x/skin.pcx`).
    pub skins: Vec<[u8; MD2_SKIN_NAME_BYTES]>,
    /// Texture coordinates in skin pixels.
    pub st: Vec<[i16; 2]>,
    pub triangles: Vec<Md2Triangle>,
    /// Every frame has one vertex per model vertex.
    pub frames: Vec<Md2Frame>,
    /// The OpenGL command words as read (regenerated on write).
    pub gl_commands: Vec<i32>,
}

/// The header's 17 fields, in file order after ident and version.
#[derive(Clone, Copy, Debug)]
struct Header {
    skin_width: i32,
    skin_height: i32,
    frame_size: i32,
    num_skins: i32,
    num_xyz: i32,
    num_st: i32,
    num_tris: i32,
    num_glcmds: i32,
    num_frames: i32,
    ofs_skins: i32,
    ofs_st: i32,
    ofs_tris: i32,
    ofs_frames: i32,
    ofs_glcmds: i32,
    ofs_end: i32,
}

fn i32_at(bytes: &[u8], at: usize) -> i32 {
    i32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]])
}

fn f32_at(bytes: &[u8], at: usize) -> f32 {
    f32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]])
}

fn u16_at(bytes: &[u8], at: usize) -> u16 {
    u16::from_le_bytes([bytes[at], bytes[at + 1]])
}

fn c_string(bytes: &[u8]) -> String {
    let end = bytes.iter().position(|&b| b == 0).unwrap_or(bytes.len());
    String::from_utf8_lossy(&bytes[..end]).into_owned()
}

/// A count from the header: not negative and within `limit`.
fn count(name: &str, value: i32, limit: usize) -> Result<usize> {
    if value < 0 {
        return Err(Error::input(WHAT, format!("{name} is negative ({value})")));
    }
    let n = value as usize;
    if n > limit {
        return Err(Error::Limit(format!(
            "{WHAT} declares {n} {name}, more than the format's limit of {limit}"
        )));
    }
    Ok(n)
}

/// A section `[offset, offset + count · size)` that must lie in the file.
fn section(name: &str, offset: i32, n: usize, size: usize, file: usize) -> Result<usize> {
    if offset < 0 {
        return Err(Error::input(
            WHAT,
            format!("{name} offset is negative ({offset})"),
        ));
    }
    let start = offset as usize;
    let end = (n as u64) * (size as u64) + start as u64;
    if n > 0 && start < MD2_HEADER_BYTES {
        return Err(Error::input(
            WHAT,
            format!("{name} at offset {start} overlaps the header"),
        ));
    }
    if end > file as u64 {
        return Err(Error::input(
            WHAT,
            format!("{n} {name} at offset {start} run to byte {end}, past the end of the {file}-byte file"),
        ));
    }
    Ok(start)
}

impl Header {
    fn read(bytes: &[u8]) -> Result<Header> {
        if bytes.len() < MD2_HEADER_BYTES {
            return Err(Error::input(
                WHAT,
                format!(
                    "truncated: {} bytes, shorter than the {MD2_HEADER_BYTES}-byte header",
                    bytes.len()
                ),
            ));
        }
        let ident = &bytes[0..4];
        let version = i32_at(bytes, 4);
        // Both must match: the seed tests `ident != IDENT && version != VERSION`.
        if ident != MD2_MAGIC {
            return Err(Error::input(
                WHAT,
                format!("wrong magic {ident:?} (expected \"IDP2\")"),
            ));
        }
        if version != MD2_VERSION {
            return Err(Error::Unsupported(format!(
                "{WHAT}: version {version} (only version {MD2_VERSION} is MD2)"
            )));
        }
        let f = |k: usize| i32_at(bytes, 8 + 4 * k);
        Ok(Header {
            skin_width: f(0),
            skin_height: f(1),
            frame_size: f(2),
            num_skins: f(3),
            num_xyz: f(4),
            num_st: f(5),
            num_tris: f(6),
            num_glcmds: f(7),
            num_frames: f(8),
            ofs_skins: f(9),
            ofs_st: f(10),
            ofs_tris: f(11),
            ofs_frames: f(12),
            ofs_glcmds: f(13),
            ofs_end: f(14),
        })
    }
}

impl Md2 {
    /// Parses an MD2 file. `opts` can only lower the format's own limits.
    pub fn parse(bytes: &[u8], opts: &ImportOptions) -> Result<Md2> {
        let h = Header::read(bytes)?;
        let file = bytes.len();
        if h.ofs_end < 0 || h.ofs_end as usize > file {
            return Err(Error::input(
                WHAT,
                format!(
                    "ofs_end {} is past the end of the {file}-byte file",
                    h.ofs_end
                ),
            ));
        }
        let file = h.ofs_end as usize;
        for (name, side) in [("skinwidth", h.skin_width), ("skinheight", h.skin_height)] {
            if !(1..=MD2_MAX_SKIN_SIDE).contains(&side) {
                return Err(Error::input(
                    WHAT,
                    format!("{name} {side} is outside 1–{MD2_MAX_SKIN_SIDE}"),
                ));
            }
        }
        let num_skins = count("skins", h.num_skins, MD2_MAX_SKINS)?;
        let num_xyz = count(
            "vertices",
            h.num_xyz,
            MD2_MAX_VERTICES.min(opts.max_vertices),
        )?;
        let num_st = count("texture coordinates", h.num_st, MD2_MAX_ST)?;
        let num_tris = count(
            "triangles",
            h.num_tris,
            MD2_MAX_TRIANGLES.min(opts.max_faces),
        )?;
        let num_frames = count("frames", h.num_frames, MD2_MAX_FRAMES)?;
        let num_glcmds = count("GL command words", h.num_glcmds, file / 4)?;
        let frame_size = MD2_FRAME_HEADER_BYTES + 4 * num_xyz;
        if h.frame_size < 0 || h.frame_size as usize != frame_size {
            return Err(Error::input(
                WHAT,
                format!(
                    "framesize {} differs from 40 + 4 × {num_xyz} vertices = {frame_size}",
                    h.frame_size
                ),
            ));
        }
        if num_frames == 0 {
            return Err(Error::input(WHAT, "has no frames"));
        }
        let ofs_skins = section("skins", h.ofs_skins, num_skins, MD2_SKIN_NAME_BYTES, file)?;
        let ofs_st = section("texture coordinates", h.ofs_st, num_st, 4, file)?;
        let ofs_tris = section("triangles", h.ofs_tris, num_tris, 12, file)?;
        let ofs_frames = section("frames", h.ofs_frames, num_frames, frame_size, file)?;
        let ofs_glcmds = section("GL command words", h.ofs_glcmds, num_glcmds, 4, file)?;

        // Every section is now known to lie in the file: allocations are
        // bounded by its size.
        let skins = (0..num_skins)
            .map(|k| {
                let at = ofs_skins + k * MD2_SKIN_NAME_BYTES;
                let mut name = [0u8; MD2_SKIN_NAME_BYTES];
                name.copy_from_slice(&bytes[at..at + MD2_SKIN_NAME_BYTES]);
                name
            })
            .collect();
        let st = (0..num_st)
            .map(|k| {
                let at = ofs_st + 4 * k;
                [u16_at(bytes, at) as i16, u16_at(bytes, at + 2) as i16]
            })
            .collect();
        let mut triangles = Vec::with_capacity(num_tris);
        for k in 0..num_tris {
            let at = ofs_tris + 12 * k;
            let t = Md2Triangle {
                vertex: std::array::from_fn(|c| u16_at(bytes, at + 2 * c)),
                st: std::array::from_fn(|c| u16_at(bytes, at + 6 + 2 * c)),
            };
            if let Some(&v) = t.vertex.iter().find(|&&v| v as usize >= num_xyz) {
                return Err(Error::input(
                    WHAT,
                    format!("triangle {k} refers to vertex {v} of {num_xyz}"),
                ));
            }
            if let Some(&s) = t.st.iter().find(|&&s| s as usize >= num_st) {
                return Err(Error::input(
                    WHAT,
                    format!("triangle {k} refers to texture coordinate {s} of {num_st}"),
                ));
            }
            triangles.push(t);
        }
        let mut frames = Vec::with_capacity(num_frames);
        for k in 0..num_frames {
            let at = ofs_frames + k * frame_size;
            let scale: [f32; 3] = std::array::from_fn(|c| f32_at(bytes, at + 4 * c));
            let translate: [f32; 3] = std::array::from_fn(|c| f32_at(bytes, at + 12 + 4 * c));
            // v · scale + translate is monotonic in v ∈ [0, 255]: finite at
            // both ends, finite for every vertex (found by the fuzzer: finite
            // fields whose product overflows).
            let far = |k: usize| 255.0 * scale[k] + translate[k];
            if scale.iter().chain(&translate).any(|x| !x.is_finite())
                || (0..3).any(|k| !far(k).is_finite())
            {
                return Err(Error::input(
                    WHAT,
                    format!("frame {k} has a non-finite scale or translation"),
                ));
            }
            let mut name = [0u8; 16];
            name.copy_from_slice(&bytes[at + 24..at + 40]);
            let verts = &bytes[at + MD2_FRAME_HEADER_BYTES..at + frame_size];
            let vertices = verts
                .chunks_exact(4)
                .map(|v| [v[0], v[1], v[2], v[3]])
                .collect();
            frames.push(Md2Frame {
                scale,
                translate,
                name,
                vertices,
            });
        }
        let gl_commands = (0..num_glcmds)
            .map(|k| i32_at(bytes, ofs_glcmds + 4 * k))
            .collect();
        Ok(Md2 {
            skin_width: h.skin_width,
            skin_height: h.skin_height,
            skins,
            st,
            triangles,
            frames,
            gl_commands,
        })
    }

    pub fn vertex_count(&self) -> usize {
        self.frames.first().map_or(0, |f| f.vertices.len())
    }

    /// Frame `k`, or an error naming how many there are.
    pub fn frame(&self, k: usize) -> Result<&Md2Frame> {
        self.frames.get(k).ok_or_else(|| {
            Error::Parameter(format!(
                "frame {k} asked for, but the MD2 model has {} frames (0–{})",
                self.frames.len(),
                self.frames.len().saturating_sub(1)
            ))
        })
    }

    /// The triangles' vertex indices, counter-clockwise seen from outside:
    /// MD2 winds them clockwise (Quake II culls with `glCullFace(GL_FRONT)`
    /// under OpenGL's counter-clockwise default), every other importer here
    /// gives counter-clockwise, so two corners swap.
    pub fn mesh_triangles(&self) -> Vec<[u32; 3]> {
        self.triangles
            .iter()
            .map(|t| [t.vertex[0], t.vertex[2], t.vertex[1]].map(u32::from))
            .collect()
    }

    /// Frame `k` as a mesh in Y-up axes: every MD2 vertex, every triangle
    /// (texture coordinates do not split vertices, so UV seams are welded).
    pub fn mesh(&self, k: usize) -> Result<IndexedMesh> {
        let frame = self.frame(k)?;
        Ok(IndexedMesh {
            positions: frame.positions(),
            colors: None,
            triangles: self.mesh_triangles(),
        })
    }

    /// The skin names up to their NULs.
    pub fn skin_names(&self) -> Vec<String> {
        self.skins.iter().map(|s| c_string(s)).collect()
    }

    /// The textured surface of frame `k`: one surface vertex per distinct
    /// (vertex, texture coordinate) pair, so a UV seam stays open there,
    /// `u = s / skinwidth`, `v = t / skinheight` (row 0 is the skin's top,
    /// glTF's convention).
    pub fn surface(&self, k: usize, image: image::RgbImage) -> Result<TexturedSurface> {
        let frame = self.frame(k)?;
        let mut index = std::collections::HashMap::new();
        let (mut positions, mut uvs) = (Vec::new(), Vec::new());
        let triangles = self
            .triangles
            .iter()
            .map(|t| {
                [0, 2, 1].map(|c| {
                    let key = (t.vertex[c], t.st[c]);
                    *index.entry(key).or_insert_with(|| {
                        let [s, tt] = self.st[key.1 as usize];
                        positions.push(quake_to_y_up(frame.quake_position(key.0 as usize)));
                        uvs.push([
                            f32::from(s) / self.skin_width as f32,
                            f32::from(tt) / self.skin_height as f32,
                        ]);
                        (positions.len() - 1) as u32
                    })
                })
            })
            .collect();
        Ok(TexturedSurface {
            positions,
            uvs,
            triangles,
            image,
        })
    }
}

/// Frame `opts.frame` of an MD2 file as a mesh.
pub(super) fn read(bytes: &[u8], opts: &ImportOptions) -> Result<IndexedMesh> {
    let model = Md2::parse(bytes, opts)?;
    finish(WHAT, model.mesh(opts.frame)?)
}

/// [`read`] plus the first skin that is found beside the file (by its file
/// name, since skins name paths in the game's tree), as the texture.
pub(super) fn read_textured(
    bytes: &[u8],
    opts: &ImportOptions,
    base: &Path,
    max_pixels: u64,
    warnings: &mut Vec<String>,
) -> Result<(IndexedMesh, Option<TexturedSurface>)> {
    let model = Md2::parse(bytes, opts)?;
    let mesh = finish(WHAT, model.mesh(opts.frame)?)?;
    if model.st.is_empty() {
        return Ok((mesh, None));
    }
    let names = model.skin_names();
    if names.is_empty() {
        warnings.push("MD2 file names no skin; imported without texture".into());
    }
    for name in names {
        let what = format!("MD2 skin {name:?}");
        let file_name = name.replace('\\', "/");
        let file_name = file_name.rsplit('/').next().unwrap_or_default();
        let path = match texture::resolve(base, file_name, &what) {
            Resolved::Inside(p) => p,
            Resolved::FileNameOnly(_, w) | Resolved::Refused(w) => {
                warnings.push(w);
                continue;
            }
        };
        match texture::load(texture::Source::File(&path), &what, max_pixels)? {
            Ok(image) => {
                let surface = model.surface(opts.frame, image)?;
                return Ok((mesh, Some(surface)));
            }
            Err(w) => warnings.push(w),
        }
    }
    Ok((mesh, None))
}
