//! The base mesh: the coarsest level, sent whole.
//!
//! It is a few percent of the vertices at most, so a simple scheme does:
//! vertices are numbered by first appearance in the face list, a face corner
//! is coded as its distance below the next new vertex (0 = new vertex), and
//! positions and colours as deltas from the previous vertex.

use crate::entropy::{IntModel, RangeDecoder, RangeEncoder};
use crate::{Error, Result};

pub(crate) struct BaseMesh {
    pub positions: Vec<[i32; 3]>,
    pub colours: Option<Vec<[u8; 3]>>,
    pub triangles: Vec<[u32; 3]>,
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
