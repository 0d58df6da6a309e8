//! The textured surface of a glTF import: the base colour image the most
//! triangles use, decoded, with the texture coordinates of the primitives
//! that use it.

use std::path::Path;

use super::super::{texture, TexturedSurface};
use super::buffers::{decode_data_uri, relative_uri_path, Buffers};
use super::TextureRequest;
use crate::{Error, IndexedMesh, Result};

/// A primitive with a base colour texture, in the combined mesh.
pub(super) struct TexturedPrimitive {
    pub(super) vertices: std::ops::Range<usize>,
    pub(super) triangles: std::ops::Range<usize>,
    pub(super) image: usize,
    pub(super) uvs: Vec<[f32; 2]>,
}

/// The textured primitives of a document, for [`read_surface`].
pub(super) struct TexturedPrimitives {
    pub(super) primitives: Vec<TexturedPrimitive>,
    /// Triangles whose material has a texture but no such TEXCOORD_n.
    pub(super) without_uvs: usize,
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
pub(super) fn read_surface(
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
