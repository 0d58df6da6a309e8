//! The primitives of the instanced meshes, read one after the other into
//! one combined mesh: positions under their node's world transform,
//! `COLOR_0`, and what each brings to the textured surface.

use gltf::mesh::{Mode, Semantic};

use super::super::ImportOptions;
use super::accessor::{self, open};
use super::buffers::Buffers;
use super::colour::linear_to_srgb_u8;
use super::material::{base_colour, read_uvs, BaseColour};
use super::scene::{det3, Mat4, IDENTITY};
use super::surface::{TexturedPrimitive, TexturedPrimitives};
use crate::{Error, IndexedMesh, Result};

/// What every primitive is read with.
pub(super) struct Reading<'r, 'b> {
    pub(super) what: &'static str,
    pub(super) opts: &'r ImportOptions,
    pub(super) buffers: &'r mut Buffers<'b>,
    /// `Some` when textures are read: unreadable texture coordinates are
    /// reported here.
    pub(super) warnings: Option<&'r mut Vec<String>>,
}

/// One primitive in the combined mesh.
pub(super) struct Placed {
    /// "mesh M primitive P", for error messages.
    pub(super) ctx: String,
    /// Index of its first vertex in the combined mesh.
    pub(super) base: usize,
    /// Its vertex count.
    pub(super) n: usize,
    /// Index of its first triangle in the combined mesh.
    pub(super) first_triangle: usize,
    /// Its world transform mirrors: windings are reversed.
    pub(super) flip: bool,
}

/// The primitives read so far, as one mesh.
#[derive(Default)]
pub(super) struct Combined {
    positions: Vec<[f32; 3]>,
    colors: Vec<[u8; 3]>,
    any_colour: bool,
    pub(super) triangles: Vec<[u32; 3]>,
    textured: Vec<TexturedPrimitive>,
    /// Triangles whose material has a texture but no such TEXCOORD_n.
    without_uvs: usize,
}

impl Combined {
    /// Adds one primitive of mesh `mesh` under the world transform `world`;
    /// primitives that are not triangles, or have no positions, are skipped.
    pub(super) fn add_primitive(
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
            accessor::load(acc, r.buffers)?;
        }
        let base = self.positions.len();
        let n = self.push_positions(r, &pos_acc, world, &ctx)?;
        self.push_colours(r, colour_acc.as_ref(), base, n, &ctx)?;
        // Unreadable texture coordinates cost the texture, not the geometry.
        let uvs = texture.as_ref().and_then(|t| {
            let acc = t.uvs.as_ref()?;
            Some(read_uvs(acc, r.buffers, r.what, &ctx, t, n))
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
    pub(super) fn finish(self, what: &'static str) -> Result<(IndexedMesh, TexturedPrimitives)> {
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
