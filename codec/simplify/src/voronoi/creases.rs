//! Sharp creases (issue 45): the seed's cover puts sites wherever its order
//! falls, so on a part with flat faces and sharp edges (a machined plate, a
//! plinth, a carved moulding) the dual's faces join sites on both sides of
//! an edge and cut it off (a genus-3 plate lost 1 % of its diagonal where
//! quadric simplification lost nothing). Here the cover takes, before any
//! other vertex, the corners (vertices where one or three or more sharp
//! edges meet), then the vertices of sharp edges: with sites along every
//! crease about r apart, neighbouring crease sites share a Voronoi edge and
//! the output edge between them runs along the crease. The sites still form
//! an r-net (a candidate becomes a site only where no site is within r), so
//! the output's size for a radius barely changes.

use glam::DVec3;
use vitrine_geodesic::{Surface, NONE};

/// Dihedral angle (between face normals) from which an edge is sharp. Scans'
/// noise stays far below it at their own resolution; machined and carved
/// edges are at 60–90°.
pub const SHARP_DEGREES: f64 = 60.0;

/// Each vertex's rank in the cover: [`CORNER`], [`CREASE`] or [`SMOOTH`].
/// Only creases at least `min_length` long count (sharp edges joined end to
/// end): a scan's noise makes short sharp runs that are no feature, and a
/// site forced onto each would pull the cover off its even spread. Faces with a vertex at or past `first_cone` (the
/// cones that close holes) do not count: a hole's border is not a crease.
pub(super) fn crease_ranks(
    surface: &Surface,
    first_cone: u32,
    degrees: f64,
    min_length: f64,
) -> Vec<u8> {
    let cos_limit = degrees.to_radians().cos();
    let triangles = surface.triangles();
    let real = |f: u32| triangles[f as usize].iter().all(|&v| v < first_cone);
    let normal = |f: u32| {
        let p = triangles[f as usize].map(|v| surface.position(v));
        (p[1] - p[0]).cross(p[2] - p[0]).normalize_or_zero()
    };
    let mut edges: Vec<[u32; 2]> = Vec::new();
    for f in 0..triangles.len() as u32 {
        if !real(f) {
            continue;
        }
        let nf: DVec3 = normal(f);
        for k in 0..3 {
            let g = surface.across(f, k);
            // Each edge once, from its face of lower index.
            if g == NONE || g < f || !real(g) {
                continue;
            }
            let ng = normal(g);
            if nf == DVec3::ZERO || ng == DVec3::ZERO || nf.dot(ng) >= cos_limit {
                continue;
            }
            let t = triangles[f as usize];
            edges.push([t[k], t[(k + 1) % 3]]);
        }
    }
    // Creases: sharp edges joined at their ends (union–find), with lengths.
    let mut parent: Vec<u32> = (0..surface.vertex_count() as u32).collect();
    fn root(parent: &mut [u32], mut v: u32) -> u32 {
        while parent[v as usize] != v {
            parent[v as usize] = parent[parent[v as usize] as usize];
            v = parent[v as usize];
        }
        v
    }
    for &[a, b] in &edges {
        let (ra, rb) = (root(&mut parent, a), root(&mut parent, b));
        parent[ra.max(rb) as usize] = ra.min(rb);
    }
    let mut length = vec![0.0f64; surface.vertex_count()];
    for &[a, b] in &edges {
        let r = root(&mut parent, a);
        length[r as usize] += surface.position(a).distance(surface.position(b));
    }
    let mut sharp = vec![0u32; surface.vertex_count()];
    for &[a, b] in &edges {
        if length[root(&mut parent, a) as usize] >= min_length {
            sharp[a as usize] += 1;
            sharp[b as usize] += 1;
        }
    }
    sharp
        .iter()
        .map(|&edges| match edges {
            0 => SMOOTH,
            2 => CREASE,
            _ => CORNER,
        })
        .collect()
}

/// Where one sharp edge ends or three or more meet.
pub(super) const CORNER: u8 = 0;
/// On exactly two sharp edges.
pub(super) const CREASE: u8 = 1;
/// On no sharp edge.
pub(super) const SMOOTH: u8 = 2;

#[cfg(test)]
mod tests {
    use super::*;
    use vitrine_samples::{icosphere, plate_with_tunnels};

    #[test]
    fn a_box_plate_has_corners_and_creases_a_sphere_none() {
        let plate = plate_with_tunnels(1, 2);
        let surface = Surface::new(&plate).unwrap();
        let n = surface.vertex_count() as u32;
        let ranks = crease_ranks(&surface, n, SHARP_DEGREES, 0.5);
        // The outer box's 8 corners are corners; its edges' other vertices creases.
        // The plate spans [0, 3] × [0, 3] × [0, 1] (voxels of side 1).
        let is_box_corner = |v: u32| {
            let p = surface.position(v);
            [(p.x, 3.0), (p.y, 3.0), (p.z, 1.0)]
                .iter()
                .all(|&(c, hi)| c == 0.0 || c == hi)
        };
        for v in 0..n {
            if is_box_corner(v) {
                assert_eq!(ranks[v as usize], CORNER, "vertex {v}");
            }
            let p = surface.position(v);
            let on_box_edge = [(p.x, 3.0), (p.y, 3.0), (p.z, 1.0)]
                .iter()
                .filter(|&&(c, hi)| c == 0.0 || c == hi)
                .count()
                == 2;
            if on_box_edge {
                assert_ne!(ranks[v as usize], SMOOTH, "vertex {v} at {p}");
            }
        }
        // The middle of the top face is smooth.
        let middle = (0..n)
            .find(|&v| surface.position(v) == DVec3::new(0.5, 0.5, 1.0))
            .unwrap();
        assert_eq!(ranks[middle as usize], SMOOTH);
        let sphere = icosphere(3);
        let round = Surface::new(&sphere).unwrap();
        let ranks = crease_ranks(&round, round.vertex_count() as u32, SHARP_DEGREES, 0.0);
        assert!(ranks.iter().all(|&r| r == SMOOTH));
        // A crease shorter than asked for is none.
        let ranks = crease_ranks(&surface, n, SHARP_DEGREES, 1000.0);
        assert!(ranks.iter().all(|&r| r == SMOOTH));
    }
}
