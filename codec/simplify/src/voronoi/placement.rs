//! Where the dual's vertices go. The seed keeps each site where it is (an
//! input vertex), so every output face is a chord between three points of
//! the surface and cuts inside it wherever the surface curves: at 10 % of
//! lucy or nefertiti the seed's output lay 3–5× further from the scan than
//! quadric simplification's (session 29). [`VoronoiPlacement::Quadric`]
//! moves each site as ACVD does (Valette, Chassery & Prost 2008, quadric
//! relocation): to the least summed squared distance to the planes of its
//! cell's faces, plus a small pull towards the site along the directions
//! those planes leave free (a flat cell keeps its site's tangential place,
//! a crease cell stays on the crease, a corner cell goes to the corner).
//! Border cells also weigh planes standing on their border edges, so a
//! hole's rim keeps its line. A point further from the site than the
//! cell's farthest vertex is refused, and so is any move that folds an
//! output face or flattens it: its three corners go back to their sites,
//! which the diagram's face checks already passed.

use glam::DVec3;
use vitrine_geodesic::Surface;

use crate::collapse::quadric::Quadric;

/// Where each output vertex goes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum VoronoiPlacement {
    /// At its site, an input vertex, bit for bit (the seed).
    #[default]
    Sites,
    /// At the minimum of its cell's quadric, near the site.
    Quadric,
}

/// The anchor's pull, relative to the trace of a cell's quadric: small
/// enough that a curved cell's minimum moves by a fraction of a per cent,
/// large enough to pin the free directions of a flat one.
const ANCHOR_WEIGHT: f64 = 1e-5;

/// A border edge's plane weighs this much per squared length, against the
/// faces' area: it holds the rim (Garland & Heckbert's boundary planes).
const BORDER_WEIGHT: f64 = 10.0;

/// The dual and the diagram it came from.
pub(super) struct Dual<'a> {
    pub surface: &'a Surface,
    pub first_cone: u32,
    /// Each input vertex's cell.
    pub labels: &'a [u32],
    pub site_vertex: &'a [u32],
    /// Output faces over input vertex ids (the sites).
    pub faces: &'a [[u32; 3]],
    /// Each input vertex's unit normal (the face checks').
    pub normals: &'a [DVec3],
}

impl Dual<'_> {
    /// Each site's output position (cones' untouched, at the cone).
    pub fn relocate(&self) -> Vec<DVec3> {
        let sites = self.site_vertex.len();
        let mut at: Vec<DVec3> = self
            .site_vertex
            .iter()
            .map(|&v| self.surface.position(v))
            .collect();
        let quadrics = self.cell_quadrics();
        let mut reach = vec![0.0f64; sites];
        for v in 0..self.first_cone {
            let s = self.labels[v as usize] as usize;
            if s < sites {
                let d = self.surface.position(v).distance(at[s]);
                reach[s] = reach[s].max(d);
            }
        }
        for s in 0..sites {
            if self.site_vertex[s] >= self.first_cone {
                continue;
            }
            if let Some(x) = quadrics[s]
                .minimum_near(at[s], ANCHOR_WEIGHT)
                .filter(|x| x.distance(at[s]) <= reach[s])
            {
                at[s] = x;
            }
        }
        self.unfold(&mut at);
        at
    }

    /// Each cell's quadric: the area-weighted planes of the faces at its
    /// vertices (each face once per corner in the cell, as the sum of the
    /// vertices' quadrics), and planes on its border edges.
    fn cell_quadrics(&self) -> Vec<Quadric> {
        let mut q = vec![Quadric::default(); self.site_vertex.len()];
        let cell = |v: u32| self.labels[v as usize] as usize;
        for t in self.surface.triangles() {
            let p = t.map(|v| self.surface.position(v));
            let cross = (p[1] - p[0]).cross(p[2] - p[0]);
            let area = cross.length() / 2.0;
            if area <= 0.0 {
                continue;
            }
            if let Some(&cone) = t.iter().find(|&&v| v >= self.first_cone) {
                // A cone's face [b, a, cone] stands on the border edge a → b.
                let k = t.iter().position(|&v| v == cone).unwrap_or(2);
                let (b, a) = (t[(k + 1) % 3], t[(k + 2) % 3]);
                let (pa, pb) = (self.surface.position(a), self.surface.position(b));
                let across = (pb - pa).cross(self.normals[a as usize] + self.normals[b as usize]);
                if across.length() > 0.0 {
                    let plane = Quadric::plane(
                        across.normalize(),
                        pa,
                        BORDER_WEIGHT * pa.distance_squared(pb),
                    );
                    q[cell(a)] += plane;
                    q[cell(b)] += plane;
                }
                continue;
            }
            let plane = Quadric::plane(cross / (2.0 * area), p[0], area);
            for &v in t {
                q[cell(v)] += plane;
            }
        }
        q
    }

    /// Sends the corners of every face the move folds or flattens back to
    /// their sites, until none does (each vertex goes back once at most).
    fn unfold(&self, at: &mut [DVec3]) {
        let site_of = |v: u32| self.labels[v as usize] as usize;
        let nil = 1e-12 * self.surface.diagonal().powi(2);
        loop {
            let mut reverted = false;
            for face in self.faces {
                let p = face.map(|v| at[site_of(v)]);
                let n = (p[1] - p[0]).cross(p[2] - p[0]);
                let surface: DVec3 = face.iter().map(|&v| self.normals[v as usize]).sum();
                if n.length() / 2.0 > nil && n.dot(surface) > 0.0 {
                    continue;
                }
                for &v in face {
                    let home = self.surface.position(v);
                    if at[site_of(v)] != home {
                        at[site_of(v)] = home;
                        reverted = true;
                    }
                }
            }
            if !reverted {
                break;
            }
        }
    }
}
