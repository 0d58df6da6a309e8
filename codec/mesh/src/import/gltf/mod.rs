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
//! are images decoded, through [`super::texture`], and the reference's
//! `KHR_texture_transform` applied to the coordinates.
//!
//! Compressed geometry is decoded into the document before it is
//! validated: [`meshopt`] (`EXT_meshopt_compression` buffer views) and
//! [`draco`] (`KHR_draco_mesh_compression` primitives).
//!
//! [`extensions`] says which required extensions are read, which are
//! accepted because they only change how a material looks, and which are
//! refused by name. Sparse accessors and `KHR_mesh_quantization`'s integer
//! attributes are read by [`accessor`]; custom attributes (`_FOO`) are
//! ignored.
//!
//! The reader is split by what it reads: [`document`] (the GLB container
//! and the JSON), [`buffers`] (buffer bytes and URIs), [`accessor`]
//! (checked accessor views, sparse or not), [`scene`] (node transforms), [`primitive`] and
//! [`triangles`] (the combined mesh), [`material`] and [`surface`] (the
//! base colour texture), [`colour`] (linear ↔ sRGB).

use std::path::Path;

use super::{ImportOptions, MeshFormat, TexturedSurface};
use crate::{IndexedMesh, Result};

mod accessor;
mod buffers;
mod colour;
mod document;
mod draco;
mod extensions;
mod material;
mod meshopt;
mod primitive;
mod scene;
mod surface;
mod triangles;

use buffers::Buffers;
pub(crate) use colour::srgb_u8_to_linear;
use primitive::{Combined, Reading};

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
pub(super) struct TextureRequest<'w> {
    pub(super) max_pixels: u64,
    pub(super) warnings: &'w mut Vec<String>,
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
    let (mut root, bin) = document::parse_root(bytes, format, what)?;
    let mut buffers = Buffers {
        what,
        base,
        bin,
        loaded: Vec::new(),
    };
    meshopt::decode_views(&mut root, &mut buffers, opts)?;
    draco::decode_primitives(&mut root, &mut buffers, opts)?;
    let doc = document::validate(root, what)?;
    let instances = scene::mesh_instances(&doc, what)?;
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
    let surface = surface::read_surface(&doc, &mesh, &found, &mut buffers, request)?;
    Ok((mesh, surface))
}
