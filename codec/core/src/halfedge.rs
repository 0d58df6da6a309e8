//! Index-based half-edge connectivity shared by the encoder and the decoder.
//!
//! Half-edge `h` lives in face `h / 3`; the face's half-edges are
//! `3f, 3f+1, 3f+2` in counter-clockwise order, so `next` and `prev` are
//! arithmetic and only `origin` and `twin` are stored. A half-edge runs from
//! `origin[h]` to `origin[next(h)]`. Dead face slots have `origin[3f] == NONE`.

use crate::edges::Edges;
use crate::{Error, IndexedMesh, Result};

pub(crate) const NONE: u32 = u32::MAX;

#[inline]
pub(crate) fn next(h: u32) -> u32 {
    if h % 3 == 2 {
        h - 2
    } else {
        h + 1
    }
}

#[inline]
pub(crate) fn prev(h: u32) -> u32 {
    if h.is_multiple_of(3) {
        h + 2
    } else {
        h - 1
    }
}

#[inline]
pub(crate) fn face(h: u32) -> u32 {
    h / 3
}

#[derive(Clone, Debug, Default)]
pub(crate) struct Connectivity {
    pub origin: Vec<u32>,
    pub twin: Vec<u32>,
    /// One live outgoing half-edge per vertex (`NONE` once removed).
    pub out: Vec<u32>,
}

impl Connectivity {
    /// Builds twins from a triangle list. Fails on a non-manifold or
    /// inconsistently oriented edge: `vitrine_mesh::repair::prepare` removes those.
    pub(crate) fn from_triangles(vertex_count: usize, triangles: &[[u32; 3]]) -> Result<Self> {
        check_indices(vertex_count, triangles)?;
        Self::from_indexed_triangles(vertex_count, triangles)
    }

    /// [`Connectivity::from_triangles`] for faces whose corners are known to
    /// index `vertex_count` vertices (it panics otherwise).
    pub(crate) fn from_indexed_triangles(
        vertex_count: usize,
        triangles: &[[u32; 3]],
    ) -> Result<Self> {
        let origin = triangles.as_flattened().to_vec();
        let mut twin = vec![NONE; origin.len()];
        Edges::build(triangles, vertex_count).try_for_each(|edge| match *edge {
            [_] => Ok(()),
            [h, g] => {
                if origin[h as usize] == origin[g as usize] {
                    return Err(non_manifold("inconsistently oriented", &origin, h));
                }
                twin[h as usize] = g;
                twin[g as usize] = h;
                Ok(())
            }
            _ => Err(non_manifold(
                "shared by more than two faces",
                &origin,
                edge[0],
            )),
        })?;
        let conn = Connectivity::paired(vertex_count, origin, twin);
        conn.check_vertex_fans()?;
        Ok(conn)
    }

    /// Faces `origin` whose half-edges are paired by `twin` already, each
    /// vertex leaving by the last half-edge that starts at it (as
    /// [`Connectivity::from_triangles`] chooses). `origin` must index
    /// `vertex_count` vertices (it panics otherwise).
    pub(crate) fn paired(vertex_count: usize, origin: Vec<u32>, twin: Vec<u32>) -> Self {
        let mut out = vec![NONE; vertex_count];
        for (h, &v) in origin.iter().enumerate() {
            out[v as usize] = h as u32;
        }
        Connectivity { origin, twin, out }
    }

    /// Every vertex's faces must form one fan, or rotation would miss some.
    pub(crate) fn check_vertex_fans(&self) -> Result<()> {
        let mut seen = vec![0u32; self.out.len()];
        for v in 0..self.out.len() as u32 {
            if self.out[v as usize] == NONE {
                continue;
            }
            let mut count = 0u32;
            self.for_each_outgoing(v, |_| count += 1);
            seen[v as usize] = count;
        }
        let mut total = vec![0u32; self.out.len()];
        for &v in &self.origin {
            total[v as usize] += 1;
        }
        if let Some(v) = (0..self.out.len()).find(|&v| seen[v] != total[v]) {
            return Err(Error::Unsupported(format!(
                "vertex {v} is non-manifold: its faces form more than one fan"
            )));
        }
        Ok(())
    }

    #[inline]
    pub(crate) fn target(&self, h: u32) -> u32 {
        self.origin[next(h) as usize]
    }

    /// Appends an empty face slot and returns its index.
    pub(crate) fn append_face(&mut self) -> u32 {
        let f = self.face_count_slots() as u32;
        self.origin.extend_from_slice(&[NONE; 3]);
        self.twin.extend_from_slice(&[NONE; 3]);
        f
    }

    pub(crate) fn face_count_slots(&self) -> usize {
        self.origin.len() / 3
    }

    #[inline]
    pub(crate) fn face_alive(&self, f: u32) -> bool {
        self.origin[3 * f as usize] != NONE
    }

    /// Counter-clockwise neighbour of outgoing half-edge `h` around its origin.
    #[inline]
    pub(crate) fn rotate_ccw(&self, h: u32) -> u32 {
        self.twin[prev(h) as usize]
    }

    /// Calls `f` on every outgoing half-edge of `v`, border vertices included.
    pub(crate) fn for_each_outgoing(&self, v: u32, mut f: impl FnMut(u32)) {
        let start = self.out[v as usize];
        let mut h = start;
        loop {
            f(h);
            h = self.rotate_ccw(h);
            if h == start {
                return;
            }
            if h == NONE {
                break;
            }
        }
        // Border: walk clockwise from the start to reach the rest.
        let mut h = self.twin[start as usize];
        while h != NONE {
            let out = next(h);
            f(out);
            h = self.twin[out as usize];
        }
    }

    /// The outgoing half-edge `a → b`, if the edge exists.
    pub(crate) fn find_half_edge(&self, a: u32, b: u32) -> Option<u32> {
        let mut found = None;
        self.for_each_outgoing(a, |h| {
            if found.is_none() && self.target(h) == b {
                found = Some(h);
            }
        });
        found
    }

    /// Whether some edge joins `a` and `b`, in either direction.
    pub(crate) fn has_edge(&self, a: u32, b: u32) -> bool {
        let mut found = false;
        self.for_each_outgoing(a, |h| {
            found |= self.target(h) == b || self.origin[prev(h) as usize] == b;
        });
        found
    }

    /// Live triangles in slot order.
    pub(crate) fn triangles(&self) -> impl Iterator<Item = [u32; 3]> + '_ {
        self.origin
            .chunks_exact(3)
            .filter(|t| t[0] != NONE)
            .map(|t| [t[0], t[1], t[2]])
    }
}

fn non_manifold(what: &str, origin: &[u32], h: u32) -> Error {
    let (a, b) = (origin[h as usize], origin[next(h) as usize]);
    Error::Unsupported(format!("edge ({a}, {b}) is non-manifold: {what}"))
}

/// An error naming the first face with a corner beyond `vertex_count`.
pub(crate) fn check_indices(vertex_count: usize, triangles: &[[u32; 3]]) -> Result<()> {
    if 3 * triangles.len() as u64 >= NONE as u64 {
        // Half-edges are numbered in 32 bits.
        return Err(Error::Limit(format!("{} faces", triangles.len())));
    }
    match triangles
        .iter()
        .find(|t| t.iter().any(|&v| v as usize >= vertex_count))
    {
        Some(t) => Err(Error::Unsupported(format!(
            "face {t:?} indexes a missing vertex"
        ))),
        None => Ok(()),
    }
}

/// Builds connectivity for a mesh that passed repair.
pub(crate) fn connectivity(mesh: &IndexedMesh) -> Result<Connectivity> {
    Connectivity::from_triangles(mesh.positions.len(), &mesh.triangles)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotation_visits_all_neighbours_of_border_vertex() {
        // A fan of three triangles around vertex 0, open on one side.
        let tris = [[0, 1, 2], [0, 2, 3], [0, 3, 4]];
        let c = Connectivity::from_triangles(5, &tris).unwrap();
        let mut targets = Vec::new();
        c.for_each_outgoing(0, |h| targets.push(c.target(h)));
        targets.sort();
        assert_eq!(targets, vec![1, 2, 3]);
        assert!(c.has_edge(0, 4));
        assert!(!c.has_edge(1, 3));
    }

    #[test]
    fn has_edge_agrees_with_the_face_list_on_borders_and_closed_surfaces() {
        use crate::samples::icosphere;
        // Two holes: the umbrellas of vertices 0 and 40 taken out.
        let mut open = icosphere(2);
        open.triangles
            .retain(|t| !t.contains(&0) && !t.contains(&40));
        for (mesh, bordered) in [(icosphere(2), false), (open, true)] {
            let n = mesh.positions.len();
            let c = Connectivity::from_triangles(n, &mesh.triangles).unwrap();
            let mut edges = std::collections::HashSet::new();
            for t in &mesh.triangles {
                for k in 0..3 {
                    let (a, b) = (t[k], t[(k + 1) % 3]);
                    edges.insert((a.min(b), a.max(b)));
                }
            }
            assert_eq!(c.twin.contains(&NONE), bordered);
            // Vertices without faces (the holes' centres) have no fan to ask.
            for a in (0..n as u32).filter(|&a| c.out[a as usize] != NONE) {
                for b in 0..n as u32 {
                    let expected = edges.contains(&(a.min(b), a.max(b)));
                    assert_eq!(c.has_edge(a, b), expected, "{a}–{b}");
                }
            }
        }
    }

    #[test]
    fn rejects_edge_with_three_faces() {
        let tris = [[0, 1, 2], [1, 0, 3], [0, 1, 4]];
        assert!(Connectivity::from_triangles(5, &tris).is_err());
    }
}
