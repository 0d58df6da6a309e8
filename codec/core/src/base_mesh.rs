//! The base mesh: the coarsest level, sent whole.
//!
//! Its faces are coded in the order of a depth-first walk across edges
//! ([`face_walk`]), each entered by an edge of a face before it. The decoder
//! keeps the walk's stack of edges to enter faces by, so for each face it
//! already knows two corners and the vertex opposite them across the entry
//! edge: the stream gives the third corner (new, or how far back among the
//! vertices seen) and which of the face's other edges lead on to faces not
//! reached yet (pushed on the stack); a new vertex's position is predicted
//! by the parallelogram on the entry edge (Touma–Gotsman), its colour by the
//! entry edge's mean. Only a connected component's first face is coded
//! corner by corner. A hand-written scheme: no crate codes a mesh's
//! connectivity, and Edgebreaker-style coders are built around exactly this
//! walk.

use crate::entropy::{BitModel, IntModel, RangeDecoder, RangeEncoder};
use crate::halfedge::{face, next, prev, Connectivity, NONE};
use crate::{Error, Result};

pub(crate) struct BaseMesh {
    pub positions: Vec<[i32; 3]>,
    pub colours: Option<Vec<[u8; 3]>>,
    pub triangles: Vec<[u32; 3]>,
}

/// The base mesh's faces in walk order, with what the walk pushed.
pub(crate) struct FaceWalk {
    /// Each face rotated to start with the edge it was entered by.
    pub triangles: Vec<[u32; 3]>,
    /// Per face: which of its edges the walk pushed, as bits of [`EDGES`]
    /// order (the entry edge only ever for a component's first face).
    pub pushed: Vec<u8>,
}

/// A face `[a, b, c]` pushes its edges in this order (the last is walked
/// first): `a → b` (the entry edge), `c → a`, `b → c`.
const EDGES: [usize; 3] = [0, 2, 1];

/// The live faces of `conn` in the order they are reached by walking across
/// edges from face to face (depth first, one walk per connected component),
/// each rotated so that it starts with the edge it was entered by. Numbered
/// by first appearance in this order, consecutive new vertices are
/// neighbours and a face's entry edge is known when it is reached.
pub(crate) fn face_walk(conn: &Connectivity) -> FaceWalk {
    let slots = conn.face_count_slots();
    let mut visited = vec![false; slots];
    let mut walk = FaceWalk {
        triangles: Vec::with_capacity(slots),
        pushed: Vec::with_capacity(slots),
    };
    let mut stack = Vec::new();
    for f in 0..slots as u32 {
        if !conn.face_alive(f) || visited[f as usize] {
            continue;
        }
        visited[f as usize] = true;
        stack.push(3 * f);
        while let Some(h) = stack.pop() {
            // `h` is the half-edge the face was entered by: its corners from `h` on.
            let corners = [h, next(h), prev(h)];
            walk.triangles
                .push(corners.map(|h| conn.origin[h as usize]));
            let mut pushed = 0u8;
            for (bit, &k) in EDGES.iter().enumerate() {
                let t = conn.twin[corners[k] as usize];
                if t != NONE && !std::mem::replace(&mut visited[face(t) as usize], true) {
                    stack.push(t);
                    pushed |= 1 << bit;
                }
            }
            walk.pushed.push(pushed);
        }
    }
    walk
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

/// The base payload's adaptive models (fresh for every stream).
struct Models {
    /// A component's first face: each corner, `next_new − index`.
    first_corner: IntModel,
    /// Any other face: its third corner, `next_new − index` (0: new).
    third: IntModel,
    /// Whether an edge was pushed: by edge (entry, `c → a`, `b → c`) and
    /// whether the face's third corner is new.
    pushed: [[BitModel; 2]; 3],
    /// A component's first vertices: difference from the previous vertex.
    delta: [IntModel; 3],
    /// Other new vertices: difference from the parallelogram prediction.
    parallelogram: [IntModel; 3],
    colour_delta: [IntModel; 3],
    colour_mean: [IntModel; 3],
}

impl Models {
    fn new() -> Self {
        Models {
            first_corner: IntModel::new(),
            third: IntModel::new(),
            pushed: [[BitModel::new(); 2]; 3],
            delta: std::array::from_fn(|_| IntModel::new()),
            parallelogram: std::array::from_fn(|_| IntModel::new()),
            colour_delta: std::array::from_fn(|_| IntModel::new()),
            colour_mean: std::array::from_fn(|_| IntModel::new()),
        }
    }

    /// The models of a new vertex's position residual, by what predicts it.
    fn position(&mut self, origin: Origin) -> &mut [IntModel; 3] {
        match origin {
            Origin::Previous => &mut self.delta,
            Origin::Across { .. } => &mut self.parallelogram,
        }
    }

    fn colour(&mut self, origin: Origin) -> &mut [IntModel; 3] {
        match origin {
            Origin::Previous => &mut self.colour_delta,
            Origin::Across { .. } => &mut self.colour_mean,
        }
    }
}

/// What a new vertex is predicted from: the previous vertex (a component's
/// first face) or the face it enters across (entry edge `p → q` reversed,
/// `o` opposite).
#[derive(Clone, Copy)]
enum Origin {
    Previous,
    Across { p: u32, q: u32, o: u32 },
}

fn predict_position(origin: Origin, positions: &[[i32; 3]], max: i32) -> [i32; 3] {
    match origin {
        Origin::Previous => positions.last().copied().unwrap_or([0; 3]),
        Origin::Across { p, q, o } => {
            let [p, q, o] = [p, q, o].map(|v| positions[v as usize]);
            std::array::from_fn(|k| {
                (p[k] as i64 + q[k] as i64 - o[k] as i64).clamp(0, max as i64) as i32
            })
        }
    }
}

fn predict_colour(origin: Origin, colours: &[[u8; 3]]) -> [u8; 3] {
    match origin {
        Origin::Previous => colours.last().copied().unwrap_or([0; 3]),
        Origin::Across { p, q, .. } => {
            let (p, q) = (colours[p as usize], colours[q as usize]);
            std::array::from_fn(|k| (p[k] as u16 + q[k] as u16).div_ceil(2) as u8)
        }
    }
}

/// Encodes a base mesh whose triangles are a [`face_walk`]'s (`pushed`
/// its), numbered by first appearance.
pub(crate) fn encode(base: &BaseMesh, pushed: &[u8], max_coordinate: i32) -> Vec<u8> {
    let mut enc = RangeEncoder::new();
    let mut m = Models::new();
    let mut next_new = 0u32;
    // Vertices are numbered by first appearance: those seen so far are a
    // prefix of `base`'s, which is what the decoder predicts from.
    let add_vertex = |v: u32, origin: Origin, m: &mut Models, enc: &mut RangeEncoder| {
        let seen = v as usize;
        let predicted = predict_position(origin, &base.positions[..seen], max_coordinate);
        let p = base.positions[seen];
        let models = m.position(origin);
        for k in 0..3 {
            enc.encode_int(&mut models[k], p[k] - predicted[k]);
        }
        if let Some(colours) = &base.colours {
            let predicted = predict_colour(origin, &colours[..seen]);
            let c = colours[seen];
            let models = m.colour(origin);
            for k in 0..3 {
                enc.encode_int(&mut models[k], c[k].wrapping_sub(predicted[k]) as i8 as i32);
            }
        }
    };
    let mut stack: Vec<[u32; 3]> = Vec::new();
    for (t, &bits) in base.triangles.iter().zip(pushed) {
        let seen_before = next_new;
        // The stack is empty exactly where a component starts.
        let first = match stack.pop() {
            Some([p, q, o]) => {
                debug_assert_eq!([t[0], t[1]], [p, q], "faces start with their entry edge");
                let x = t[2];
                enc.encode_uint(&mut m.third, next_new - x);
                if x == next_new {
                    next_new += 1;
                    add_vertex(x, Origin::Across { p, q, o }, &mut m, &mut enc);
                }
                false
            }
            None => {
                for &v in t {
                    debug_assert!(v <= next_new, "base mesh must be first-appearance numbered");
                    enc.encode_uint(&mut m.first_corner, next_new - v);
                    if v == next_new {
                        next_new += 1;
                        add_vertex(v, Origin::Previous, &mut m, &mut enc);
                    }
                }
                true
            }
        };
        // Only the third corner can be new, but for a component's first face.
        let new_third = usize::from(first || next_new > seen_before);
        for (bit, entry) in edge_entries(*t).into_iter().enumerate() {
            if bit == 0 && !first {
                continue;
            }
            let push = bits & (1 << bit) != 0;
            enc.encode_bit(&mut m.pushed[bit][new_third], push);
            if push {
                stack.push(entry);
            }
        }
    }
    enc.finish()
}

/// The stack entries face `[a, b, c]` pushes, in [`EDGES`] order: the
/// neighbour across each edge starts with that edge reversed, and the
/// third entry is the vertex opposite it here.
fn edge_entries([a, b, c]: [u32; 3]) -> [[u32; 3]; 3] {
    [[b, a, c], [a, c, b], [c, b, a]]
}

pub(crate) fn decode(
    payload: &[u8],
    vertices: u32,
    faces: u32,
    has_colour: bool,
    max_coordinate: i32,
) -> Result<BaseMesh> {
    let mut dec = RangeDecoder::new(payload);
    let mut m = Models::new();
    let mut next_new = 0u32;
    // Counts were checked against the Limits and the level table by the
    // caller, but the Limits may be generous and the bytes few: reserve no
    // more than one face per payload byte up front (growth is then paid for
    // by decoded faces), and stop once the payload has run out rather than
    // decoding billions of faces from the zeros past its end.
    let reserve = (faces as usize).min(payload.len());
    let mut triangles = Vec::with_capacity(reserve);
    let mut positions: Vec<[i32; 3]> = Vec::with_capacity((vertices as usize).min(reserve));
    let mut colours: Vec<[u8; 3]> = Vec::new();
    let mut stack: Vec<[u32; 3]> = Vec::new();
    let new_vertex = |origin: Origin,
                      dec: &mut RangeDecoder,
                      m: &mut Models,
                      positions: &mut Vec<[i32; 3]>,
                      colours: &mut Vec<[u8; 3]>|
     -> Result<()> {
        if positions.len() as u32 >= vertices {
            return Err(Error::stream("base mesh uses more vertices than declared"));
        }
        let predicted = predict_position(origin, positions, max_coordinate);
        let models = m.position(origin);
        let mut p = [0i32; 3];
        for k in 0..3 {
            p[k] = predicted[k].wrapping_add(dec.decode_int(&mut models[k]));
            if !(0..=max_coordinate).contains(&p[k]) {
                return Err(Error::stream(
                    "base mesh position outside the quantization range",
                ));
            }
        }
        positions.push(p);
        if has_colour {
            let predicted = predict_colour(origin, colours);
            let models = m.colour(origin);
            colours.push(std::array::from_fn(|k| {
                predicted[k].wrapping_add(dec.decode_int(&mut models[k]) as u8)
            }));
        }
        Ok(())
    };
    for f in 0..faces {
        if f % 256 == 0 {
            dec.check_overrun()?;
        }
        let first = stack.is_empty();
        let seen_before = next_new;
        let t = if let Some([p, q, o]) = stack.pop() {
            let back = dec.decode_uint(&mut m.third);
            if back > next_new {
                return Err(Error::stream(
                    "base mesh face refers to a vertex not yet seen",
                ));
            }
            let x = next_new - back;
            if back == 0 {
                next_new += 1;
                new_vertex(
                    Origin::Across { p, q, o },
                    &mut dec,
                    &mut m,
                    &mut positions,
                    &mut colours,
                )?;
            }
            [p, q, x]
        } else {
            let mut t = [0u32; 3];
            for v in &mut t {
                let back = dec.decode_uint(&mut m.first_corner);
                if back > next_new {
                    return Err(Error::stream(
                        "base mesh face refers to a vertex not yet seen",
                    ));
                }
                *v = next_new - back;
                if back == 0 {
                    next_new += 1;
                    new_vertex(
                        Origin::Previous,
                        &mut dec,
                        &mut m,
                        &mut positions,
                        &mut colours,
                    )?;
                }
            }
            t
        };
        if t[0] == t[1] || t[1] == t[2] || t[2] == t[0] {
            return Err(Error::stream("base mesh face repeats a vertex"));
        }
        // Only the third corner can be new, but for a component's first face.
        let new_third = usize::from(first || next_new > seen_before);
        for (bit, entry) in edge_entries(t).into_iter().enumerate() {
            if bit == 0 && !first {
                continue;
            }
            if dec.decode_bit(&mut m.pushed[bit][new_third]) {
                stack.push(entry);
            }
        }
        triangles.push(t);
    }
    if next_new != vertices {
        return Err(Error::stream("base mesh declares vertices no face uses"));
    }
    if !stack.is_empty() {
        return Err(Error::stream("base mesh walk leaves edges unvisited"));
    }
    dec.check_overrun()?;
    Ok(BaseMesh {
        positions,
        colours: has_colour.then_some(colours),
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

    /// Two components (an icosphere and a torus beside it), coloured, as
    /// the encoder writes a base: walked, numbered by first appearance.
    fn walked_base() -> (BaseMesh, Vec<u8>) {
        let mut mesh = icosphere(2);
        let ring = torus(12, 6, 1.0, 0.3);
        let offset = mesh.positions.len() as u32;
        mesh.positions
            .extend(ring.positions.iter().map(|p| [p[0] + 3.0, p[1], p[2]]));
        mesh.triangles
            .extend(ring.triangles.iter().map(|t| t.map(|v| v + offset)));
        let walk = face_walk(&connectivity(&mesh).unwrap());
        let order = first_appearance_order(mesh.positions.len(), &walk.triangles);
        let mut new_id = vec![0u32; order.len()];
        for (new, &old) in order.iter().enumerate() {
            new_id[old as usize] = new as u32;
        }
        let quantize = |p: [f32; 3]| p.map(|x| ((x + 2.0) * 500.0).round() as i32);
        let base = BaseMesh {
            positions: order
                .iter()
                .map(|&v| quantize(mesh.positions[v as usize]))
                .collect(),
            colours: Some(
                order
                    .iter()
                    .map(|&v| [(v * 37) as u8, (v * 11) as u8, 200])
                    .collect(),
            ),
            triangles: walk
                .triangles
                .iter()
                .map(|t| t.map(|v| new_id[v as usize]))
                .collect(),
        };
        (base, walk.pushed)
    }

    #[test]
    fn base_round_trips_exactly() {
        let (base, pushed) = walked_base();
        let bytes = encode(&base, &pushed, 4095);
        let n = base.positions.len() as u32;
        let f = base.triangles.len() as u32;
        let back = decode(&bytes, n, f, true, 4095).unwrap();
        assert_eq!(back.triangles, base.triangles);
        assert_eq!(back.positions, base.positions);
        assert_eq!(back.colours, base.colours);
        // The walk carries two corners of every face but each component's
        // first: with positions that cost nothing, a face costs a few bits
        // (version 3's three explicit corners took about 12).
        let flat = BaseMesh {
            positions: vec![[0; 3]; base.positions.len()],
            colours: None,
            triangles: base.triangles.clone(),
        };
        let walked = encode(&flat, &pushed, 4095).len();
        // Version 3: every corner as a signed distance back.
        let mut enc = RangeEncoder::new();
        let mut corner = IntModel::new();
        let mut next_new = 0u32;
        for t in &base.triangles {
            for &v in t {
                enc.encode_int(&mut corner, (next_new - v) as i32);
                next_new += u32::from(v == next_new);
            }
        }
        let explicit = enc.finish().len();
        assert!(
            2 * walked < explicit,
            "{walked} bytes walked, {explicit} explicit"
        );
    }

    #[test]
    fn a_damaged_base_is_an_error() {
        let (base, pushed) = walked_base();
        let bytes = encode(&base, &pushed, 4095);
        let (n, f) = (base.positions.len() as u32, base.triangles.len() as u32);
        // Truncated, or with a counts that the payload does not match.
        assert!(decode(&bytes[..bytes.len() / 2], n, f, true, 4095).is_err());
        assert!(decode(&bytes, n + 1, f, true, 4095).is_err());
        assert!(decode(&bytes, n, f - 1, true, 4095).is_err());
        // Flipped bits anywhere: an error or another mesh, never a panic.
        for i in 0..bytes.len() {
            let mut flipped = bytes.clone();
            flipped[i] ^= 0x5a;
            let _ = decode(&flipped, n, f, true, 4095);
        }
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
        let walk = face_walk(&conn).triangles;
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
