//! The checks made before every merge, which the seed leaves out (SEEDS.md
//! 004, "no manifold/flip tests"): the link condition keeps the surface a
//! 2-manifold of the same topology, and flip rejection keeps it from
//! folding over itself or growing slivers.

use glam::DVec3;

use super::working::{Merge, WorkingMesh};

/// No surviving face may turn by more than this (cosine of 90°, the issue's
/// bound): a face turned further has flipped.
const MIN_TURN_COSINE: f64 = 0.0;

/// Nor may it face more than 60° away from the input's orientation over
/// the patches its corners stand for. Per-merge turns add up, and a
/// survivor's patch can span a crease, so the margin is wide: at 80° a
/// plate with tunnels decimated to 10 % grew a face turned past 90° from
/// the input around it (tests/simplifier.rs).
const MIN_INPUT_COSINE: f64 = 0.5;

/// Twice the area over the longest edge squared, below which a face counts
/// as degenerate (an equilateral triangle has √3/2 ≈ 0.87).
const MIN_SHAPE: f64 = 1e-3;

/// Reusable buffers, so that checking a merge allocates nothing.
#[derive(Default)]
pub(crate) struct Scratch {
    keep: Vec<u32>,
    gone: Vec<u32>,
    star: Vec<StarFace>,
}

/// The link condition and flip rejection together.
pub(crate) fn allows(mesh: &WorkingMesh, merge: &Merge, scratch: &mut Scratch) -> bool {
    link_condition(mesh, merge.keep, merge.gone, scratch) && keeps_orientation(mesh, merge, scratch)
}

/// Dey et al.'s link condition for the edge (a, b), with `b` off the border:
/// Lk(a) ∩ Lk(b) = Lk(ab). The shared neighbours must be exactly the two
/// corners opposite the edge (else a face or edge would double), and the
/// edge between those two must not be in both links (a tetrahedron, which
/// would collapse into two coincident faces).
pub(crate) fn link_condition(mesh: &WorkingMesh, a: u32, b: u32, scratch: &mut Scratch) -> bool {
    let mut opposite = [u32::MAX; 2];
    let mut edge_faces = 0;
    for &f in &mesh.faces_of[b as usize] {
        let t = mesh.triangles[f as usize];
        if t.contains(&a) {
            if edge_faces == 2 {
                return false;
            }
            opposite[edge_faces] = t.iter().copied().find(|&v| v != a && v != b).unwrap_or(a);
            edge_faces += 1;
        }
    }
    if edge_faces != 2 {
        return false;
    }
    mesh.neighbours(a, &mut scratch.keep);
    mesh.neighbours(b, &mut scratch.gone);
    let shared = scratch
        .gone
        .iter()
        .filter(|v| scratch.keep.binary_search(v).is_ok())
        .count();
    let [c, d] = opposite;
    shared == 2 && !(mesh.has_face(a, c, d) && mesh.has_face(b, c, d))
}

/// A face around the survivor after the merge: its slot, its corners and
/// unit normals before and after.
struct StarFace {
    face: u32,
    before: [u32; 3],
    after: [u32; 3],
    was: DVec3,
    is: DVec3,
}

/// Every face that survives the merge keeps its side (turns by at most
/// 90°, and still faces within 60° of the input over its corners) and its
/// shape (does not become a sliver, unless it was one); and no two faces
/// sharing an edge around the survivor fold past 90° unless they already
/// did (the seed's "pyramids" are such folds).
pub(crate) fn keeps_orientation(mesh: &WorkingMesh, merge: &Merge, scratch: &mut Scratch) -> bool {
    let moved = mesh.positions[merge.keep as usize] != merge.to;
    let to = DVec3::from(merge.to.map(f64::from));
    let at = |v: u32| if v == merge.keep { to } else { mesh.point(v) };
    scratch.star.clear();
    for (v, changes) in [(merge.gone, true), (merge.keep, moved)] {
        for &f in &mesh.faces_of[v as usize] {
            let before = mesh.triangles[f as usize];
            if before.contains(&merge.keep) && before.contains(&merge.gone) {
                continue;
            }
            let after = before.map(|w| if w == merge.gone { merge.keep } else { w });
            let (p0, p1) = (before.map(|w| mesh.point(w)), after.map(at));
            let (n0, n1) = (normal(&p0), normal(&p1));
            if changes {
                let reference: DVec3 = after
                    .iter()
                    .map(|&w| mesh.reference[w as usize].normalize_or_zero())
                    .sum();
                let keeps = n0.dot(n1) > MIN_TURN_COSINE * n0.length() * n1.length()
                    && n1.dot(reference) > MIN_INPUT_COSINE * n1.length() * reference.length()
                    && (shape(&p1) >= MIN_SHAPE || shape(&p1) >= shape(&p0));
                if !keeps {
                    return false;
                }
            }
            scratch.star.push(StarFace {
                face: f,
                before,
                after,
                was: n0.normalize_or_zero(),
                is: n1.normalize_or_zero(),
            });
        }
    }
    !folds_inside(&scratch.star) && !folds_outside(mesh, merge.keep, &scratch.star)
}

/// Whether two faces of the new star that share an edge fold past 90°,
/// further than they did before (1 when they were not neighbours).
fn folds_inside(star: &[StarFace]) -> bool {
    star.iter().enumerate().any(|(i, f)| {
        star[i + 1..].iter().any(|g| {
            let after = f.is.dot(g.is);
            after < 0.0
                && shares_edge(&f.after, &g.after)
                && after
                    < if shares_edge(&f.before, &g.before) {
                        f.was.dot(g.was)
                    } else {
                        1.0
                    }
        })
    })
}

/// Whether a star face folds past 90° against the face across its edge
/// away from the survivor, further than it did before.
fn folds_outside(mesh: &WorkingMesh, keep: u32, star: &[StarFace]) -> bool {
    star.iter().any(|s| {
        let k = s.after.iter().position(|&w| w == keep).unwrap_or(0);
        let (x, y) = (s.after[(k + 1) % 3], s.after[(k + 2) % 3]);
        mesh.faces_of[x as usize].iter().any(|&g| {
            let t = mesh.triangles[g as usize];
            if g == s.face || !t.contains(&y) || t.contains(&keep) {
                return false;
            }
            let n = normal(&t.map(|w| mesh.point(w))).normalize_or_zero();
            let after = s.is.dot(n);
            after < 0.0 && after < s.was.dot(n)
        })
    })
}

fn shares_edge(a: &[u32; 3], b: &[u32; 3]) -> bool {
    a.iter().filter(|v| b.contains(v)).count() == 2
}

/// Twice the area times the unit normal.
pub(crate) fn normal(p: &[DVec3; 3]) -> DVec3 {
    (p[1] - p[0]).cross(p[2] - p[0])
}

/// Twice the area over the longest edge squared: 0 for a degenerate face.
fn shape(p: &[DVec3; 3]) -> f64 {
    let longest = (0..3)
        .map(|k| p[k].distance_squared(p[(k + 1) % 3]))
        .fold(0.0, f64::max);
    if longest > 0.0 {
        normal(p).length() / longest
    } else {
        0.0
    }
}
