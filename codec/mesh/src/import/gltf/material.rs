//! A primitive's material as far as the importer uses it: the base colour
//! texture and the `TEXCOORD_n` it is read through, with its
//! `KHR_texture_transform` (offset, rotation, scale, and the `texCoord`
//! that overrides the reference's) applied to the coordinates.

use gltf::mesh::Semantic;

use super::accessor::{self, open};
use super::buffers::Buffers;
use crate::{Error, Result};

/// A primitive's base colour texture: its image, and the `TEXCOORD_<set>`
/// accessor it is read through (absent when the primitive has none).
pub(super) struct BaseColour<'a> {
    pub(super) image: usize,
    pub(super) set: u32,
    pub(super) uvs: Option<gltf::Accessor<'a>>,
    /// `KHR_texture_transform` as the affine map `[a, b, c, d, e, f]`:
    /// `u' = a·u + b·v + c`, `v' = d·u + e·v + f`.
    pub(super) transform: Option<[f64; 6]>,
}

/// The extension's `T · R · S`: scale, then rotate by `rotation` radians
/// (counter-clockwise in UV space, `v` pointing down), then offset.
fn affine(t: &gltf::texture::TextureTransform<'_>) -> [f64; 6] {
    let [ox, oy] = t.offset().map(f64::from);
    let [sx, sy] = t.scale().map(f64::from);
    let (sin, cos) = f64::from(t.rotation()).sin_cos();
    [cos * sx, sin * sy, ox, -sin * sx, cos * sy, oy]
}

pub(super) fn base_colour<'a>(prim: &gltf::Primitive<'a>) -> Option<BaseColour<'a>> {
    let info = prim
        .material()
        .pbr_metallic_roughness()
        .base_color_texture()?;
    let transform = info.texture_transform();
    let set = transform
        .as_ref()
        .and_then(|t| t.tex_coord())
        .unwrap_or_else(|| info.tex_coord());
    Some(BaseColour {
        image: info.texture().source().index(),
        set,
        uvs: prim.get(&Semantic::TexCoords(set)),
        transform: transform.as_ref().map(affine),
    })
}

/// A primitive's `TEXCOORD_<set>` of its base colour texture, `n` finite
/// values, transformed as the texture reference says.
pub(super) fn read_uvs(
    acc: &gltf::Accessor<'_>,
    buffers: &mut Buffers<'_>,
    what: &'static str,
    ctx: &str,
    texture: &BaseColour<'_>,
    n: usize,
) -> Result<Vec<[f32; 2]>> {
    let set = texture.set;
    accessor::load(acc, buffers)?;
    let t = open(acc, buffers, what)?;
    if t.dims != 2 || t.count != n {
        return Err(Error::input(
            what,
            format!("{ctx}: TEXCOORD_{set} must be VEC2 with one value per vertex"),
        ));
    }
    let mut uvs = Vec::with_capacity(n);
    for i in 0..n {
        let (u, v) = (t.value(i, 0), t.value(i, 1));
        let uv = match texture.transform {
            None => [u as f32, v as f32],
            Some([a, b, c, d, e, f]) => [(a * u + b * v + c) as f32, (d * u + e * v + f) as f32],
        };
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
