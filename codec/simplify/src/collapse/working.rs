//! The mesh while it shrinks: triangles keep their slots (a dead face is
//! skipped), vertices keep theirs (a merged vertex lives on in the slot of
//! the one it was merged into), so the input's indices name everything
//! until the final compaction.

use glam::DVec3;
use vitrine_codec::{Error, IndexedMesh, Result};

use super::quadric::{vertex_quadrics, Quadric};
use crate::deviation::{border_vertices, normal_deviation, one_ring_max};
use crate::FeatureThreshold;

/// One vertex merged into another: `gone`'s faces move to `keep`, the two
/// faces on the edge between them die, and `keep` moves to `to`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Merge {
    pub keep: u32,
    pub gone: u32,
    pub to: [f32; 3],
    pub colour: Option<[f32; 3]>,
}

pub(crate) struct WorkingMesh {
    pub positions: Vec<[f32; 3]>,
    /// Colours as floats, so that averages of averages stay exact enough.
    pub colours: Option<Vec<[f32; 3]>>,
    pub triangles: Vec<[u32; 3]>,
    pub face_alive: Vec<bool>,
    pub faces_of: Vec<Vec<u32>>,
    pub border: Vec<bool>,
    /// The full resolution's one-ring maximum θ, carried through merges
    /// as the largest value of the vertices a survivor stands for.
    pub theta: Vec<f64>,
    /// The sum of the input's area-weighted vertex normals over the input
    /// vertices each survivor stands for: the orientation of the patch it
    /// replaces, which faces around it must keep (per-merge turn limits
    /// alone let a face drift over in several steps).
    pub reference: Vec<DVec3>,
    /// Each survivor's error quadric (the sum over the input vertices it
    /// stands for), when the placement uses them.
    pub quadrics: Option<Vec<Quadric>>,
    pub live_vertices: usize,
}

impl WorkingMesh {
    /// Validates the input and measures θ, the threshold τ (returned, in
    /// radians) and the borders on it.
    pub fn new(mesh: &IndexedMesh, threshold: FeatureThreshold) -> Result<(Self, f64)> {
        validate(mesh)?;
        let theta = normal_deviation(mesh);
        let threshold = threshold.radians(&theta);
        let ring = one_ring_max(mesh, &theta);
        Ok((Self::build(mesh, ring)?, threshold))
    }

    /// The mesh without θ (every vertex at 0), for simplifiers that cost
    /// collapses otherwise (Melax).
    pub fn without_deviation(mesh: &IndexedMesh) -> Result<Self> {
        validate(mesh)?;
        Self::build(mesh, vec![0.0; mesh.positions.len()])
    }

    fn build(mesh: &IndexedMesh, ring: Vec<f64>) -> Result<Self> {
        let mut faces_of = vec![Vec::new(); mesh.positions.len()];
        for (f, t) in mesh.triangles.iter().enumerate() {
            for &v in t {
                faces_of[v as usize].push(f as u32);
            }
        }
        let live_vertices = faces_of.iter().filter(|f| !f.is_empty()).count();
        let working = WorkingMesh {
            positions: mesh.positions.clone(),
            colours: mesh
                .colors
                .as_ref()
                .map(|c| c.iter().map(|c| c.map(f32::from)).collect()),
            triangles: mesh.triangles.clone(),
            face_alive: vec![true; mesh.triangles.len()],
            faces_of,
            border: border_vertices(mesh),
            theta: ring,
            reference: vertex_normals(mesh),
            quadrics: None,
            live_vertices,
        };
        working.check_fans()?;
        Ok(working)
    }

    /// Starts carrying error quadrics through the merges.
    pub fn with_quadrics(mut self) -> Self {
        self.quadrics = Some(vertex_quadrics(&self.positions, &self.triangles));
        self
    }

    /// The quadric `v` carries (zero without quadrics).
    pub fn quadric(&self, v: u32) -> Quadric {
        self.quadrics
            .as_ref()
            .map_or(Quadric::default(), |q| q[v as usize])
    }

    pub fn live_faces(&self) -> usize {
        self.face_alive.iter().filter(|&&a| a).count()
    }

    pub fn point(&self, v: u32) -> DVec3 {
        DVec3::from(self.positions[v as usize].map(f64::from))
    }

    pub fn colour(&self, v: u32) -> Option<[f32; 3]> {
        self.colours.as_ref().map(|c| c[v as usize])
    }

    /// Not on a border and no feature near it at full resolution.
    pub fn removable(&self, v: u32, threshold: f64) -> bool {
        let v = v as usize;
        !self.border[v] && !self.faces_of[v].is_empty() && self.theta[v] <= threshold
    }

    /// The vertices sharing a face with `v`, sorted, into `out`.
    pub fn neighbours(&self, v: u32, out: &mut Vec<u32>) {
        out.clear();
        for &f in &self.faces_of[v as usize] {
            out.extend(self.triangles[f as usize].iter().filter(|&&w| w != v));
        }
        out.sort_unstable();
        out.dedup();
    }

    /// Whether a live face has exactly these three corners, in any order.
    pub fn has_face(&self, a: u32, b: u32, c: u32) -> bool {
        self.faces_of[a as usize].iter().any(|&f| {
            let t = self.triangles[f as usize];
            t.contains(&b) && t.contains(&c)
        })
    }

    pub fn apply(&mut self, m: &Merge) {
        let (keep, gone) = (m.keep as usize, m.gone as usize);
        // Vertices that lose faces are counted out only at the end: the
        // survivor may lose all its own faces and gain the merged ones. An
        // edge has at most two faces, so at most two opposite corners.
        let mut touched = [m.keep; 3];
        let mut n = 1;
        for f in std::mem::take(&mut self.faces_of[gone]) {
            let t = self.triangles[f as usize];
            if t.contains(&m.keep) {
                self.face_alive[f as usize] = false;
                for v in t.into_iter().filter(|&v| v != m.gone) {
                    self.unlink(v, f);
                    if !touched[..n].contains(&v) && n < 3 {
                        touched[n] = v;
                        n += 1;
                    }
                }
            } else {
                self.triangles[f as usize] = t.map(|v| if v == m.gone { m.keep } else { v });
                self.faces_of[keep].push(f);
            }
        }
        let emptied = touched[..n]
            .iter()
            .filter(|&&v| self.faces_of[v as usize].is_empty())
            .count();
        self.live_vertices -= 1 + emptied;
        self.positions[keep] = m.to;
        if let (Some(c), Some(colour)) = (&mut self.colours, m.colour) {
            c[keep] = colour;
        }
        self.theta[keep] = self.theta[keep].max(self.theta[gone]);
        let absorbed = self.reference[gone];
        self.reference[keep] += absorbed;
        if let Some(q) = &mut self.quadrics {
            let absorbed = q[gone];
            q[keep] += absorbed;
        }
    }

    /// Kills a face; a vertex left without faces stops counting.
    pub fn delete_face(&mut self, f: u32) {
        self.face_alive[f as usize] = false;
        for v in self.triangles[f as usize] {
            if self.unlink(v, f) && self.faces_of[v as usize].is_empty() {
                self.live_vertices -= 1;
            }
        }
    }

    /// Drops `f` from `v`'s faces; whether it was there.
    fn unlink(&mut self, v: u32, f: u32) -> bool {
        let faces = &mut self.faces_of[v as usize];
        let found = faces.iter().position(|&g| g == f);
        if let Some(i) = found {
            faces.swap_remove(i);
        }
        found.is_some()
    }

    /// The live mesh with unused vertices dropped, in slot order, and the
    /// input vertex each output vertex's slot belonged to.
    pub fn compact(&self) -> (IndexedMesh, Vec<u32>) {
        let mut map = vec![u32::MAX; self.positions.len()];
        let mut origin = Vec::with_capacity(self.live_vertices);
        for (v, faces) in self.faces_of.iter().enumerate() {
            if !faces.is_empty() {
                map[v] = origin.len() as u32;
                origin.push(v as u32);
            }
        }
        let triangles = (0..self.triangles.len())
            .filter(|&f| self.face_alive[f])
            .map(|f| self.triangles[f].map(|v| map[v as usize]))
            .collect();
        let mesh = IndexedMesh {
            positions: origin.iter().map(|&v| self.positions[v as usize]).collect(),
            colors: self.colours.as_ref().map(|c| {
                origin
                    .iter()
                    .map(|&v| c[v as usize].map(|x| x.round().clamp(0.0, 255.0) as u8))
                    .collect()
            }),
            triangles,
        };
        (mesh, origin)
    }

    /// Every vertex off the border must have one fan: a single cycle of faces.
    fn check_fans(&self) -> Result<()> {
        for v in 0..self.positions.len() as u32 {
            let faces = &self.faces_of[v as usize];
            if self.border[v as usize] || faces.is_empty() {
                continue;
            }
            let mut f = faces[0];
            for walked in 1.. {
                // Across the edge (v, next): the face that has (next, v).
                let next = after(self.triangles[f as usize], v);
                let across = faces.iter().copied().find(|&g| {
                    let t = self.triangles[g as usize];
                    t.contains(&next) && after(t, next) == v
                });
                match across {
                    Some(g) if g == faces[0] && walked == faces.len() => break,
                    Some(g) if g != faces[0] && walked < faces.len() => f = g,
                    _ => {
                        return Err(Error::Unsupported(format!(
                            "vertex {v} has more than one fan of faces (run vitrine_mesh::repair::prepare first)"
                        )))
                    }
                }
            }
        }
        Ok(())
    }
}

/// The corner after `v` in `t`, counter-clockwise (`t` must contain `v`).
pub(crate) fn after(t: [u32; 3], v: u32) -> u32 {
    let i = t.iter().position(|&w| w == v).unwrap_or(0);
    t[(i + 1) % 3]
}

/// Area-weighted vertex normals (twice the area, unnormalised).
fn vertex_normals(mesh: &IndexedMesh) -> Vec<DVec3> {
    let mut normals = vec![DVec3::ZERO; mesh.positions.len()];
    let p = |v: u32| DVec3::from(mesh.positions[v as usize].map(f64::from));
    for &[a, b, c] in &mesh.triangles {
        let n = (p(b) - p(a)).cross(p(c) - p(a));
        for v in [a, b, c] {
            normals[v as usize] += n;
        }
    }
    normals
}

/// Indices in range, finite positions, no degenerate face, and every
/// directed edge used once (an oriented mesh, each edge on ≤ 2 faces).
fn validate(mesh: &IndexedMesh) -> Result<()> {
    let n = mesh.positions.len();
    if let Some(v) = mesh
        .positions
        .iter()
        .position(|p| p.iter().any(|c| !c.is_finite()))
    {
        return Err(Error::input("mesh", format!("vertex {v} is not finite")));
    }
    if mesh.colors.as_ref().is_some_and(|c| c.len() != n) {
        return Err(Error::input(
            "mesh",
            "colour count differs from vertex count",
        ));
    }
    let mut directed = Vec::with_capacity(mesh.triangles.len() * 3);
    for (f, &t) in mesh.triangles.iter().enumerate() {
        if t.iter().any(|&v| v as usize >= n) {
            return Err(Error::input(
                "mesh",
                format!("face {f} indexes past the vertices"),
            ));
        }
        if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
            return Err(Error::Unsupported(format!("face {f} {t:?} is degenerate")));
        }
        directed.extend((0..3).map(|k| (u64::from(t[k]) << 32) | u64::from(t[(k + 1) % 3])));
    }
    directed.sort_unstable();
    if let Some(w) = directed.windows(2).find(|w| w[0] == w[1]) {
        return Err(Error::Unsupported(format!(
            "edge ({}, {}) is used twice in one direction (non-manifold or misoriented; run vitrine_mesh::repair::prepare first)",
            w[0] >> 32,
            w[0] & u64::from(u32::MAX)
        )));
    }
    Ok(())
}
