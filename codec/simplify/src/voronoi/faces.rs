//! The dual's faces checked against the surface they stand for (issue 45;
//! SEEDS.md 001: "long dual chords can leave the cell complex"). The
//! closed-ball property makes the dual a manifold of the input's topology,
//! which is combinatorial only: a face over three sites can still be
//! folded over its neighbours, have no area, or span a region that belongs
//! to other cells (a chord across a groove or a thin part). Each is a
//! fourth kind of violation, refined as the others are (the largest of the
//! face's cells is split):
//!
//! - **degenerate**: the face's area is nil at the mesh's scale;
//! - **folded**: its normal turns more than 90° from the surface's at its
//!   three sites (their area-weighted vertex normals, summed);
//! - **outside its cells**: the input vertex nearest its centroid (among
//!   those facing the same way, so the other side of a thin part does not
//!   count) lies in none of its three cells, nor in a cell that meets two
//!   of them. The dual face of three cells spans their Voronoi vertex, and
//!   an obtuse one's centroid can fall in a fourth cell around that vertex
//!   without the face leaving the surface; counting those as violations
//!   split cells without end on a noisy scan (nefertiti-rgb-10k at
//!   r = 0.035: 386 cover sites became 1,048, more faces failing each
//!   round, and the search for a vertex count landed on a far larger
//!   radius with a few refined patches: Hausdorff 4–8× quadric's).

use std::collections::HashSet;

use glam::DVec3;
use rstar::primitives::GeomWithData;
use rstar::RTree;
use vitrine_geodesic::Surface;

use super::closed_ball::Violation;

/// Input vertices tried, nearest first, for one facing the face's way.
const NEAREST_TRIED: usize = 16;

/// A face's area below this share of the diagonal squared is nil.
const NIL_AREA: f64 = 1e-12;

/// What the checks need of the surface, built once per simplification.
pub(super) struct FaceChecks<'a> {
    surface: &'a Surface,
    /// Each vertex's unit normal (area-weighted over its real faces).
    pub normals: Vec<DVec3>,
    /// The input vertices (not the cones), for nearest-vertex queries. An
    /// R-tree (rstar) rather than a hand-made grid: scans are far from
    /// uniform, and the queries ask for the nearest few in order.
    vertices: RTree<GeomWithData<[f64; 3], u32>>,
    nil_area: f64,
}

impl<'a> FaceChecks<'a> {
    pub fn new(surface: &'a Surface, first_cone: u32) -> Self {
        let mut normals = vec![DVec3::ZERO; surface.vertex_count()];
        for t in surface.triangles() {
            if t.iter().any(|&v| v >= first_cone) {
                continue;
            }
            let p = t.map(|v| surface.position(v));
            let n = (p[1] - p[0]).cross(p[2] - p[0]);
            for &v in t {
                normals[v as usize] += n;
            }
        }
        for n in &mut normals {
            *n = n.normalize_or_zero();
        }
        let points = (0..first_cone)
            .filter(|&v| !surface.faces_of(v).is_empty())
            .map(|v| GeomWithData::new(surface.position(v).to_array(), v))
            .collect();
        let diagonal = surface.diagonal();
        FaceChecks {
            surface,
            normals,
            vertices: RTree::bulk_load(points),
            nil_area: NIL_AREA * diagonal * diagonal,
        }
    }

    /// The violations among the dual's faces: `faces` in input vertex ids,
    /// `sites` the cells (site labels) of each, `labels` each vertex's cell.
    pub fn violations(
        &self,
        faces: &[[u32; 3]],
        sites: &[[u32; 3]],
        labels: &[u32],
    ) -> Vec<Violation> {
        let mut meeting = HashSet::new();
        for c in sites {
            for k in 0..3 {
                let (a, b) = (c[k], c[(k + 1) % 3]);
                meeting.insert((a.min(b), a.max(b)));
            }
        }
        let meet = |a: u32, b: u32| meeting.contains(&(a.min(b), a.max(b)));
        faces
            .iter()
            .zip(sites)
            .filter(|(face, cells)| !self.sound(**face, **cells, labels, meet))
            .map(|(_, &cells)| Violation::Triple(cells))
            .collect()
    }

    /// `meet`: whether two cells share a Voronoi edge (a dual edge).
    fn sound(
        &self,
        face: [u32; 3],
        cells: [u32; 3],
        labels: &[u32],
        meet: impl Fn(u32, u32) -> bool,
    ) -> bool {
        let p = face.map(|v| self.surface.position(v));
        let n = (p[1] - p[0]).cross(p[2] - p[0]);
        if n.length() / 2.0 <= self.nil_area {
            return false;
        }
        let surface_normal: DVec3 = face.iter().map(|&v| self.normals[v as usize]).sum();
        if n.dot(surface_normal) <= 0.0 {
            return false;
        }
        let centroid = (p[0] + p[1] + p[2]) / 3.0;
        let facing = self
            .vertices
            .nearest_neighbor_iter(centroid.to_array())
            .take(NEAREST_TRIED)
            .find(|v| self.normals[v.data as usize].dot(n) > 0.0);
        facing.is_none_or(|v| {
            let c = labels[v.data as usize];
            cells.contains(&c) || cells.iter().filter(|&&d| meet(c, d)).count() >= 2
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use vitrine_samples::grid;

    const N: u32 = 12;

    /// Vertex (i, j) of `grid(N)` (x = i, y = j, z = 0, faces turned to +z).
    fn id(i: u32, j: u32) -> u32 {
        j * (N + 1) + i
    }

    #[test]
    fn a_face_over_its_cells_passes_a_folded_a_flat_and_a_far_one_fail() {
        let surface = Surface::new(&grid(N)).unwrap();
        // Three cells by x: [0, 4), [4, 8), [8, 12].
        let labels: Vec<u32> = (0..surface.vertex_count() as u32)
            .map(|v| ((v % (N + 1)) / 4).min(2))
            .collect();
        let checks = FaceChecks::new(&surface, surface.vertex_count() as u32);
        let cells_of = |f: [u32; 3]| f.map(|v| labels[v as usize]);
        let face = [id(2, 3), id(10, 3), id(6, 8)];
        assert_eq!(cells_of(face), [0, 2, 1]);
        assert!(checks
            .violations(&[face], &[cells_of(face)], &labels)
            .is_empty());
        // The same face turned over: folded.
        let flipped = [face[0], face[2], face[1]];
        assert_eq!(
            checks
                .violations(&[flipped], &[cells_of(flipped)], &labels)
                .len(),
            1
        );
        // Three sites on one line: no area.
        let line = [id(1, 6), id(6, 6), id(11, 6)];
        assert_eq!(
            checks.violations(&[line], &[cells_of(line)], &labels).len(),
            1
        );
        // The face's centroid (x = 6) lies in cell 1: a face said to be over
        // cells 0, 2 and 5 is outside them.
        assert_eq!(checks.violations(&[face], &[[0, 2, 5]], &labels).len(), 1);
        // Unless cell 1 meets two of them (another dual face joins it to
        // cells 0 and 2): it is then one of the cells around the face's
        // Voronoi vertex.
        assert!(checks
            .violations(&[face, face], &[[0, 2, 5], [0, 2, 1]], &labels)
            .is_empty());
    }
}
