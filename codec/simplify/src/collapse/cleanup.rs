//! The seed's clean-up after each pass (004, Alg. 5), kept as a safety net:
//! with the link condition and flip rejection in front of every merge it
//! should find nothing, and [`Cleanup`] counts say whether it did.

use super::topology::{link_condition, normal, Scratch};
use super::working::{Merge, WorkingMesh};
use super::Cleanup;

/// Spikes, then pyramids, then faces wound against their neighbours.
/// Pyramids are removed only while the mesh is above `target` vertices and
/// only at vertices the feature threshold lets go.
pub(super) fn clean(mesh: &mut WorkingMesh, threshold: f64, target: usize) -> Cleanup {
    let mut scratch = Scratch::default();
    Cleanup {
        duplicates: remove_duplicates(mesh),
        pyramids: flatten_pyramids(mesh, threshold, target, &mut scratch),
        flipped: unflip(mesh),
    }
}

/// Two faces on the same three vertices ("spikes"): both go.
fn remove_duplicates(mesh: &mut WorkingMesh) -> usize {
    let mut keys: Vec<([u32; 3], u32)> = (0..mesh.triangles.len())
        .filter(|&f| mesh.face_alive[f])
        .map(|f| {
            let mut key = mesh.triangles[f];
            key.sort_unstable();
            (key, f as u32)
        })
        .collect();
    keys.sort_unstable();
    let mut doomed = Vec::new();
    for run in keys.chunk_by(|a, b| a.0 == b.0).filter(|run| run.len() > 1) {
        doomed.extend(run.iter().map(|&(_, f)| f));
    }
    for &f in &doomed {
        mesh.delete_face(f);
    }
    doomed.len()
}

/// A valence-3 vertex one of whose faces turns more than 90° from another
/// (a "pyramid"): its three faces become the one under it. That is the
/// merge of the vertex into a neighbour, so the link condition applies.
fn flatten_pyramids(
    mesh: &mut WorkingMesh,
    threshold: f64,
    target: usize,
    scratch: &mut Scratch,
) -> usize {
    let mut flattened = 0;
    for v in 0..mesh.positions.len() as u32 {
        if mesh.live_vertices <= target {
            break;
        }
        if mesh.faces_of[v as usize].len() != 3 || !mesh.removable(v, threshold) {
            continue;
        }
        let normals: Vec<_> = mesh.faces_of[v as usize]
            .iter()
            .map(|&f| normal(&mesh.triangles[f as usize].map(|w| mesh.point(w))))
            .collect();
        let spike = (0..3).any(|i| normals[i].dot(normals[(i + 1) % 3]) < 0.0);
        let first = mesh.triangles[mesh.faces_of[v as usize][0] as usize];
        let keep = super::working::after(first, v);
        if spike && link_condition(mesh, keep, v, scratch) {
            mesh.apply(&Merge {
                keep,
                gone: v,
                to: mesh.positions[keep as usize],
                colour: mesh.colour(keep),
            });
            flattened += 1;
        }
    }
    flattened
}

/// A face whose edges run the same way as its neighbours' (more of them
/// than run opposite) is wound the wrong way round: reverse it.
fn unflip(mesh: &mut WorkingMesh) -> usize {
    let mut flipped = 0;
    for f in 0..mesh.triangles.len() {
        if !mesh.face_alive[f] {
            continue;
        }
        let t = mesh.triangles[f];
        let (mut agree, mut disagree) = (0, 0);
        for k in 0..3 {
            let (x, y) = (t[k], t[(k + 1) % 3]);
            for &g in &mesh.faces_of[x as usize] {
                let u = mesh.triangles[g as usize];
                if g as usize == f || !u.contains(&y) {
                    continue;
                }
                if super::working::after(u, x) == y {
                    disagree += 1;
                } else {
                    agree += 1;
                }
            }
        }
        if disagree > agree {
            mesh.triangles[f].swap(1, 2);
            flipped += 1;
        }
    }
    flipped
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::FeatureThreshold;
    use vitrine_codec::IndexedMesh;

    fn working(positions: Vec<[f32; 3]>, triangles: Vec<[u32; 3]>) -> WorkingMesh {
        let mesh = IndexedMesh {
            positions,
            colors: None,
            triangles,
        };
        WorkingMesh::new(&mesh, FeatureThreshold::Degrees(180.0))
            .unwrap()
            .0
    }

    /// Two triangles per square of an `n × n` grid.
    fn grid(n: u32) -> WorkingMesh {
        let id = |i: u32, j: u32| j * (n + 1) + i;
        let positions = (0..=n)
            .flat_map(|j| (0..=n).map(move |i| [i as f32, j as f32, 0.0]))
            .collect();
        let triangles = (0..n)
            .flat_map(|j| (0..n).map(move |i| (i, j)))
            .flat_map(|(i, j)| {
                [
                    [id(i, j), id(i + 1, j), id(i + 1, j + 1)],
                    [id(i, j), id(i + 1, j + 1), id(i, j + 1)],
                ]
            })
            .collect();
        working(positions, triangles)
    }

    #[test]
    fn a_pyramid_becomes_the_face_under_it() {
        // v = 3 pulled out past the edge (1, 2): its face there turns over.
        let positions = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [1.5, 1.5, 0.0],
        ];
        let mut mesh = working(positions, vec![[3, 0, 1], [3, 1, 2], [3, 2, 0]]);
        let found = clean(&mut mesh, std::f64::consts::PI, 0);
        assert_eq!(found.pyramids, 1);
        let (out, _) = mesh.compact();
        assert_eq!(out.triangles, vec![[0, 1, 2]]);
    }

    #[test]
    fn both_of_two_coincident_faces_go() {
        let mut mesh = grid(3);
        let [a, b, c] = mesh.triangles[4];
        let f = mesh.triangles.len() as u32;
        mesh.triangles.push([a, c, b]);
        mesh.face_alive.push(true);
        for v in [a, b, c] {
            mesh.faces_of[v as usize].push(f);
        }
        let found = clean(&mut mesh, 0.0, 0);
        assert_eq!((found.duplicates, found.flipped), (2, 0));
        assert_eq!(mesh.live_faces(), 17);
    }

    #[test]
    fn a_face_wound_against_its_neighbours_is_turned_back() {
        let mut mesh = grid(3);
        let original = mesh.triangles[7];
        mesh.triangles[7].swap(0, 1);
        assert_eq!(clean(&mut mesh, 0.0, 0).flipped, 1);
        let t = mesh.triangles[7];
        let rotations = [
            original,
            [original[1], original[2], original[0]],
            [original[2], original[0], original[1]],
        ];
        assert!(rotations.contains(&t), "{t:?}");
    }
}
