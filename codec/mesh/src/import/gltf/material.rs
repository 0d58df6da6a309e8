//! A primitive's material as far as the importer uses it: the base colour
//! texture and the `TEXCOORD_n` it is read through.

use gltf::mesh::Semantic;

use super::accessor::open;
use super::buffers::Buffers;
use crate::{Error, Result};

/// A primitive's base colour texture: its image, and the `TEXCOORD_<set>`
/// accessor it is read through (absent when the primitive has none).
pub(super) struct BaseColour<'a> {
    pub(super) image: usize,
    pub(super) set: u32,
    pub(super) uvs: Option<gltf::Accessor<'a>>,
}

pub(super) fn base_colour<'a>(prim: &gltf::Primitive<'a>) -> Option<BaseColour<'a>> {
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

/// A primitive's `TEXCOORD_<set>`, `n` finite values.
pub(super) fn read_uvs(
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
