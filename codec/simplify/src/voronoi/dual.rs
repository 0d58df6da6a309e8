//! The dual of the diagram (seed 001 §3.3.1, Alg. 6): a face whose three
//! corners lie in three cells ("characteristic") becomes the output face
//! over those cells' sites, in the same corner order, so the output keeps
//! the input's orientation. Faces with one or two labels vanish (a cell's
//! inside, a Voronoi edge). Faces on a cone's site are dropped: the hole
//! stays a hole. A repeated triple is kept once (the closed-ball check
//! already refuses those; this keeps the output sound regardless).

use std::collections::HashSet;

use vitrine_geodesic::Surface;

/// Output faces as input vertex indices, in input face order, and each
/// one's cells (site labels).
pub(super) fn dual_faces(
    surface: &Surface,
    labels: &[u32],
    site_vertex: &[u32],
    is_cone: impl Fn(u32) -> bool,
) -> (Vec<[u32; 3]>, Vec<[u32; 3]>) {
    let mut seen = HashSet::new();
    let mut faces = Vec::new();
    let mut cells = Vec::new();
    for t in surface.triangles() {
        let l = t.map(|v| labels[v as usize]);
        if l[0] == l[1] || l[1] == l[2] || l[0] == l[2] {
            continue;
        }
        let face = l.map(|s| site_vertex[s as usize]);
        if face.iter().any(|&v| is_cone(v)) {
            continue;
        }
        let mut key = face;
        key.sort_unstable();
        if seen.insert(key) {
            faces.push(face);
            cells.push(l);
        }
    }
    (faces, cells)
}
