//! Melax's progressive edge collapse (seed 003; SEEDS.md "003"), with what
//! the seed lacks: a heap instead of a linear scan for the cheapest
//! collapse, the link condition and flip rejection of [`crate::simplify`]
//! (`collapse::topology`), borders locked, UV seams kept (a seam vertex
//! goes only along its seam, both sides at once), and for an
//! animated model a cost that is the largest over its frames and one
//! collapse order for all of them.
//!
//! Each collapse moves a vertex into a neighbour that stays where it is, so
//! positions never change: a level is the input's vertices minus those
//! collapsed, with the triangles rewritten. [`melax_chain`] runs once; every
//! level ([`MelaxChain::level`]) is then a prefix of its collapses.
//!
//! ```
//! use vitrine_simplify::melax::{melax_chain, MelaxCost, MelaxModel};
//! # let mesh = vitrine_samples::torus(24, 12, 1.0, 0.3);
//! let frames = [mesh.positions.clone()];
//! let chain = melax_chain(&MelaxModel { triangles: &mesh.triangles, frames: &frames, corner_uvs: None, cost: MelaxCost::Sine })?;
//! let level = chain.level(chain.percent(40))?;
//! assert_eq!(level.vertices, 288 * 40 / 100);
//! # Ok::<(), vitrine_codec::Error>(())
//! ```

mod cost;
mod run;

use vitrine_codec::{Error, IndexedMesh, Result};

use crate::collapse::working::WorkingMesh;
use crate::Target;
pub use cost::MelaxCost;
use run::Run;

/// A model to simplify: one connectivity, one or more frames of positions.
#[derive(Clone, Copy, Debug)]
pub struct MelaxModel<'a> {
    /// Counter-clockwise, an oriented 2-manifold (borders allowed), as
    /// `vitrine_mesh::repair::prepare` makes it.
    pub triangles: &'a [[u32; 3]],
    /// At least one; every frame has the same number of positions.
    pub frames: &'a [Vec<[f32; 3]>],
    /// Per triangle, an id for each corner's texture coordinate (MD2's st
    /// index): a vertex whose corners have two ids sits on a seam and goes
    /// only along it, one with three or more (seams meeting) stays, and no
    /// collapse carries a coordinate across a seam.
    pub corner_uvs: Option<&'a [[u32; 3]]>,
    /// The crease term: [`MelaxCost::Sine`] unless the seed's own is wanted.
    pub cost: MelaxCost,
}

/// One collapse: `gone` moves into `keep`; its corners take texture
/// coordinate `uv` (`keep`'s on that side), except, along a seam, those
/// with id `seam[0]`, which take `seam[1]` (`keep`'s on the other side).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MelaxCollapse {
    pub gone: u32,
    pub keep: u32,
    pub uv: Option<u32>,
    pub seam: Option<[u32; 2]>,
}

impl MelaxCollapse {
    /// The texture coordinate a corner of `gone` with id `id` takes.
    fn uv_of(&self, id: u32) -> u32 {
        match (self.seam, self.uv) {
            (Some([from, to]), _) if from == id => to,
            (_, Some(uv)) => uv,
            _ => id,
        }
    }
}

/// Every collapse Melax could make, cheapest first.
#[derive(Clone, Debug)]
pub struct MelaxChain {
    /// Vertices used by the input's triangles.
    pub vertices: usize,
    pub collapses: Vec<MelaxCollapse>,
    triangles: Vec<[u32; 3]>,
    corner_uvs: Option<Vec<[u32; 3]>>,
    positions: usize,
}

/// A level: the input's triangles after a prefix of the collapses.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct MelaxLevel {
    /// Vertices still used (indices are the input's).
    pub vertices: usize,
    pub triangles: Vec<[u32; 3]>,
    pub corner_uvs: Option<Vec<[u32; 3]>>,
}

/// Runs Melax's collapses on `model` as far as the checks allow.
pub fn melax_chain(model: &MelaxModel<'_>) -> Result<MelaxChain> {
    melax_until(model, 0)
}

fn melax_until(model: &MelaxModel<'_>, stop: usize) -> Result<MelaxChain> {
    let Some(first) = model.frames.first() else {
        return Err(Error::Parameter("Melax needs at least one frame".into()));
    };
    if let Some(k) = model.frames.iter().position(|f| f.len() != first.len()) {
        return Err(Error::Parameter(format!(
            "frame {k} has {} positions, frame 0 has {}",
            model.frames[k].len(),
            first.len()
        )));
    }
    if model
        .corner_uvs
        .is_some_and(|u| u.len() != model.triangles.len())
    {
        return Err(Error::Parameter(
            "one set of corner texture coordinates per triangle is needed".into(),
        ));
    }
    let frames = model
        .frames
        .iter()
        .map(|positions| {
            WorkingMesh::without_deviation(&IndexedMesh {
                positions: positions.clone(),
                colors: None,
                triangles: model.triangles.to_vec(),
            })
        })
        .collect::<Result<Vec<_>>>()?;
    let mut run = Run::new(frames, model.corner_uvs.map(<[_]>::to_vec), model.cost);
    let vertices = run.live_vertices();
    let mut collapses = Vec::new();
    run.collapse_to(stop, &mut collapses);
    Ok(MelaxChain {
        vertices,
        collapses,
        triangles: model.triangles.to_vec(),
        corner_uvs: model.corner_uvs.map(<[_]>::to_vec),
        positions: first.len(),
    })
}

impl MelaxChain {
    /// ⌊vertices · percent / 100⌋, the seed's level size (Quadro 11).
    pub fn percent(&self, percent: u32) -> usize {
        self.vertices * percent.min(100) as usize / 100
    }

    /// The fewest vertices a level can have.
    pub fn min_vertices(&self) -> usize {
        self.vertices - self.collapses.len()
    }

    /// The level with exactly `vertices` vertices.
    pub fn level(&self, vertices: usize) -> Result<MelaxLevel> {
        if vertices > self.vertices {
            return Err(Error::Parameter(format!(
                "a level of {vertices} vertices asked of a model with {}",
                self.vertices
            )));
        }
        if vertices < self.min_vertices() {
            return Err(Error::Unsupported(format!(
                "Melax stops at {} of {} vertices (the rest are on borders or seams, \
                 or where seams meet, or their collapses would break the surface); \
                 {vertices} asked",
                self.min_vertices(),
                self.vertices
            )));
        }
        let done = &self.collapses[..self.vertices - vertices];
        // Where each collapsed vertex ends: later collapses first, so a
        // survivor's own fate is known when a vertex collapsed into it is
        // reached.
        let mut root: Vec<u32> = (0..self.positions as u32).collect();
        let mut collapse_of = vec![u32::MAX; self.positions];
        for (i, c) in done.iter().enumerate().rev() {
            root[c.gone as usize] = root[c.keep as usize];
            collapse_of[c.gone as usize] = i as u32;
        }
        // A corner's texture coordinate follows its vertex's collapses one
        // by one (along a seam, which side it is on decides).
        let corner_uv = |mut v: u32, mut id: u32| {
            while let Some(c) = done.get(collapse_of[v as usize] as usize) {
                id = c.uv_of(id);
                v = c.keep;
            }
            id
        };
        let mut triangles = Vec::with_capacity(self.triangles.len());
        let mut corner_uvs = self.corner_uvs.as_ref().map(|_| Vec::new());
        for (f, t) in self.triangles.iter().enumerate() {
            let r = t.map(|v| root[v as usize]);
            if r[0] == r[1] || r[1] == r[2] || r[0] == r[2] {
                continue;
            }
            triangles.push(r);
            if let (Some(out), Some(uvs)) = (&mut corner_uvs, &self.corner_uvs) {
                let uv: [u32; 3] = std::array::from_fn(|k| corner_uv(t[k], uvs[f][k]));
                out.push(uv);
            }
        }
        Ok(MelaxLevel {
            vertices,
            triangles,
            corner_uvs,
        })
    }
}

/// A mesh simplified by Melax's collapses.
#[derive(Clone, Debug)]
pub struct MelaxSimplified {
    /// Compacted: unused vertices dropped, the rest in input order with
    /// their positions and colours unchanged.
    pub mesh: IndexedMesh,
    /// For each output vertex, its index in the input.
    pub origin: Vec<u32>,
    /// Whether the target was reached (else the mesh is the coarsest level).
    pub reached: bool,
}

/// `mesh` (an oriented 2-manifold) down to `target` vertices by Melax's
/// collapses, stopping there.
pub fn melax_simplify(
    mesh: &IndexedMesh,
    target: Target,
    cost: MelaxCost,
) -> Result<MelaxSimplified> {
    target.validate()?;
    let frames = [mesh.positions.clone()];
    let model = MelaxModel {
        triangles: &mesh.triangles,
        frames: &frames,
        corner_uvs: None,
        cost,
    };
    let used = {
        let mut used = vec![false; mesh.positions.len()];
        for t in &mesh.triangles {
            for &v in t {
                if let Some(u) = used.get_mut(v as usize) {
                    *u = true;
                }
            }
        }
        used.iter().filter(|&&u| u).count()
    };
    let want = target.vertices(used);
    let chain = melax_until(&model, want)?;
    let reached = chain.min_vertices() <= want;
    let level = chain.level(want.max(chain.min_vertices()).min(chain.vertices))?;
    let (mesh, origin) = compact(mesh, &level.triangles);
    Ok(MelaxSimplified {
        mesh,
        origin,
        reached,
    })
}

/// The vertices `triangles` use, in input order, and the triangles renumbered.
pub fn compact(mesh: &IndexedMesh, triangles: &[[u32; 3]]) -> (IndexedMesh, Vec<u32>) {
    let mut map = vec![u32::MAX; mesh.positions.len()];
    for t in triangles {
        for &v in t {
            map[v as usize] = 0;
        }
    }
    let mut origin = Vec::new();
    for (v, m) in map.iter_mut().enumerate() {
        if *m == 0 {
            *m = origin.len() as u32;
            origin.push(v as u32);
        }
    }
    let out = IndexedMesh {
        positions: origin.iter().map(|&v| mesh.positions[v as usize]).collect(),
        colors: mesh
            .colors
            .as_ref()
            .map(|c| origin.iter().map(|&v| c[v as usize]).collect()),
        triangles: triangles
            .iter()
            .map(|t| t.map(|v| map[v as usize]))
            .collect(),
    };
    (out, origin)
}
