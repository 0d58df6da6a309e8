//! Chart-parallel streams (format 5).
//!
//! The encoder cuts the mesh into charts ([`partition`]) and runs the fine
//! layers inside each chart, with the chart's cut edges as borders (AD01
//! never removes a border vertex, so cut vertices stay until the charts have
//! thinned out). What the charts leave is simplified by ordinary global
//! layers down to the base mesh. A decoder applies the base and the global
//! batches as in format 4, then cuts the level they make into the same
//! charts (the labels travel in the first parted batch) and decodes each
//! chart's part of every later batch on its own: on as many threads as it
//! has, and to the same bytes whatever the number.
//!
//! Both sides agree on the charts' vertex numbering through the level where
//! charts begin: its faces in canonical order ([`canonical_faces`]), each
//! chart's vertices in order of first appearance there ([`cut`]).

pub(crate) mod encode;
mod labels;
pub(crate) mod nested;
mod partition;

pub(crate) use labels::{decode_labels, encode_labels};

use crate::halfedge::{face, Connectivity, NONE};
use crate::{Error, Result};

/// At most this many charts: a label is one symbol of a 64-symbol model.
pub const MAX_CHARTS: usize = 64;

/// The corner of a face with the smallest vertex id.
fn smallest_corner(t: [u32; 3]) -> usize {
    if t[0] <= t[1] && t[0] <= t[2] {
        0
    } else if t[1] <= t[2] {
        1
    } else {
        2
    }
}

/// Face `t` starting from corner `i`.
fn rotated(t: [u32; 3], i: usize) -> [u32; 3] {
    [t[i], t[(i + 1) % 3], t[(i + 2) % 3]]
}

/// The order both sides list the faces of the level where charts begin in
/// (FORMAT.md, "canonical order"): each face rotated to its smallest vertex
/// (orientation kept), then sorted. Faces are bucketed by their smallest
/// vertex (ids are dense, so the level is never sorted whole), then each
/// bucket is sorted. Returns each face's rotation (the corner it starts
/// from) and the faces in that order. `triangles` index `vertex_count`
/// vertices (it panics otherwise).
fn canonical_order(triangles: &[[u32; 3]], vertex_count: usize) -> (Vec<u8>, Vec<u32>) {
    let rotation: Vec<u8> = triangles
        .iter()
        .map(|&t| smallest_corner(t) as u8)
        .collect();
    let smallest = |f: usize| triangles[f][rotation[f] as usize] as usize;
    let mut starts = vec![0u32; vertex_count + 1];
    for f in 0..triangles.len() {
        starts[smallest(f) + 1] += 1;
    }
    for v in 0..vertex_count {
        starts[v + 1] += starts[v];
    }
    let mut order = vec![0u32; triangles.len()];
    let mut cursor = starts.clone();
    for f in 0..triangles.len() {
        let slot = &mut cursor[smallest(f)];
        order[*slot as usize] = f as u32;
        *slot += 1;
    }
    drop(cursor);
    for bucket in starts.windows(2) {
        let faces = &mut order[bucket[0] as usize..bucket[1] as usize];
        if faces.len() > 1 {
            faces.sort_unstable_by_key(|&f| {
                rotated(triangles[f as usize], rotation[f as usize] as usize)
            });
        }
    }
    (rotation, order)
}

/// The faces of the level where charts begin in canonical order
/// ([`canonical_order`]), with each face's `tags` entry (its label) carried
/// along. `triangles` index `vertex_count` vertices.
pub(crate) fn canonical_faces(
    triangles: &[[u32; 3]],
    vertex_count: usize,
    tags: &[u32],
) -> (Vec<[u32; 3]>, Vec<u32>) {
    let (rotation, order) = canonical_order(triangles, vertex_count);
    order
        .iter()
        .map(|&f| {
            let f = f as usize;
            (rotated(triangles[f], rotation[f] as usize), tags[f])
        })
        .unzip()
}

/// The level where charts begin, as the decoder holds it, in canonical
/// order: canonical face `i` is half-edges `3i..3i + 3` of `adjacency`.
pub(crate) struct CanonicalLevel {
    pub adjacency: Connectivity,
}

impl CanonicalLevel {
    pub(crate) fn faces(&self) -> &[[u32; 3]] {
        self.adjacency.origin.as_chunks().0
    }
}

/// A level in canonical order, with the adjacency read off the level's own
/// half-edges rather than built from an edge table: the decoder's cut built
/// one for the labels and one per chart, and took about as long as
/// decoding a level of its size.
pub(crate) fn canonical_level(conn: &Connectivity) -> Result<CanonicalLevel> {
    let vertex_count = conn.out.len();
    if conn.origin.iter().any(|&v| v as usize >= vertex_count) {
        return Err(Error::stream("a face names a vertex the level lacks"));
    }
    let triangles: &[[u32; 3]] = conn.origin.as_chunks().0;
    let (rotation, order) = canonical_order(triangles, vertex_count);
    let mut position = vec![0u32; triangles.len()];
    for (i, &f) in order.iter().enumerate() {
        position[f as usize] = i as u32;
    }
    // Canonical half-edge 3i + k is the level's 3f + (k + rotation) mod 3.
    let canonical_half_edge = |h: u32| {
        if h == NONE {
            return NONE;
        }
        let f = face(h) as usize;
        3 * position[f] + (h % 3 + 3 - u32::from(rotation[f])) % 3
    };
    let mut origin = Vec::with_capacity(conn.origin.len());
    let mut twin = Vec::with_capacity(conn.origin.len());
    for &f in &order {
        let r = rotation[f as usize] as u32;
        origin.extend(rotated(triangles[f as usize], r as usize));
        for k in 0..3 {
            twin.push(canonical_half_edge(
                conn.twin[(3 * f + (k + r) % 3) as usize],
            ));
        }
    }
    Ok(CanonicalLevel {
        adjacency: Connectivity::paired(vertex_count, origin, twin),
    })
}

/// One chart cut out of the level where charts begin.
#[derive(Debug, Default, PartialEq)]
pub(crate) struct Cut {
    /// The level's id of each chart vertex, by first appearance.
    pub global: Vec<u32>,
    /// The chart's faces in chart ids, in canonical order.
    pub triangles: Vec<[u32; 3]>,
    /// Where each of them is in the level's canonical order.
    pub faces: Vec<u32>,
}

/// Cuts `faces` (canonical order, ids below `vertex_count`) into `charts`
/// charts by their `labels` (each below `charts`).
pub(crate) fn cut(
    faces: &[[u32; 3]],
    labels: &[u32],
    charts: usize,
    vertex_count: usize,
) -> Vec<Cut> {
    let mut cuts: Vec<Cut> = (0..charts).map(|_| Cut::default()).collect();
    let mut local = vec![NONE; vertex_count];
    // Charts in turn, so `local` serves each and is cleared after it.
    let mut by_chart: Vec<Vec<u32>> = vec![Vec::new(); charts];
    for (f, &label) in labels.iter().enumerate() {
        by_chart[label as usize].push(f as u32);
    }
    for (chart, faces_of) in cuts.iter_mut().zip(by_chart) {
        chart.triangles.reserve(faces_of.len());
        for &f in &faces_of {
            let t = faces[f as usize].map(|v| {
                let slot = &mut local[v as usize];
                if *slot == NONE {
                    *slot = chart.global.len() as u32;
                    chart.global.push(v);
                }
                *slot
            });
            chart.triangles.push(t);
        }
        for &v in &chart.global {
            local[v as usize] = NONE;
        }
        chart.faces = faces_of;
    }
    cuts
}

/// Each chart's vertices (its cut's `global`) and connectivity, read off
/// the level's (`adjacency`, in canonical order, [`canonical_level`]): a
/// chart's half-edges pair as the level's do inside it and are borders
/// along its cut, which is what [`Connectivity::from_triangles`] makes of
/// its faces, without an edge table. The same check of every vertex's fan
/// follows. The cuts' faces become the charts' connectivity (not copied).
pub(crate) fn chart_connectivity(
    cuts: Vec<Cut>,
    labels: &[u32],
    adjacency: &Connectivity,
) -> Result<Vec<(Vec<u32>, Connectivity)>> {
    // Each level face's place in its chart.
    let mut place = vec![0u32; labels.len()];
    for chart in &cuts {
        for (j, &f) in chart.faces.iter().enumerate() {
            place[f as usize] = j as u32;
        }
    }
    cuts.into_iter()
        .enumerate()
        .map(|(c, chart)| {
            let mut twin = Vec::with_capacity(3 * chart.faces.len());
            for &f in &chart.faces {
                for k in 0..3 {
                    let t = adjacency.twin[(3 * f + k) as usize];
                    let inside = t != NONE && labels[face(t) as usize] as usize == c;
                    twin.push(if inside {
                        3 * place[face(t) as usize] + t % 3
                    } else {
                        NONE
                    });
                }
            }
            let origin = chart.triangles.into_flattened();
            let conn = Connectivity::paired(chart.global.len(), origin, twin);
            conn.check_vertex_fans()?;
            Ok((chart.global, conn))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn canonical_keeps_orientation() {
        let canonical = |t: [u32; 3]| canonical_faces(&[t], 10, &[0]).0[0];
        assert_eq!(canonical([5, 2, 9]), [2, 9, 5]);
        assert_eq!(canonical([9, 5, 2]), [2, 9, 5]);
        assert_eq!(canonical([2, 9, 5]), [2, 9, 5]);
    }

    /// A torus of `n × n` quads with scrambled vertex ids, faces in a
    /// scrambled order, each starting from a scrambled corner; with each
    /// face, its quad's row and column.
    fn scrambled_torus(n: u32) -> Vec<([u32; 3], [u32; 2])> {
        let mut state = 0x9e37_79b9_7f4a_7c15_u64;
        let mut random = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let mut ids: Vec<u32> = (0..n * n).collect();
        for i in (1..ids.len()).rev() {
            ids.swap(i, (random() % (i as u64 + 1)) as usize);
        }
        let v = |i: u32, j: u32| ids[((i % n) * n + j % n) as usize];
        let mut faces = Vec::new();
        for i in 0..n {
            for j in 0..n {
                faces.push(([v(i, j), v(i + 1, j), v(i + 1, j + 1)], [i, j]));
                faces.push(([v(i, j), v(i + 1, j + 1), v(i, j + 1)], [i, j]));
            }
        }
        for i in (1..faces.len()).rev() {
            faces.swap(i, (random() % (i as u64 + 1)) as usize);
        }
        faces
            .into_iter()
            .map(|(t, quad)| (rotated(t, (random() % 3) as usize), quad))
            .collect()
    }

    #[test]
    fn a_level_read_off_its_half_edges_is_what_its_faces_would_build() {
        let n = 24;
        let torus = scrambled_torus(n);
        let faces: Vec<[u32; 3]> = torus.iter().map(|&(t, _)| t).collect();
        let vertices = (n * n) as usize;
        let level = Connectivity::from_triangles(vertices, &faces).unwrap();
        let canonical = canonical_level(&level).unwrap();
        let quads: Vec<u32> = torus.iter().map(|&(_, [i, j])| i * n + j).collect();
        let (expected, quads) = canonical_faces(&faces, vertices, &quads);
        assert_eq!(canonical.faces(), &expected[..]);
        // Canonical order itself: each face from its smallest vertex, all
        // sorted (and distinct).
        assert!(expected.iter().all(|t| t[0] < t[1] && t[0] < t[2]));
        assert!(expected.windows(2).all(|w| w[0] < w[1]));
        let built = Connectivity::from_triangles(vertices, &expected).unwrap();
        assert_eq!(canonical.adjacency.twin, built.twin);
        assert_eq!(canonical.adjacency.out, built.out);
        // Charts: the torus's four quarters (discs), then scattered faces
        // whose charts touch themselves at single vertices (not manifolds).
        let quarters: Vec<u32> = quads
            .iter()
            .map(|q| 2 * (q / n / (n / 2)) + q % n / (n / 2))
            .collect();
        let scattered: Vec<u32> = expected.iter().map(|t| t[0] % 3).collect();
        for (labels, charts, manifold) in [(quarters, 4, true), (scattered, 3, false)] {
            let cuts = cut(canonical.faces(), &labels, charts, vertices);
            let built: Vec<_> = cuts
                .iter()
                .map(|c| Connectivity::from_triangles(c.global.len(), &c.triangles))
                .collect();
            let read = chart_connectivity(cuts, &labels, &canonical.adjacency);
            assert_eq!(read.is_ok(), manifold);
            match read {
                Ok(read) => {
                    for ((_, r), b) in read.iter().zip(built) {
                        let b = b.expect("a chart both sides accept");
                        assert_eq!((&r.origin, &r.twin, &r.out), (&b.origin, &b.twin, &b.out));
                    }
                }
                Err(_) => assert!(built.iter().any(Result::is_err)),
            }
        }
    }

    #[test]
    fn cut_numbers_each_chart_by_first_appearance() {
        // Two quads sharing the edge 1–4: chart 0 the left, chart 1 the right.
        let faces = [[0, 1, 4], [0, 4, 3], [1, 2, 5], [1, 5, 4]];
        let (faces, labels) = canonical_faces(&faces, 6, &[0, 0, 1, 1]);
        let cuts = cut(&faces, &labels, 2, 6);
        assert_eq!(cuts[0].global, vec![0, 1, 4, 3]);
        assert_eq!(cuts[0].triangles, vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!(cuts[1].global, vec![1, 2, 5, 4]);
        assert_eq!(cuts[1].triangles, vec![[0, 1, 2], [0, 2, 3]]);
    }
}
