//! The collapse loop: every vertex off the borders and seam junctions proposes its
//! cheapest allowed collapse; a min-heap (lazy: stale entries carry an old
//! stamp and are skipped) hands out the cheapest of all, which is checked
//! again, applied to every frame, and the vertices whose faces changed
//! (the survivor and the collapsed vertex's ring) propose again. The seed
//! scans every vertex for the minimum after each collapse instead.

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use glam::DVec3;

use super::cost::{cost, MelaxCost};
use super::MelaxCollapse;
use crate::collapse::topology::{keeps_orientation, link_condition, Scratch};
use crate::collapse::working::{Merge, WorkingMesh};

/// A proposed collapse `gone → keep`, ordered cheapest first.
struct Entry {
    cost: f64,
    gone: u32,
    keep: u32,
    stamp: u32,
}

impl PartialEq for Entry {
    fn eq(&self, o: &Self) -> bool {
        self.cmp(o) == Ordering::Equal
    }
}
impl Eq for Entry {}
impl PartialOrd for Entry {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Entry {
    /// Reversed, so that `BinaryHeap` (a max-heap) pops the cheapest; ties
    /// by vertex index, for determinism.
    fn cmp(&self, o: &Self) -> Ordering {
        o.cost
            .total_cmp(&self.cost)
            .then(o.gone.cmp(&self.gone))
            .then(o.keep.cmp(&self.keep))
    }
}

pub(super) struct Run {
    /// One working mesh per frame, all with the same connectivity.
    pub frames: Vec<WorkingMesh>,
    /// Per face, the texture-coordinate id of each corner.
    pub corner_uvs: Option<Vec<[u32; 3]>>,
    /// The crease term.
    kind: MelaxCost,
    /// Borders and seam junctions (three texture coordinates or more) never go.
    pub locked: Vec<bool>,
    stamp: Vec<u32>,
    heap: BinaryHeap<Entry>,
    scratch: Scratch,
    ring: Vec<u32>,
    edge: Vec<DVec3>,
}

impl Run {
    pub fn new(
        frames: Vec<WorkingMesh>,
        corner_uvs: Option<Vec<[u32; 3]>>,
        kind: MelaxCost,
    ) -> Run {
        let first = &frames[0];
        let n = first.positions.len();
        let mut locked: Vec<bool> = first.border.clone();
        if let Some(uvs) = &corner_uvs {
            for (v, lock) in locked.iter_mut().enumerate() {
                *lock |= uv_ids(first, uvs, v as u32) > 2;
            }
        }
        let mut run = Run {
            frames,
            corner_uvs,
            kind,
            locked,
            stamp: vec![0; n],
            heap: BinaryHeap::new(),
            scratch: Scratch::default(),
            ring: Vec::new(),
            edge: Vec::new(),
        };
        for v in 0..n as u32 {
            run.propose(v);
        }
        run
    }

    pub fn live_vertices(&self) -> usize {
        self.frames[0].live_vertices
    }

    /// Collapses until `stop` vertices are left or nothing more may go.
    pub fn collapse_to(&mut self, stop: usize, out: &mut Vec<MelaxCollapse>) {
        while self.live_vertices() > stop {
            let Some(e) = self.heap.pop() else { break };
            if e.stamp != self.stamp[e.gone as usize] {
                continue;
            }
            // A neighbour's collapse may have changed what this one does
            // to the faces around it without touching `gone` itself.
            let Some(uv) = self.allowed(e.gone, e.keep) else {
                self.propose(e.gone);
                continue;
            };
            out.push(self.apply(e.gone, e.keep, uv));
        }
    }

    fn apply(&mut self, gone: u32, keep: u32, uv: Option<UvMove>) -> MelaxCollapse {
        let first = &self.frames[0];
        first.neighbours(gone, &mut self.ring);
        if let (Some(uvs), Some(uv)) = (&mut self.corner_uvs, uv) {
            for &f in &first.faces_of[gone as usize] {
                let t = first.triangles[f as usize];
                if let Some(k) = t.iter().position(|&w| w == gone) {
                    let id = &mut uvs[f as usize][k];
                    *id = uv.of(*id);
                }
            }
        }
        for m in &mut self.frames {
            let merge = Merge {
                keep,
                gone,
                to: m.positions[keep as usize],
                colour: None,
            };
            m.apply(&merge);
        }
        self.stamp[gone as usize] += 1;
        let ring = std::mem::take(&mut self.ring);
        for &w in &ring {
            self.propose(w);
        }
        self.ring = ring;
        MelaxCollapse {
            gone,
            keep,
            uv: uv.map(|m| m.uv),
            seam: uv.and_then(|m| m.seam),
        }
    }

    /// Pushes `v`'s cheapest allowed collapse, if it has one.
    fn propose(&mut self, v: u32) {
        self.stamp[v as usize] += 1;
        let first = &self.frames[0];
        if self.locked[v as usize] || first.faces_of[v as usize].is_empty() {
            return;
        }
        let mut ring = std::mem::take(&mut self.ring);
        first.neighbours(v, &mut ring);
        let mut options: Vec<(f64, u32)> = ring
            .iter()
            .map(|&w| (cost(self.kind, &self.frames, v, w, &mut self.edge), w))
            .collect();
        self.ring = ring;
        options.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        for (c, w) in options {
            if self.allowed(v, w).is_some() {
                self.heap.push(Entry {
                    cost: c,
                    gone: v,
                    keep: w,
                    stamp: self.stamp[v as usize],
                });
                return;
            }
        }
    }

    /// Whether `gone → keep` keeps the surface a manifold of the same
    /// topology (link condition), flips no face in any frame and keeps the
    /// texture coordinates: `Some` of the ids `gone`'s corners take (`None`
    /// without texture coordinates).
    fn allowed(&mut self, gone: u32, keep: u32) -> Option<Option<UvMove>> {
        let first = &self.frames[0];
        if self.locked[gone as usize]
            || first.faces_of[gone as usize].is_empty()
            || !link_condition(first, keep, gone, &mut self.scratch)
        {
            return None;
        }
        let uv = match &self.corner_uvs {
            Some(uvs) => Some(uv_move(first, uvs, gone, keep)?),
            None => None,
        };
        for m in &self.frames {
            let merge = Merge {
                keep,
                gone,
                to: m.positions[keep as usize],
                colour: None,
            };
            if !keeps_orientation(m, &merge, &mut self.scratch) {
                return None;
            }
        }
        Some(uv)
    }
}

/// The id of `v`'s corner in face `f`.
fn corner_uv(mesh: &WorkingMesh, uvs: &[[u32; 3]], f: u32, v: u32) -> Option<u32> {
    let t = mesh.triangles[f as usize];
    t.iter().position(|&w| w == v).map(|k| uvs[f as usize][k])
}

/// How many texture coordinates `v`'s corners carry (3 standing for 3 or
/// more): 1 inside a chart, 2 on a seam, more where seams meet.
fn uv_ids(mesh: &WorkingMesh, uvs: &[[u32; 3]], v: u32) -> usize {
    let mut ids: Vec<u32> = Vec::with_capacity(3);
    for id in mesh.faces_of[v as usize]
        .iter()
        .filter_map(|&f| corner_uv(mesh, uvs, f, v))
    {
        if !ids.contains(&id) {
            ids.push(id);
            if ids.len() == 3 {
                break;
            }
        }
    }
    ids.len()
}

/// The texture coordinates `gone`'s corners take when it moves into `keep`:
/// `keep`'s on each corner's side of the seam (`seam` maps the ids of one
/// side, `uv` is the other's or every corner's).
#[derive(Clone, Copy, Debug)]
pub(super) struct UvMove {
    pub uv: u32,
    pub seam: Option<[u32; 2]>,
}

impl UvMove {
    /// The id a corner of `gone` with id `id` takes.
    pub fn of(self, id: u32) -> u32 {
        match self.seam {
            Some([from, to]) if from == id => to,
            _ => self.uv,
        }
    }
}

/// `gone → keep` with texture coordinates (issue 45: models with many UV
/// islands could not reach 20 % while every seam vertex was locked). Inside
/// a chart, `gone`'s corners take `keep`'s coordinate on `gone`'s side
/// ([`seam_side`]). A seam vertex (two coordinates) may go only along the
/// seam, into a neighbour across the seam edge: each side's corners take
/// `keep`'s coordinate on that side, so the seam loses a vertex on both
/// sides at once and no texture crosses it. A seam vertex never moves off
/// its seam, and junctions are locked.
fn uv_move(mesh: &WorkingMesh, uvs: &[[u32; 3]], gone: u32, keep: u32) -> Option<UvMove> {
    if uv_ids(mesh, uvs, gone) == 1 {
        return seam_side(mesh, uvs, gone, keep).map(|uv| UvMove { uv, seam: None });
    }
    let mut on_edge = mesh.faces_of[gone as usize]
        .iter()
        .copied()
        .filter(|&f| mesh.triangles[f as usize].contains(&keep));
    let (f, g) = (on_edge.next()?, on_edge.next()?);
    let (a, b) = (
        corner_uv(mesh, uvs, f, gone)?,
        corner_uv(mesh, uvs, g, gone)?,
    );
    if a == b {
        return None; // the edge is inside one side: it would pull the seam off
    }
    let (a_keep, b_keep) = (
        corner_uv(mesh, uvs, f, keep)?,
        corner_uv(mesh, uvs, g, keep)?,
    );
    Some(UvMove {
        uv: a_keep,
        seam: Some([b, b_keep]),
    })
}

/// `keep`'s texture coordinate on the side of the edge where `gone` lies:
/// the same in both faces on the edge, or the collapse would carry
/// `gone`'s texture across a seam (then `None`).
fn seam_side(mesh: &WorkingMesh, uvs: &[[u32; 3]], gone: u32, keep: u32) -> Option<u32> {
    let mut side = None;
    for &f in &mesh.faces_of[gone as usize] {
        if !mesh.triangles[f as usize].contains(&keep) {
            continue;
        }
        let id = corner_uv(mesh, uvs, f, keep)?;
        match side {
            None => side = Some(id),
            Some(s) if s != id => return None,
            Some(_) => {}
        }
    }
    side
}
