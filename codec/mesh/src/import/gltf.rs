//! glTF 2.0 (`.gltf` JSON) and GLB reader.
//!
//! The `gltf` crate parses and validates the JSON document. The GLB
//! container and the accessor bytes are read here, with every offset and
//! length checked against the bytes actually present, because the crate's
//! own GLB and accessor readers trust declared lengths (they can panic on a
//! hostile file). Images are never decoded.
//!
//! Every triangle primitive (`TRIANGLES`, `TRIANGLE_STRIP`, `TRIANGLE_FAN`)
//! of every mesh instanced in the default scene is read, with its node's
//! world transform applied (winding flipped under mirroring transforms). A
//! file without scenes, or whose scene instances no mesh, gives all meshes
//! untransformed. `COLOR_0` is linear RGB per the glTF specification and is
//! converted to the sRGB bytes that [`IndexedMesh::colors`] holds.
//!
//! [`read_textured`] also reads the primitives' `baseColorTexture` image and
//! their `TEXCOORD_n` (the `texCoord` of the texture reference); only then
//! are images decoded, through [`super::texture`]. `KHR_texture_transform`
//! is ignored.

use std::borrow::Cow;
use std::path::{Component, Path};

use gltf::accessor::DataType;
use gltf::buffer::Source;
use gltf::mesh::{Mode, Semantic};

use super::texture;
use super::{push_triangle, ImportOptions, MeshFormat, TexturedSurface};
use crate::{Error, IndexedMesh, Result};

type Mat4 = [[f64; 4]; 4];

const IDENTITY: Mat4 = [
    [1.0, 0.0, 0.0, 0.0],
    [0.0, 1.0, 0.0, 0.0],
    [0.0, 0.0, 1.0, 0.0],
    [0.0, 0.0, 0.0, 1.0],
];

/// Deepest node hierarchy followed (deeper means a cycle, in practice).
const MAX_DEPTH: usize = 512;
/// Most node visits (guards against hierarchies that share subtrees).
const MAX_NODE_VISITS: usize = 1_000_000;

/// Splits a GLB container into its JSON chunk and optional BIN chunk.
fn split_glb<'a>(bytes: &'a [u8], what: &'static str) -> Result<(&'a [u8], Option<&'a [u8]>)> {
    let u32_at = |p: usize| -> Option<u32> {
        let b = bytes.get(p..p.checked_add(4)?)?;
        Some(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    };
    let (Some(version), Some(length)) = (u32_at(4), u32_at(8)) else {
        return Err(Error::input(
            what,
            "truncated: shorter than the 12-byte GLB header",
        ));
    };
    if version != 2 {
        return Err(Error::Unsupported(format!(
            "{what}: GLB version {version} (only glTF 2.0 is read)"
        )));
    }
    let length = length as usize;
    if length > bytes.len() {
        return Err(Error::input(
            what,
            format!(
                "truncated: the header says {length} bytes but the file has {}",
                bytes.len()
            ),
        ));
    }
    let mut pos = 12usize;
    let (mut json, mut bin) = (None, None);
    while pos < length {
        let (Some(len), Some(kind)) = (u32_at(pos), u32_at(pos + 4)) else {
            return Err(Error::input(
                what,
                format!("truncated chunk header at byte {pos}"),
            ));
        };
        let start = pos + 8;
        let end = start
            .checked_add(len as usize)
            .filter(|&e| e <= length)
            .ok_or_else(|| {
                Error::input(
                    what,
                    format!("truncated: chunk at byte {pos} declares {len} bytes, past the end"),
                )
            })?;
        let data = &bytes[start..end];
        match &kind.to_le_bytes() {
            b"JSON" if json.is_none() => json = Some(data),
            b"BIN\0" if bin.is_none() && json.is_some() => bin = Some(data),
            _ => {} // unknown chunks are skipped
        }
        pos = end;
    }
    let json = json.ok_or_else(|| Error::input(what, "has no JSON chunk"))?;
    Ok((json, bin))
}

fn gltf_error(e: gltf::Error, what: &'static str) -> Error {
    if let gltf::Error::Validation(list) = &e {
        let unsupported = list
            .iter()
            .any(|(_, e)| matches!(e, gltf::json::validation::Error::Unsupported));
        let detail = list
            .iter()
            .take(5)
            .map(|(path, e)| format!("{path}: {e}"))
            .collect::<Vec<_>>()
            .join("; ");
        if unsupported {
            return Error::Unsupported(format!("{what}: {detail}"));
        }
        return Error::input(what, format!("invalid glTF: {detail}"));
    }
    Error::input(what, e)
}

/// gltf-json 1.4's validation reads a primitive's `POSITION` accessor
/// before checking that it exists, and panics on an index past the end of
/// `accessors`: refuse such documents before validating them.
fn check_attribute_accessors(root: &gltf::json::Root, what: &'static str) -> Result<()> {
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, prim) in mesh.primitives.iter().enumerate() {
            for index in prim.attributes.values() {
                if index.value() >= root.accessors.len() {
                    return Err(Error::input(
                        what,
                        format!(
                            "invalid glTF: mesh {m} primitive {p} uses accessor {} but there are {}",
                            index.value(),
                            root.accessors.len()
                        ),
                    ));
                }
            }
        }
    }
    Ok(())
}

/// The buffers of a document, loaded on first use.
struct Buffers<'a> {
    what: &'static str,
    base: Option<&'a Path>,
    bin: Option<&'a [u8]>,
    loaded: Vec<Option<Cow<'a, [u8]>>>,
}

impl<'a> Buffers<'a> {
    fn load(&mut self, buffer: &gltf::Buffer<'_>) -> Result<()> {
        let i = buffer.index();
        if self.loaded.get(i).is_some_and(|b| b.is_some()) {
            return Ok(());
        }
        let what = self.what;
        let data: Cow<'a, [u8]> = match buffer.source() {
            Source::Bin => Cow::Borrowed(self.bin.ok_or_else(|| {
                Error::input(
                    what,
                    format!("buffer {i} refers to a GLB binary chunk that is absent"),
                )
            })?),
            Source::Uri(uri) if uri.starts_with("data:") => Cow::Owned(
                decode_data_uri(uri)
                    .map_err(|e| Error::input(what, format!("buffer {i}: bad data URI: {e}")))?,
            ),
            Source::Uri(uri) => {
                let Some(base) = self.base else {
                    return Err(Error::input(
                        what,
                        format!("buffer {i} is in the external file {uri:?}: import from a path to read it"),
                    ));
                };
                let rel = relative_uri_path(uri)
                    .map_err(|e| Error::input(what, format!("buffer {i}: uri {uri:?}: {e}")))?;
                let path = base.join(rel);
                Cow::Owned(std::fs::read(&path).map_err(|e| {
                    Error::Io(std::io::Error::new(
                        e.kind(),
                        format!("buffer {i} of the glTF file, {}: {e}", path.display()),
                    ))
                })?)
            }
        };
        if data.len() < buffer.length() {
            return Err(Error::input(
                what,
                format!(
                    "truncated: buffer {i} holds {} bytes but declares byteLength {}",
                    data.len(),
                    buffer.length()
                ),
            ));
        }
        if self.loaded.len() <= i {
            self.loaded.resize(i + 1, None);
        }
        self.loaded[i] = Some(data);
        Ok(())
    }

    fn get(&self, i: usize) -> &[u8] {
        self.loaded.get(i).and_then(|b| b.as_deref()).unwrap_or(&[])
    }
}

fn decode_data_uri(uri: &str) -> std::result::Result<Vec<u8>, String> {
    use base64::Engine as _;
    let (header, payload) = uri
        .split_once(',')
        .ok_or_else(|| "no ',' separator".to_string())?;
    if !header.ends_with(";base64") {
        return Err("only base64 data URIs are supported".to_string());
    }
    base64::engine::general_purpose::STANDARD
        .decode(payload.trim())
        .map_err(|e| e.to_string())
}

/// A relative URI reference to a file beside the glTF, percent-decoded.
/// Absolute paths, other schemes and `..` are refused: a glTF must not make
/// the importer read files outside its folder.
fn relative_uri_path(uri: &str) -> std::result::Result<std::path::PathBuf, String> {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = bytes
                .get(i + 1..i + 3)
                .and_then(|h| std::str::from_utf8(h).ok())
                .and_then(|h| u8::from_str_radix(h, 16).ok())
                .ok_or_else(|| "bad percent-escape".to_string())?;
            out.push(hex);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    let s = String::from_utf8(out).map_err(|_| "not UTF-8 after percent-decoding".to_string())?;
    if s.contains(':') || s.contains('\\') || s.contains('\0') {
        return Err("only relative file names are read".to_string());
    }
    let p = std::path::PathBuf::from(s);
    if p.components()
        .any(|c| !matches!(c, Component::Normal(_) | Component::CurDir))
    {
        return Err("must stay inside the glTF file's folder".to_string());
    }
    Ok(p)
}

/// A checked view of one accessor's bytes.
struct Accessor<'b> {
    data: &'b [u8],
    start: usize,
    stride: usize,
    count: usize,
    ty: DataType,
    dims: usize,
    normalized: bool,
}

impl Accessor<'_> {
    #[inline]
    fn raw(&self, i: usize, j: usize) -> f64 {
        let p = self.start + i * self.stride + j * self.ty.size();
        // In range: checked by `open` for every i < count, j < dims.
        let b = &self.data[p..p + self.ty.size()];
        match self.ty {
            DataType::I8 => b[0] as i8 as f64,
            DataType::U8 => b[0] as f64,
            DataType::I16 => i16::from_le_bytes([b[0], b[1]]) as f64,
            DataType::U16 => u16::from_le_bytes([b[0], b[1]]) as f64,
            DataType::U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
            DataType::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
        }
    }

    /// The value as the spec means it: normalized integers map to 0–1 or −1–1.
    #[inline]
    fn value(&self, i: usize, j: usize) -> f64 {
        let v = self.raw(i, j);
        if !self.normalized {
            return v;
        }
        match self.ty {
            DataType::I8 => (v / 127.0).max(-1.0),
            DataType::U8 => v / 255.0,
            DataType::I16 => (v / 32767.0).max(-1.0),
            DataType::U16 => v / 65535.0,
            DataType::U32 => v / 4294967295.0,
            DataType::F32 => v,
        }
    }

    #[inline]
    fn index(&self, i: usize) -> u64 {
        match self.ty {
            DataType::F32 => u64::MAX,
            _ => self.raw(i, 0) as u64,
        }
    }
}

fn open<'b>(
    acc: &gltf::Accessor<'_>,
    buffers: &'b Buffers<'_>,
    what: &'static str,
) -> Result<Accessor<'b>> {
    let ai = acc.index();
    if acc.sparse().is_some() {
        return Err(Error::Unsupported(format!(
            "{what}: accessor {ai} is sparse"
        )));
    }
    let view = acc
        .view()
        .ok_or_else(|| Error::Unsupported(format!("{what}: accessor {ai} has no bufferView")))?;
    let ty = acc.data_type();
    let dims = acc.dimensions().multiplicity();
    let elem = ty.size() * dims;
    let stride = view.stride().unwrap_or(elem);
    if stride < elem {
        return Err(Error::input(
            what,
            format!(
                "accessor {ai}: byteStride {stride} is smaller than its element ({elem} bytes)"
            ),
        ));
    }
    let data = buffers.get(view.buffer().index());
    let bad = |detail: String| Error::input(what, format!("accessor {ai}: {detail}"));
    let view_end = view
        .offset()
        .checked_add(view.length())
        .filter(|&e| e <= data.len())
        .ok_or_else(|| {
            bad(format!(
                "buffer view {} ends past its buffer ({} bytes)",
                view.index(),
                data.len()
            ))
        })?;
    let start = view.offset().checked_add(acc.offset());
    let count = acc.count();
    let end = match count {
        0 => start,
        n => start
            .and_then(|s| s.checked_add(stride.checked_mul(n - 1)?))
            .and_then(|s| s.checked_add(elem)),
    };
    match (start, end) {
        (Some(start), Some(end)) if end <= view_end => Ok(Accessor {
            data: &data[..view_end],
            start,
            stride,
            count,
            ty,
            dims,
            normalized: acc.normalized(),
        }),
        _ => Err(bad(format!(
            "{count} elements run past the end of buffer view {}",
            view.index()
        ))),
    }
}

fn mul(a: &Mat4, b: &Mat4) -> Mat4 {
    let mut m = [[0.0; 4]; 4];
    for (c, col) in m.iter_mut().enumerate() {
        for (r, v) in col.iter_mut().enumerate() {
            *v = (0..4).map(|k| a[k][r] * b[c][k]).sum();
        }
    }
    m
}

fn det3(m: &Mat4) -> f64 {
    m[0][0] * (m[1][1] * m[2][2] - m[2][1] * m[1][2])
        - m[1][0] * (m[0][1] * m[2][2] - m[2][1] * m[0][2])
        + m[2][0] * (m[0][1] * m[1][2] - m[1][1] * m[0][2])
}

/// glTF vertex colours are linear; IndexedMesh holds sRGB bytes.
pub(crate) fn linear_to_srgb_u8(l: f64) -> u8 {
    let l = if l.is_nan() { 0.0 } else { l.clamp(0.0, 1.0) };
    let s = if l <= 0.003_130_8 {
        12.92 * l
    } else {
        1.055 * l.powf(1.0 / 2.4) - 0.055
    };
    (s * 255.0).round().clamp(0.0, 255.0) as u8
}

/// The inverse of [`linear_to_srgb_u8`], for the exporter.
pub(crate) fn srgb_u8_to_linear(c: u8) -> f32 {
    let s = c as f64 / 255.0;
    let l = if s <= 0.040_45 {
        s / 12.92
    } else {
        ((s + 0.055) / 1.055).powf(2.4)
    };
    l as f32
}

pub(super) fn read(
    bytes: &[u8],
    format: MeshFormat,
    base: Option<&Path>,
    opts: &ImportOptions,
) -> Result<IndexedMesh> {
    read_inner(bytes, format, base, opts, None).map(|(mesh, _)| mesh)
}

/// [`read`] plus the base colour texture and the texture coordinates of the
/// primitives that use it. Warnings go to `warnings`.
pub(super) fn read_textured(
    bytes: &[u8],
    format: MeshFormat,
    base: &Path,
    opts: &ImportOptions,
    max_pixels: u64,
    warnings: &mut Vec<String>,
) -> Result<(IndexedMesh, Option<TexturedSurface>)> {
    let request = TextureRequest {
        max_pixels,
        warnings,
    };
    read_inner(bytes, format, Some(base), opts, Some(request))
}

/// A textured import's image budget and the place its warnings go.
struct TextureRequest<'w> {
    max_pixels: u64,
    warnings: &'w mut Vec<String>,
}

/// A primitive with a base colour texture, in the combined mesh.
struct TexturedPrimitive {
    vertices: std::ops::Range<usize>,
    triangles: std::ops::Range<usize>,
    image: usize,
    uvs: Vec<[f32; 2]>,
}

/// The textured primitives of a document, for [`read_surface`].
struct TexturedPrimitives {
    primitives: Vec<TexturedPrimitive>,
    /// Triangles whose material has a texture but no such TEXCOORD_n.
    without_uvs: usize,
}

fn read_inner(
    bytes: &[u8],
    format: MeshFormat,
    base: Option<&Path>,
    opts: &ImportOptions,
    mut textured: Option<TextureRequest<'_>>,
) -> Result<(IndexedMesh, Option<TexturedSurface>)> {
    let what = if bytes.starts_with(b"glTF") {
        MeshFormat::Glb.name()
    } else {
        format.name()
    };
    let (doc, bin) = parse_document(bytes, format, what)?;
    let mut buffers = Buffers {
        what,
        base,
        bin,
        loaded: Vec::new(),
    };
    let instances = mesh_instances(&doc, what)?;
    let mut reading = Reading {
        what,
        opts,
        buffers: &mut buffers,
        warnings: textured.as_mut().map(|t| &mut *t.warnings),
    };
    let mut combined = Combined::default();
    for (mesh, world) in &instances {
        for prim in mesh.primitives() {
            combined.add_primitive(&mut reading, &prim, mesh.index(), world)?;
        }
    }
    let (mesh, found) = combined.finish(what)?;
    let Some(request) = textured else {
        return Ok((mesh, None));
    };
    let surface = read_surface(&doc, &mesh, &found, &mut buffers, request)?;
    Ok((mesh, surface))
}

/// The JSON document of a `.gltf` or GLB file, and the GLB's binary chunk.
fn parse_document<'a>(
    bytes: &'a [u8],
    format: MeshFormat,
    what: &'static str,
) -> Result<(gltf::Document, Option<&'a [u8]>)> {
    let (json, bin) = if bytes.starts_with(b"glTF") {
        split_glb(bytes, what)?
    } else if format == MeshFormat::Glb {
        return Err(Error::input(what, "not a GLB file (no glTF magic)"));
    } else {
        (bytes, None)
    };
    if json.iter().all(|b| b.is_ascii_whitespace()) {
        return Err(Error::input(what, "is empty"));
    }
    let root = gltf::json::Root::from_slice(json)
        .map_err(|e| gltf_error(gltf::Error::Deserialize(e), what))?;
    check_attribute_accessors(&root, what)?;
    let doc = gltf::Document::from_json(root).map_err(|e| gltf_error(e, what))?;
    Ok((doc, bin))
}

/// Mesh instances with their world matrices: the meshes of the default
/// scene (or the first), depth first in node order; every mesh,
/// untransformed, when no scene instances one.
fn mesh_instances<'d>(
    doc: &'d gltf::Document,
    what: &'static str,
) -> Result<Vec<(gltf::Mesh<'d>, Mat4)>> {
    let mut instances: Vec<(gltf::Mesh<'_>, Mat4)> = Vec::new();
    if let Some(scene) = doc.default_scene().or_else(|| doc.scenes().next()) {
        let mut stack: Vec<(gltf::Node<'_>, Mat4, usize)> =
            scene.nodes().map(|n| (n, IDENTITY, 0)).collect();
        stack.reverse();
        let mut visits = 0usize;
        while let Some((node, parent, depth)) = stack.pop() {
            visits += 1;
            if depth > MAX_DEPTH || visits > MAX_NODE_VISITS {
                return Err(Error::input(
                    what,
                    format!(
                        "node hierarchy too deep or too large at node {} (cycle?)",
                        node.index()
                    ),
                ));
            }
            let local = node.transform().matrix().map(|c| c.map(f64::from));
            let world = mul(&parent, &local);
            if let Some(mesh) = node.mesh() {
                instances.push((mesh, world));
            }
            let children: Vec<_> = node.children().collect();
            stack.extend(children.into_iter().rev().map(|c| (c, world, depth + 1)));
        }
    }
    if instances.is_empty() {
        instances = doc.meshes().map(|m| (m, IDENTITY)).collect();
    }
    Ok(instances)
}

/// What every primitive is read with.
struct Reading<'r, 'b> {
    what: &'static str,
    opts: &'r ImportOptions,
    buffers: &'r mut Buffers<'b>,
    /// `Some` when textures are read: unreadable texture coordinates are
    /// reported here.
    warnings: Option<&'r mut Vec<String>>,
}

/// A primitive's base colour texture: its image, and the `TEXCOORD_<set>`
/// accessor it is read through (absent when the primitive has none).
struct BaseColour<'a> {
    image: usize,
    set: u32,
    uvs: Option<gltf::Accessor<'a>>,
}

fn base_colour<'a>(prim: &gltf::Primitive<'a>) -> Option<BaseColour<'a>> {
    let info = prim
        .material()
        .pbr_metallic_roughness()
        .base_color_texture()?;
    let set = info.tex_coord();
    Some(BaseColour {
        image: info.texture().source().index(),
        set,
        uvs: prim.get(&Semantic::TexCoords(set)),
    })
}

/// One primitive in the combined mesh.
struct Placed {
    /// "mesh M primitive P", for error messages.
    ctx: String,
    /// Index of its first vertex in the combined mesh.
    base: usize,
    /// Its vertex count.
    n: usize,
    /// Index of its first triangle in the combined mesh.
    first_triangle: usize,
    /// Its world transform mirrors: windings are reversed.
    flip: bool,
}

/// The primitives read so far, as one mesh.
#[derive(Default)]
struct Combined {
    positions: Vec<[f32; 3]>,
    colors: Vec<[u8; 3]>,
    any_colour: bool,
    triangles: Vec<[u32; 3]>,
    textured: Vec<TexturedPrimitive>,
    /// Triangles whose material has a texture but no such TEXCOORD_n.
    without_uvs: usize,
}

impl Combined {
    /// Adds one primitive of mesh `mesh` under the world transform `world`;
    /// primitives that are not triangles, or have no positions, are skipped.
    fn add_primitive(
        &mut self,
        r: &mut Reading<'_, '_>,
        prim: &gltf::Primitive<'_>,
        mesh: usize,
        world: &Mat4,
    ) -> Result<()> {
        let mode = prim.mode();
        if !matches!(
            mode,
            Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
        ) {
            return Ok(());
        }
        let Some(pos_acc) = prim.get(&Semantic::Positions) else {
            return Ok(());
        };
        let ctx = format!("mesh {} primitive {}", mesh, prim.index());
        let colour_acc = prim.get(&Semantic::Colors(0));
        let index_acc = prim.indices();
        let texture = r.warnings.as_ref().and_then(|_| base_colour(prim));
        for acc in [Some(&pos_acc), colour_acc.as_ref(), index_acc.as_ref()]
            .into_iter()
            .flatten()
        {
            if let Some(view) = acc.view() {
                r.buffers.load(&view.buffer())?;
            }
        }
        let base = self.positions.len();
        let n = self.push_positions(r, &pos_acc, world, &ctx)?;
        self.push_colours(r, colour_acc.as_ref(), base, n, &ctx)?;
        // Unreadable texture coordinates cost the texture, not the geometry.
        let uvs = texture.as_ref().and_then(|t| {
            let acc = t.uvs.as_ref()?;
            Some(read_uvs(acc, r.buffers, r.what, &ctx, t.set, n))
        });
        let placed = Placed {
            ctx,
            base,
            n,
            first_triangle: self.triangles.len(),
            flip: det3(world) < 0.0,
        };
        self.push_triangles(r, mode, index_acc.as_ref(), &placed)?;
        self.record_texture(r, texture, uvs, &placed);
        Ok(())
    }

    /// Appends the primitive's `POSITION`s, transformed; returns their count.
    fn push_positions(
        &mut self,
        r: &Reading<'_, '_>,
        acc: &gltf::Accessor<'_>,
        world: &Mat4,
        ctx: &str,
    ) -> Result<usize> {
        let what = r.what;
        let pos = open(acc, r.buffers, what)?;
        if pos.dims != 3 {
            return Err(Error::input(what, format!("{ctx}: POSITION is not VEC3")));
        }
        let n = pos.count;
        let base = self.positions.len();
        if base + n > r.opts.max_vertices {
            return Err(Error::Limit(format!(
                "{what} has more than {} vertices",
                r.opts.max_vertices
            )));
        }
        if base + n > u32::MAX as usize {
            return Err(Error::Limit(format!("{what} has more than 2^32 vertices")));
        }
        self.positions.reserve(n);
        let identity = *world == IDENTITY;
        for i in 0..n {
            let p = [pos.value(i, 0), pos.value(i, 1), pos.value(i, 2)];
            let p = if identity {
                p.map(|v| v as f32)
            } else {
                let w = world;
                [0, 1, 2].map(|row| {
                    (w[0][row] * p[0] + w[1][row] * p[1] + w[2][row] * p[2] + w[3][row]) as f32
                })
            };
            if !p.iter().all(|v| v.is_finite()) {
                return Err(Error::input(
                    what,
                    format!("{ctx}: vertex {i} has a non-finite coordinate {p:?}"),
                ));
            }
            self.positions.push(p);
        }
        Ok(n)
    }

    /// Appends the primitive's `COLOR_0` as sRGB bytes; vertices without
    /// colour are white once any primitive has had one.
    fn push_colours(
        &mut self,
        r: &Reading<'_, '_>,
        acc: Option<&gltf::Accessor<'_>>,
        base: usize,
        n: usize,
        ctx: &str,
    ) -> Result<()> {
        match acc {
            Some(acc) => {
                let c = open(acc, r.buffers, r.what)?;
                if !(c.dims == 3 || c.dims == 4) || c.count != n {
                    return Err(Error::input(
                        r.what,
                        format!("{ctx}: COLOR_0 must be VEC3/VEC4 with one value per vertex"),
                    ));
                }
                if !self.any_colour {
                    self.colors.resize(base, [255; 3]);
                    self.any_colour = true;
                }
                self.colors
                    .extend((0..n).map(|i| [0, 1, 2].map(|j| linear_to_srgb_u8(c.value(i, j)))));
            }
            None if self.any_colour => self.colors.resize(base + n, [255; 3]),
            None => {}
        }
        Ok(())
    }

    /// Appends the primitive's triangles, through its indices when it has
    /// them.
    fn push_triangles(
        &mut self,
        r: &Reading<'_, '_>,
        mode: Mode,
        acc: Option<&gltf::Accessor<'_>>,
        placed: &Placed,
    ) -> Result<()> {
        let indices = match acc {
            Some(acc) => {
                let ix = open(acc, r.buffers, r.what)?;
                if ix.dims != 1 || ix.ty == DataType::F32 {
                    return Err(Error::input(
                        r.what,
                        format!("{}: indices must be unsigned integer scalars", placed.ctx),
                    ));
                }
                Some(ix)
            }
            None => None,
        };
        let count = indices.as_ref().map_or(placed.n, |ix| ix.count);
        let at = |i: usize| indices.as_ref().map_or(i as u64, |ix| ix.index(i));
        let emit = |t: [u64; 3], k: usize| self.add_triangle(r, placed, t, k);
        for_each_triangle(mode, count, at, emit)
    }

    /// Appends triangle `k` of the primitive, `t` in its own vertex numbers.
    fn add_triangle(
        &mut self,
        r: &Reading<'_, '_>,
        placed: &Placed,
        t: [u64; 3],
        k: usize,
    ) -> Result<()> {
        let n = placed.n;
        for &v in &t {
            if v >= n as u64 {
                return Err(Error::input(
                    r.what,
                    format!(
                        "{}: triangle {k} has vertex index {v} out of range ({n} vertices)",
                        placed.ctx
                    ),
                ));
            }
        }
        let [a, b, c] = t.map(|v| (v as usize + placed.base) as u32);
        let t = if placed.flip { [a, c, b] } else { [a, b, c] };
        push_triangle(&mut self.triangles, t, r.what, r.opts.max_faces)
    }

    /// Notes what the primitive brings to the textured surface: its UVs, a
    /// warning about unreadable ones, or triangles without any.
    fn record_texture(
        &mut self,
        r: &mut Reading<'_, '_>,
        texture: Option<BaseColour<'_>>,
        uvs: Option<Result<Vec<[f32; 2]>>>,
        placed: &Placed,
    ) {
        let triangles = placed.first_triangle..self.triangles.len();
        match (texture, uvs) {
            (Some(texture), Some(Ok(uvs))) => self.textured.push(TexturedPrimitive {
                vertices: placed.base..placed.base + placed.n,
                triangles,
                image: texture.image,
                uvs,
            }),
            (Some(_), Some(Err(e))) => {
                if let Some(warnings) = r.warnings.as_mut() {
                    warnings.push(format!(
                        "{e}; its {} triangles are left out of the textured surface",
                        triangles.len()
                    ));
                }
            }
            (Some(_), None) => self.without_uvs += triangles.len(),
            _ => {}
        }
    }

    /// The combined mesh (refused when it has no triangles) and its
    /// textured primitives.
    fn finish(self, what: &'static str) -> Result<(IndexedMesh, TexturedPrimitives)> {
        if self.positions.is_empty() || self.triangles.is_empty() {
            return Err(Error::input(
                what,
                "contains no triangle meshes (empty mesh)",
            ));
        }
        let mesh = IndexedMesh {
            positions: self.positions,
            colors: self.any_colour.then_some(self.colors),
            triangles: self.triangles,
        };
        let found = TexturedPrimitives {
            primitives: self.textured,
            without_uvs: self.without_uvs,
        };
        Ok((mesh, found))
    }
}

/// Calls `emit(triangle, k)` for each triangle of a `TRIANGLES`,
/// `TRIANGLE_STRIP` or `TRIANGLE_FAN` primitive with `count` vertex
/// references, `at(i)` being reference `i`. Degenerate strip triangles
/// (stitching) are dropped.
fn for_each_triangle(
    mode: Mode,
    count: usize,
    at: impl Fn(usize) -> u64,
    mut emit: impl FnMut([u64; 3], usize) -> Result<()>,
) -> Result<()> {
    match mode {
        Mode::Triangles => {
            for k in 0..count / 3 {
                emit([at(3 * k), at(3 * k + 1), at(3 * k + 2)], k)?;
            }
        }
        Mode::TriangleStrip => {
            for k in 0..count.saturating_sub(2) {
                let t = if k % 2 == 0 {
                    [at(k), at(k + 1), at(k + 2)]
                } else {
                    [at(k + 1), at(k), at(k + 2)]
                };
                if t[0] != t[1] && t[1] != t[2] && t[0] != t[2] {
                    emit(t, k)?;
                }
            }
        }
        _ => {
            for k in 0..count.saturating_sub(2) {
                emit([at(0), at(k + 1), at(k + 2)], k)?;
            }
        }
    }
    Ok(())
}

/// The image the textured primitives use most.
struct ImageChoice {
    image: usize,
    /// Triangles that use it.
    used: usize,
    /// Triangles with any base colour image and texture coordinates.
    textured: usize,
}

/// The image covering the most triangles (lowest index on a tie).
fn most_used_image(primitives: &[TexturedPrimitive]) -> Option<ImageChoice> {
    let mut votes: Vec<(usize, usize)> = Vec::new();
    for p in primitives {
        match votes.iter_mut().find(|v| v.0 == p.image) {
            Some(v) => v.1 += p.triangles.len(),
            None => votes.push((p.image, p.triangles.len())),
        }
    }
    let &(image, used) = votes
        .iter()
        .max_by(|a, b| a.1.cmp(&b.1).then_with(|| b.0.cmp(&a.0)))?;
    Some(ImageChoice {
        image,
        used,
        textured: votes.iter().map(|v| v.1).sum(),
    })
}

/// The textured surface of the most used base colour image, with warnings
/// for the triangles it leaves out; `None` when there is no texture to read.
fn read_surface(
    doc: &gltf::Document,
    mesh: &IndexedMesh,
    found: &TexturedPrimitives,
    buffers: &mut Buffers<'_>,
    request: TextureRequest<'_>,
) -> Result<Option<TexturedSurface>> {
    let TextureRequest {
        max_pixels,
        warnings,
    } = request;
    let what = buffers.what;
    if found.without_uvs > 0 {
        warnings.push(format!(
            "{} {what} triangles have a base colour texture but not its TEXCOORD \
             attribute; they are left out of the textured surface",
            found.without_uvs
        ));
    }
    let Some(choice) = most_used_image(&found.primitives) else {
        return Ok(None);
    };
    let image = match load_image(doc, choice.image, buffers, what, max_pixels)? {
        Ok(image) => image,
        Err(w) => {
            warnings.push(w);
            return Ok(None);
        }
    };
    if choice.textured > choice.used {
        warnings.push(format!(
            "{} {what} triangles use another base colour image than image {}; \
             they are left out of the textured surface",
            choice.textured - choice.used,
            choice.image
        ));
    }
    Ok(Some(assemble_surface(
        mesh,
        &found.primitives,
        &choice,
        image,
    )))
}

/// The primitives that use the chosen image, one after the other, with
/// their vertices and triangles renumbered.
fn assemble_surface(
    mesh: &IndexedMesh,
    primitives: &[TexturedPrimitive],
    choice: &ImageChoice,
    image: image::RgbImage,
) -> TexturedSurface {
    let chosen = || primitives.iter().filter(|p| p.image == choice.image);
    let nv: usize = chosen().map(|p| p.vertices.len()).sum();
    let mut surface = TexturedSurface {
        positions: Vec::with_capacity(nv),
        uvs: Vec::with_capacity(nv),
        triangles: Vec::with_capacity(choice.used),
        image,
    };
    for p in chosen() {
        let offset = surface.positions.len() as u32;
        let from = p.vertices.start as u32;
        surface
            .positions
            .extend_from_slice(&mesh.positions[p.vertices.clone()]);
        surface.uvs.extend_from_slice(&p.uvs);
        surface.triangles.extend(
            mesh.triangles[p.triangles.clone()]
                .iter()
                .map(|t| t.map(|v| v - from + offset)),
        );
    }
    surface
}

/// A primitive's `TEXCOORD_<set>`, `n` finite values.
fn read_uvs(
    acc: &gltf::Accessor<'_>,
    buffers: &mut Buffers<'_>,
    what: &'static str,
    ctx: &str,
    set: u32,
    n: usize,
) -> Result<Vec<[f32; 2]>> {
    if let Some(view) = acc.view() {
        buffers.load(&view.buffer())?;
    }
    let t = open(acc, buffers, what)?;
    if t.dims != 2 || t.count != n {
        return Err(Error::input(
            what,
            format!("{ctx}: TEXCOORD_{set} must be VEC2 with one value per vertex"),
        ));
    }
    let mut uvs = Vec::with_capacity(n);
    for i in 0..n {
        let uv = [t.value(i, 0) as f32, t.value(i, 1) as f32];
        if !uv.iter().all(|v| v.is_finite()) {
            return Err(Error::input(
                what,
                format!("{ctx}: TEXCOORD_{set} value {i} is not finite {uv:?}"),
            ));
        }
        uvs.push(uv);
    }
    Ok(uvs)
}

/// Decodes image `index` of the document (from a buffer view, a `data:` URI
/// or a file beside the glTF). `Ok(Err(warning))`: absent, or a format
/// that is not read.
fn load_image(
    doc: &gltf::Document,
    index: usize,
    buffers: &mut Buffers<'_>,
    what: &'static str,
    max_pixels: u64,
) -> Result<std::result::Result<image::RgbImage, String>> {
    let Some(image) = doc.images().nth(index) else {
        return Err(Error::input(what, format!("image {index} does not exist")));
    };
    match image.source() {
        gltf::image::Source::View { view, .. } => {
            let name = format!("{what} image {index} (buffer view {})", view.index());
            buffers.load(&view.buffer())?;
            let data = buffers.get(view.buffer().index());
            let bytes = view
                .offset()
                .checked_add(view.length())
                .and_then(|end| data.get(view.offset()..end))
                .ok_or_else(|| {
                    Error::input(
                        what,
                        format!(
                            "image {index}: buffer view {} ends past its buffer ({} bytes)",
                            view.index(),
                            data.len()
                        ),
                    )
                })?;
            texture::load(texture::Source::Bytes(bytes), &name, max_pixels)
        }
        gltf::image::Source::Uri { uri, .. } if uri.starts_with("data:") => {
            let name = format!("{what} image {index} (data URI)");
            let bytes = decode_data_uri(uri)
                .map_err(|e| Error::input(what, format!("image {index}: bad data URI: {e}")))?;
            texture::load(texture::Source::Bytes(&bytes), &name, max_pixels)
        }
        gltf::image::Source::Uri { uri, .. } => {
            let name = format!("{what} image {index} ({uri:?})");
            let rel = relative_uri_path(uri)
                .map_err(|e| Error::input(what, format!("image {index}: uri {uri:?}: {e}")))?;
            let base = buffers.base.unwrap_or_else(|| Path::new("."));
            texture::load(texture::Source::File(&base.join(rel)), &name, max_pixels)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_round_trip_is_exact() {
        for c in 0..=255u8 {
            assert_eq!(linear_to_srgb_u8(srgb_u8_to_linear(c) as f64), c);
        }
    }

    #[test]
    fn uri_paths_stay_inside() {
        assert!(relative_uri_path("a%20b.bin").is_ok());
        assert_eq!(
            relative_uri_path("a%20b.bin").unwrap(),
            std::path::PathBuf::from("a b.bin")
        );
        assert!(relative_uri_path("../x.bin").is_err());
        assert!(relative_uri_path("/etc/passwd").is_err());
        assert!(relative_uri_path("http://x/y.bin").is_err());
        assert!(relative_uri_path("sub/%2e%2e/%2e%2e/x").is_err());
    }

    #[test]
    fn glb_container_errors() {
        let o = ImportOptions::default();
        let e = read(b"glTF\x02\0\0\0", MeshFormat::Glb, None, &o).unwrap_err();
        assert!(e.to_string().contains("12-byte"), "{e}");
        let e = read(b"glTF\x02\0\0\0\x00\x01\0\0", MeshFormat::Glb, None, &o).unwrap_err();
        assert!(e.to_string().contains("truncated"), "{e}");
        let e = read(b"glTF\x02\0\0\0\x0b\0\0\0", MeshFormat::Glb, None, &o).unwrap_err();
        assert!(e.to_string().contains("no JSON chunk"), "{e}");
    }
}
