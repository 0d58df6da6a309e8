//! The base mesh: the coarsest level, sent whole.
//!
//! It is a few percent of the vertices at most, so a simple scheme does:
//! vertices are numbered by first appearance in the face list, a face corner
//! is coded as its distance below the next new vertex (0 = new vertex), and
//! positions and colours as deltas from the previous vertex.

use crate::entropy::{IntModel, RangeDecoder, RangeEncoder};
use crate::halfedge::{face, next, prev, Connectivity, NONE};
use crate::{Error, Result};

pub(crate) struct BaseMesh {
    pub positions: Vec<[i32; 3]>,
    pub colours: Option<Vec<[u8; 3]>>,
    pub triangles: Vec<[u32; 3]>,
}

/// The live faces of `conn` in the order they are reached by walking across
/// edges from face to face (depth first, one walk per connected component),
/// each rotated so that it starts with the edge it was entered by. Numbered
/// by first appearance in this order, a face's first two corners are
/// vertices of a face just before it and its third is new or close by, so
/// corner codes stay small; consecutive new vertices are neighbours, so
/// position deltas do too. Any face order decodes to the same
/// mesh: this only makes the base cheaper (1 % of the whole stream on igea,
/// 0.4–0.8 % on smaller scans, against the slot order; a breadth-first walk
/// did about half as well, and worse on one scan).
pub(crate) fn face_walk_order(conn: &Connectivity) -> Vec<[u32; 3]> {
    let slots = conn.face_count_slots();
    let mut visited = vec![false; slots];
    let mut order = Vec::with_capacity(slots);
    let mut stack = Vec::new();
    for f in 0..slots as u32 {
        if !conn.face_alive(f) || visited[f as usize] {
            continue;
        }
        visited[f as usize] = true;
        stack.push(3 * f);
        while let Some(h) = stack.pop() {
            // `h` is the half-edge the face was entered by: its corners from `h` on.
            let (a, b, c) = (h, next(h), prev(h));
            order.push([a, b, c].map(|h| conn.origin[h as usize]));
            // The entry edge's twin is the face this one was entered from,
            // except for a component's first face.
            for g in [a, c, b] {
                let t = conn.twin[g as usize];
                if t != NONE && !std::mem::replace(&mut visited[face(t) as usize], true) {
                    stack.push(t);
                }
            }
        }
    }
    order
}

/// Returns the vertex order that makes `triangles` first-appearance
/// numbered: `order[new] = old`.
pub(crate) fn first_appearance_order(vertex_count: usize, triangles: &[[u32; 3]]) -> Vec<u32> {
    let mut seen = vec![false; vertex_count];
    let mut order = Vec::new();
    for t in triangles {
        for &v in t {
            if !std::mem::replace(&mut seen[v as usize], true) {
                order.push(v);
            }
        }
    }
    order
}

/// Encodes a first-appearance numbered base mesh.
pub(crate) fn encode(base: &BaseMesh) -> Vec<u8> {
    let mut enc = RangeEncoder::new();
    let mut corner = IntModel::new();
    let mut next_new = 0u32;
    for t in &base.triangles {
        for &v in t {
            debug_assert!(v <= next_new, "base mesh must be first-appearance numbered");
            enc.encode_int(&mut corner, (next_new - v) as i32);
            if v == next_new {
                next_new += 1;
            }
        }
    }
    let mut axis = [IntModel::new(), IntModel::new(), IntModel::new()];
    let mut prev = [0i32; 3];
    for p in &base.positions {
        for k in 0..3 {
            enc.encode_int(&mut axis[k], p[k] - prev[k]);
        }
        prev = *p;
    }
    if let Some(colours) = &base.colours {
        let mut channel = [IntModel::new(), IntModel::new(), IntModel::new()];
        let mut prev = [0u8; 3];
        for c in colours {
            for k in 0..3 {
                enc.encode_int(&mut channel[k], c[k].wrapping_sub(prev[k]) as i8 as i32);
            }
            prev = *c;
        }
    }
    enc.finish()
}

pub(crate) fn decode(
    payload: &[u8],
    vertices: u32,
    faces: u32,
    has_colour: bool,
    max_coordinate: i32,
) -> Result<BaseMesh> {
    let mut dec = RangeDecoder::new(payload);
    let mut corner = IntModel::new();
    let mut next_new = 0u32;
    // Counts were checked against the Limits and the level table by the
    // caller, but the Limits may be generous and the bytes few: reserve no
    // more than one face per payload byte up front (growth is then paid for
    // by decoded faces), and stop once the payload has run out rather than
    // decoding billions of faces from the zeros past its end.
    let mut triangles = Vec::with_capacity((faces as usize).min(payload.len()));
    for f in 0..faces {
        if f % 256 == 0 {
            dec.check_overrun()?;
        }
        let mut t = [0u32; 3];
        for v in &mut t {
            let back = dec.decode_int(&mut corner);
            if back < 0 || back as u32 > next_new {
                return Err(Error::stream(
                    "base mesh face refers to a vertex not yet seen",
                ));
            }
            *v = next_new - back as u32;
            if back == 0 {
                next_new += 1;
                if next_new > vertices {
                    return Err(Error::stream("base mesh uses more vertices than declared"));
                }
            }
        }
        triangles.push(t);
    }
    if next_new != vertices {
        return Err(Error::stream("base mesh declares vertices no face uses"));
    }
    let mut axis = [IntModel::new(), IntModel::new(), IntModel::new()];
    let mut prev = [0i32; 3];
    let mut positions = Vec::with_capacity(vertices as usize);
    for v in 0..vertices {
        if v % 256 == 0 {
            dec.check_overrun()?;
        }
        let mut p = [0i32; 3];
        for k in 0..3 {
            p[k] = prev[k].wrapping_add(dec.decode_int(&mut axis[k]));
            if !(0..=max_coordinate).contains(&p[k]) {
                return Err(Error::stream(
                    "base mesh position outside the quantization range",
                ));
            }
        }
        positions.push(p);
        prev = p;
    }
    let colours = if has_colour {
        let mut channel = [IntModel::new(), IntModel::new(), IntModel::new()];
        let mut prev = [0u8; 3];
        let mut colours = Vec::with_capacity(vertices as usize);
        for _ in 0..vertices {
            let c: [u8; 3] = std::array::from_fn(|k| {
                prev[k].wrapping_add(dec.decode_int(&mut channel[k]) as u8)
            });
            colours.push(c);
            prev = c;
        }
        Some(colours)
    } else {
        None
    };
    dec.check_overrun()?;
    Ok(BaseMesh {
        positions,
        colours,
        triangles,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::halfedge::connectivity;
    use crate::samples::{icosphere, torus};
    use std::collections::HashSet;

    /// A face as its rotation starting at its smallest vertex (orientation kept).
    fn canonical(t: [u32; 3]) -> [u32; 3] {
        let k = (0..3).min_by_key(|&k| t[k]).unwrap();
        [t[k], t[(k + 1) % 3], t[(k + 2) % 3]]
    }

    #[test]
    fn face_walk_keeps_every_face_and_enters_each_by_a_known_edge() {
        // Two components: an icosphere and a torus beside it.
        let mut mesh = icosphere(2);
        let ring = torus(12, 6, 1.0, 0.3);
        let offset = mesh.positions.len() as u32;
        mesh.positions.extend(&ring.positions);
        mesh.triangles
            .extend(ring.triangles.iter().map(|t| t.map(|v| v + offset)));
        let conn = connectivity(&mesh).unwrap();
        let walk = face_walk_order(&conn);
        let expected: HashSet<_> = mesh.triangles.iter().map(|&t| canonical(t)).collect();
        let got: HashSet<_> = walk.iter().map(|&t| canonical(t)).collect();
        assert_eq!(walk.len(), mesh.triangles.len());
        assert_eq!(got, expected, "same faces, same orientation");
        // Every face but each component's first starts with an edge (b, a)
        // of a face written before it (as a → b): its first two corners are
        // already numbered.
        let mut edges = HashSet::new();
        let mut starts = 0;
        for t in &walk {
            if !edges.contains(&(t[1], t[0])) {
                starts += 1;
            }
            for k in 0..3 {
                edges.insert((t[k], t[(k + 1) % 3]));
            }
        }
        assert_eq!(starts, 2, "one entry without a known edge per component");
    }
}
