//! The mesh as the propagations walk it: positions in f64, the faces around
//! each vertex, each vertex's neighbours with edge lengths, and the face
//! across each edge (for unfolding). Built once, after checking that the
//! mesh is an oriented 2-manifold (borders allowed), so that no walk below
//! can meet a shape it does not expect.

use std::collections::HashMap;

use glam::DVec3;
use vitrine_codec::{Error, IndexedMesh, Result};

/// No face, no vertex.
pub const NONE: u32 = u32::MAX;

/// More faces than this is refused rather than allocated (indices and the
/// per-corner tables stay well inside u32).
pub const MAX_FACES: usize = 1 << 27;

/// Compressed rows: `items[offsets[i]..offsets[i + 1]]` belong to row i.
#[derive(Clone, Debug, Default)]
struct Rows {
    offsets: Vec<u32>,
    items: Vec<u32>,
}

impl Rows {
    fn of(&self, i: usize) -> &[u32] {
        &self.items[self.offsets[i] as usize..self.offsets[i + 1] as usize]
    }
}

/// An oriented 2-manifold triangle mesh, ready for distance propagation.
#[derive(Clone, Debug)]
pub struct Surface {
    positions: Vec<DVec3>,
    triangles: Vec<[u32; 3]>,
    faces: Rows,
    neighbours: Rows,
    /// Length of the edge to each entry of `neighbours`, same layout.
    lengths: Vec<f64>,
    /// For face f, corner k: the face across the edge (t[k], t[k+1]).
    across: Vec<[u32; 3]>,
    /// Vertices that no distance passes through (the simplifier's cones).
    blocked: Vec<bool>,
}

impl Surface {
    /// Checks `mesh` and builds the tables. Errors (never panics) on NaN or
    /// infinite positions, indices out of range, a face that repeats a
    /// vertex, an edge used twice in one direction or by three faces, a
    /// vertex whose faces form two fans, or more than [`MAX_FACES`] faces.
    pub fn new(mesh: &IndexedMesh) -> Result<Self> {
        Self::from_parts(&mesh.positions, &mesh.triangles)
    }

    /// [`Surface::new`] on bare buffers.
    pub fn from_parts(positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> Result<Self> {
        let fail = |detail: String| Err(Error::input("mesh", detail));
        if triangles.len() > MAX_FACES || positions.len() > 3 * MAX_FACES {
            return Err(Error::Limit(format!(
                "{} faces and {} vertices: at most {MAX_FACES} faces",
                triangles.len(),
                positions.len()
            )));
        }
        if let Some(v) = positions
            .iter()
            .position(|p| p.iter().any(|c| !c.is_finite()))
        {
            return fail(format!("vertex {v} has a non-finite coordinate"));
        }
        let n = positions.len();
        for (f, t) in triangles.iter().enumerate() {
            if t.iter().any(|&v| v as usize >= n) {
                return fail(format!("face {f} {t:?} indexes past {n} vertices"));
            }
            if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
                return fail(format!("face {f} {t:?} repeats a vertex"));
            }
        }
        let positions: Vec<DVec3> = positions
            .iter()
            .map(|p| DVec3::from(p.map(f64::from)))
            .collect();
        let across = across(triangles)?;
        let faces = vertex_faces(n, triangles);
        let (neighbours, lengths) = vertex_neighbours(&positions, triangles, &faces);
        let surface = Surface {
            positions,
            triangles: triangles.to_vec(),
            faces,
            neighbours,
            lengths,
            across,
            blocked: vec![false; n],
        };
        surface.check_fans()?;
        Ok(surface)
    }

    /// Vertices that distances must not pass through: they get none.
    pub fn block(&mut self, vertex: u32) {
        self.blocked[vertex as usize] = true;
    }

    pub fn is_blocked(&self, vertex: u32) -> bool {
        self.blocked[vertex as usize]
    }

    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    pub fn position(&self, vertex: u32) -> DVec3 {
        self.positions[vertex as usize]
    }

    /// Faces using `vertex`.
    pub fn faces_of(&self, vertex: u32) -> &[u32] {
        self.faces.of(vertex as usize)
    }

    /// Neighbours of `vertex` (sorted) and the lengths of the edges to them.
    pub fn neighbours(&self, vertex: u32) -> (&[u32], &[f64]) {
        let v = vertex as usize;
        let range = self.neighbours.offsets[v] as usize..self.neighbours.offsets[v + 1] as usize;
        (&self.neighbours.items[range.clone()], &self.lengths[range])
    }

    /// An id for the edge (v, w), the same both ways, below
    /// [`Surface::edge_ids`]; `None` when they share no face.
    pub fn edge_id(&self, v: u32, w: u32) -> Option<u32> {
        let (v, w) = (v.min(w), v.max(w));
        let row = self.neighbours(v).0;
        let k = row.binary_search(&w).ok()?;
        Some(self.neighbours.offsets[v as usize] + k as u32)
    }

    /// One more than the largest [`Surface::edge_id`].
    pub fn edge_ids(&self) -> usize {
        self.neighbours.items.len()
    }

    /// The face across edge (t[k], t[k+1]) of face `face`, or [`NONE`] on a border.
    pub fn across(&self, face: u32, k: usize) -> u32 {
        self.across[face as usize][k]
    }

    /// Length of the bounding box's diagonal (0 for no vertex).
    pub fn diagonal(&self) -> f64 {
        let mut lo = DVec3::splat(f64::INFINITY);
        let mut hi = DVec3::splat(f64::NEG_INFINITY);
        for f in &self.triangles {
            for &v in f {
                lo = lo.min(self.positions[v as usize]);
                hi = hi.max(self.positions[v as usize]);
            }
        }
        if lo.x <= hi.x {
            (hi - lo).length()
        } else {
            0.0
        }
    }

    /// The border as loops of vertices, each in the direction of its faces.
    pub fn boundary_loops(&self) -> Vec<Vec<u32>> {
        // On a manifold each border vertex starts exactly one border edge.
        let mut next = HashMap::new();
        for (f, t) in self.triangles.iter().enumerate() {
            for k in 0..3 {
                if self.across[f][k] == NONE {
                    next.insert(t[k], t[(k + 1) % 3]);
                }
            }
        }
        let mut starts: Vec<u32> = next.keys().copied().collect();
        starts.sort_unstable();
        let mut seen = HashMap::new();
        let mut loops = Vec::new();
        for s in starts {
            if seen.contains_key(&s) {
                continue;
            }
            let mut ring = Vec::new();
            let mut v = s;
            while seen.insert(v, ()).is_none() {
                ring.push(v);
                v = next[&v];
            }
            loops.push(ring);
        }
        loops
    }

    /// Connected components of the used vertices: how many, and each
    /// vertex's (`NONE` for a vertex no face uses).
    pub fn components(&self) -> (usize, Vec<u32>) {
        let mut component = vec![NONE; self.vertex_count()];
        let mut count = 0;
        let mut stack = Vec::new();
        for s in 0..self.vertex_count() as u32 {
            if component[s as usize] != NONE || self.faces_of(s).is_empty() {
                continue;
            }
            component[s as usize] = count;
            stack.push(s);
            while let Some(v) = stack.pop() {
                for &w in self.neighbours(v).0 {
                    if component[w as usize] == NONE {
                        component[w as usize] = count;
                        stack.push(w);
                    }
                }
            }
            count += 1;
        }
        (count as usize, component)
    }

    /// Every vertex's faces must form one fan: walking across edges from
    /// one face around the vertex, both ways, reaches them all.
    fn check_fans(&self) -> Result<()> {
        for v in 0..self.vertex_count() as u32 {
            let around = self.faces_of(v).len();
            if around == 0 {
                continue;
            }
            let (ahead, closed) = self.walk_fan(v, true);
            let reached = if closed {
                ahead
            } else {
                ahead + self.walk_fan(v, false).0 - 1
            };
            if reached != around {
                return Err(Error::input(
                    "mesh",
                    format!("vertex {v} is non-manifold: its faces form more than one fan"),
                ));
            }
        }
        Ok(())
    }

    /// Faces met walking around `v` from its first face, across the edges
    /// leaving v (or entering it), and whether the walk came back.
    fn walk_fan(&self, v: u32, leaving: bool) -> (usize, bool) {
        let around = self.faces_of(v);
        let first = around[0];
        let (mut f, mut count) = (first, 1);
        while count <= around.len() {
            let t = self.triangles[f as usize];
            let k = t.iter().position(|&w| w == v).unwrap_or(0);
            let g = self.across[f as usize][if leaving { k } else { (k + 2) % 3 }];
            if g == NONE {
                return (count, false);
            }
            if g == first {
                return (count, true);
            }
            count += 1;
            f = g;
        }
        (count, false)
    }
}

/// The face across every edge; errors on an edge used twice in one
/// direction (inconsistent orientation or a duplicate face) or by three faces.
fn across(triangles: &[[u32; 3]]) -> Result<Vec<[u32; 3]>> {
    let mut directed: HashMap<(u32, u32), u32> = HashMap::with_capacity(triangles.len() * 3);
    for (f, t) in triangles.iter().enumerate() {
        for k in 0..3 {
            let edge = (t[k], t[(k + 1) % 3]);
            if let Some(g) = directed.insert(edge, f as u32) {
                return Err(Error::input(
                    "mesh",
                    format!(
                        "edge {edge:?} is used in the same direction by faces {g} and {f} \
                         (non-manifold, duplicate or inconsistently oriented)"
                    ),
                ));
            }
        }
    }
    Ok(triangles
        .iter()
        .map(|t| [0, 1, 2].map(|k| *directed.get(&(t[(k + 1) % 3], t[k])).unwrap_or(&NONE)))
        .collect())
}

fn vertex_faces(n: usize, triangles: &[[u32; 3]]) -> Rows {
    let mut offsets = vec![0u32; n + 1];
    for t in triangles {
        for &v in t {
            offsets[v as usize + 1] += 1;
        }
    }
    for i in 0..n {
        offsets[i + 1] += offsets[i];
    }
    let mut next = offsets.clone();
    let mut items = vec![0u32; offsets[n] as usize];
    for (f, t) in triangles.iter().enumerate() {
        for &v in t {
            items[next[v as usize] as usize] = f as u32;
            next[v as usize] += 1;
        }
    }
    Rows { offsets, items }
}

fn vertex_neighbours(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    faces: &Rows,
) -> (Rows, Vec<f64>) {
    let n = positions.len();
    let mut offsets = Vec::with_capacity(n + 1);
    let mut items = Vec::with_capacity(faces.items.len());
    let mut lengths = Vec::with_capacity(faces.items.len());
    let mut ring = Vec::new();
    offsets.push(0);
    for v in 0..n {
        ring.clear();
        for &f in faces.of(v) {
            ring.extend(
                triangles[f as usize]
                    .iter()
                    .copied()
                    .filter(|&w| w as usize != v),
            );
        }
        ring.sort_unstable();
        ring.dedup();
        for &w in &ring {
            items.push(w);
            lengths.push(positions[v].distance(positions[w as usize]));
        }
        offsets.push(items.len() as u32);
    }
    (Rows { offsets, items }, lengths)
}
