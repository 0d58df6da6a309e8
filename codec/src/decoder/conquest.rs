//! The decoder's mirror of the conquests: the same gate traversal over the
//! coarser mesh, reading one code per gate and re-inserting removed vertices.

use std::collections::VecDeque;

use super::Level;
use crate::entropy::RangeDecoder;
use crate::halfedge::{face, next, prev, NONE};
use crate::patch::{pattern, Pattern, Tag, MAX_VALENCE, NO_TWIN};
use crate::predict::{
    decode_colour, gate_context, predict_colour, umbrellas, PassModels, PatchPrediction,
};
use crate::{Error, Result};

const FREE: u8 = 0;
const CONQUERED: u8 = 1;

#[derive(Clone, Copy, PartialEq, Eq)]
pub(crate) enum PassKind {
    Decimating,
    Cleaning,
}

/// Scratch state reused across passes so a pass allocates nothing per vertex.
#[derive(Default)]
pub(crate) struct Scratch {
    state: Vec<u8>,
    tag: Vec<Tag>,
    face_done: Vec<bool>,
    gates: VecDeque<u32>,
    /// Patches found by the traversal, inserted once geometry is decoded.
    pending: Vec<Region>,
    decoded: Vec<([i32; 3], Option<[u8; 3]>)>,
    umbrellas: Vec<[i32; 4]>,
}

pub(crate) struct PassInput<'a> {
    pub kind: PassKind,
    pub seeds: Vec<[u32; 2]>,
    pub inserted: u32,
    pub connectivity: &'a [u8],
    pub geometry: &'a [u8],
    pub colour: &'a [u8],
}

struct Streams<'a> {
    conn: RangeDecoder<'a>,
    geom: RangeDecoder<'a>,
    colour: RangeDecoder<'a>,
    models: PassModels,
}

impl Level {
    pub(crate) fn undo_pass(&mut self, pass: &PassInput, scratch: &mut Scratch) -> Result<()> {
        let n = self.vertex_count();
        if pass.seeds.is_empty() {
            // A skipped pass (the encoder found nothing worth a traversal).
            return match pass.inserted {
                0 => Ok(()),
                _ => Err(Error::stream("pass without seeds claims inserted vertices")),
            };
        }
        let target = n + pass.inserted as usize;
        scratch.state.clear();
        scratch.state.resize(n, FREE);
        scratch.tag.clear();
        scratch.tag.resize(n, Tag::None);
        scratch.pending.clear();
        scratch.face_done.clear();
        scratch
            .face_done
            .resize(self.conn.face_count_slots(), false);
        let mut s = Streams {
            conn: RangeDecoder::new(pass.connectivity)?,
            geom: RangeDecoder::new(pass.geometry)?,
            colour: RangeDecoder::new(pass.colour)?,
            models: PassModels::new(),
        };
        for &[a, b] in &pass.seeds {
            if a as usize >= n || b as usize >= n {
                return Err(Error::stream(
                    "seed gate names a vertex that does not exist yet",
                ));
            }
            let h = self
                .conn
                .find_half_edge(a, b)
                .ok_or_else(|| Error::stream("seed gate is not an edge of the mesh"))?;
            if scratch.face_done[face(h) as usize] {
                return Err(Error::stream("seed gate lies in an already conquered face"));
            }
            conquer(scratch, a, Tag::Plus);
            conquer(scratch, b, Tag::Minus);
            scratch.gates.push_back(h);
            while let Some(g) = scratch.gates.pop_front() {
                self.process_gate(g, pass.kind, target, scratch, &mut s)?;
            }
        }
        if n + scratch.pending.len() != target {
            return Err(Error::stream(format!(
                "pass inserted {} vertices, its header says {}",
                scratch.pending.len(),
                pass.inserted
            )));
        }
        let mut decoded = std::mem::take(&mut scratch.decoded);
        decoded.clear();
        umbrellas(&self.conn, &self.positions_q, &mut scratch.umbrellas);
        for r in &scratch.pending {
            decoded.push(self.decode_vertex(r, &scratch.umbrellas, &mut s)?);
        }
        for (r, &(position, colour)) in scratch.pending.iter().zip(&decoded) {
            self.insert_vertex(r, position, colour);
        }
        scratch.decoded = decoded;
        s.conn.check_overrun()?;
        s.geom.check_overrun()?;
        s.colour.check_overrun()
    }

    fn process_gate(
        &mut self,
        g: u32,
        kind: PassKind,
        target: usize,
        scratch: &mut Scratch,
        s: &mut Streams,
    ) -> Result<()> {
        let f = face(g);
        if scratch.face_done[f as usize] {
            return Ok(());
        }
        let tag_of =
            |scratch: &Scratch, v: u32| scratch.tag.get(v as usize).copied().unwrap_or(Tag::None);
        let t0 = tag_of(scratch, self.conn.origin[g as usize]);
        let t1 = tag_of(scratch, self.conn.target(g));
        let front = self.conn.origin[prev(g) as usize];
        let ctx = gate_context(t0, t1, tag_of(scratch, front));
        let valence = match kind {
            PassKind::Decimating => match s.conn.decode_symbol(&mut s.models.valence[ctx]) {
                0 => 0,
                sym => sym + 2,
            },
            PassKind::Cleaning => {
                if s.conn.decode_bit(&mut s.models.cleaning[ctx]) {
                    3
                } else {
                    0
                }
            }
        };
        if valence == 0 {
            scratch.face_done[f as usize] = true;
            conquer(scratch, front, Tag::Plus);
            for h in [next(g), prev(g)] {
                let t = self.conn.twin[h as usize];
                if t != NONE {
                    scratch.gates.push_back(t);
                }
            }
            return Ok(());
        }
        if self.vertex_count() + scratch.pending.len() >= target {
            return Err(Error::stream(
                "pass inserts more vertices than its header says",
            ));
        }
        let pat = pattern(valence, as_gate_tag(t0), as_gate_tag(t1));
        let region = self.find_patch(g, pat, scratch)?;
        self.claim_patch(&region, pat, scratch);
        scratch.pending.push(region);
        Ok(())
    }

    /// Walks the `valence − 2` faces of the retriangulated patch from the gate.
    fn find_patch(&self, g: u32, pat: &Pattern, scratch: &Scratch) -> Result<Region> {
        let c = &self.conn;
        let count = pat.triangle_count();
        let mut r = Region {
            valence: pat.valence,
            polygon: [NONE; MAX_VALENCE],
            outer: [NONE; MAX_VALENCE],
            boundary: [NONE; MAX_VALENCE],
            corner0: [NONE; MAX_VALENCE - 2],
        };
        let mut first = g;
        for _ in 0..pat.gate_corner {
            first = prev(first);
        }
        r.corner0[pat.gate_triangle as usize] = first;
        let mut stack = [0u8; MAX_VALENCE - 2];
        stack[0] = pat.gate_triangle;
        let mut stack_len = 1;
        while stack_len > 0 {
            stack_len -= 1;
            let t = stack[stack_len] as usize;
            let mut h = r.corner0[t];
            for k in 0..3 {
                let corner = 3 * t + k;
                let local = pat.corner_vertex(corner);
                let v = c.origin[h as usize];
                if r.polygon[local] == NONE {
                    if r.polygon[..pat.valence].contains(&v) {
                        return Err(Error::stream("patch polygon repeats a vertex"));
                    }
                    r.polygon[local] = v;
                } else if r.polygon[local] != v {
                    return Err(Error::stream("patch faces do not match their pattern"));
                }
                let twin = pat.twin[corner];
                if twin >= NO_TWIN {
                    r.outer[(twin - NO_TWIN) as usize] = c.twin[h as usize];
                    r.boundary[(twin - NO_TWIN) as usize] = h;
                } else {
                    let t2 = twin as usize / 3;
                    if r.corner0[t2] == NONE {
                        let h2 = c.twin[h as usize];
                        if h2 == NONE {
                            return Err(Error::stream("patch crosses a border"));
                        }
                        let f2 = face(h2);
                        if scratch.face_done[f2 as usize]
                            || r.corner0[..count]
                                .iter()
                                .any(|&x| x != NONE && face(x) == f2)
                        {
                            return Err(Error::stream("patch overlaps conquered faces"));
                        }
                        let mut first = h2;
                        for _ in 0..twin % 3 {
                            first = prev(first);
                        }
                        r.corner0[t2] = first;
                        stack[stack_len] = t2 as u8;
                        stack_len += 1;
                    }
                }
                h = next(h);
            }
        }
        Ok(r)
    }

    /// Phase 1 of a patch: conquer its faces and border as the encoder did,
    /// without touching the mesh yet.
    fn claim_patch(&self, r: &Region, pat: &Pattern, scratch: &mut Scratch) {
        let d = r.valence;
        for &h in &r.corner0[..d - 2] {
            scratch.face_done[face(h) as usize] = true;
        }
        for i in 0..d {
            conquer(scratch, r.polygon[i], pat.tags[i]);
        }
        for &o in &r.outer[1..d] {
            if o != NONE {
                scratch.gates.push_back(o);
            }
        }
    }

    /// Phase 2: the removed vertex's position and colour, predicted from the
    /// coarse mesh (nothing inserted yet, exactly what the encoder saw).
    fn decode_vertex(
        &self,
        r: &Region,
        umbrella_of: &[[i32; 4]],
        s: &mut Streams,
    ) -> Result<([i32; 3], Option<[u8; 3]>)> {
        let d = r.valence;
        let mut polygon = [[0i32; 3]; MAX_VALENCE];
        let mut umbrellas = [[0i32; 4]; MAX_VALENCE];
        for i in 0..d {
            polygon[i] = self.positions_q[r.polygon[i] as usize];
            umbrellas[i] = umbrella_of[r.polygon[i] as usize];
        }
        let position = PatchPrediction::with_curvature(&polygon[..d], &umbrellas[..d])
            .decode(self.quantization.max_value(), &mut s.models, &mut s.geom)
            .ok_or_else(|| Error::stream("decoded position outside the quantization range"))?;
        let colour = match &self.colours {
            Some(colours) => {
                let mut border = [[0u8; 3]; MAX_VALENCE];
                for i in 0..d {
                    border[i] = colours[r.polygon[i] as usize];
                }
                Some(decode_colour(
                    predict_colour(&border[..d]),
                    &mut s.models,
                    &mut s.colour,
                ))
            }
            None => None,
        };
        Ok((position, colour))
    }

    /// Phase 3: replace the patch's faces by the fan of the new vertex.
    fn insert_vertex(&mut self, r: &Region, position: [i32; 3], colour: Option<[u8; 3]>) {
        let d = r.valence;
        // Read the outer half-edges now: neighbouring patches inserted since
        // phase 1 have re-linked them.
        let mut outer = [NONE; MAX_VALENCE];
        for (o, &h) in outer.iter_mut().zip(&r.boundary[..d]) {
            *o = self.conn.twin[h as usize];
        }
        let v = self.push_vertex(position, colour);
        // Faces (v, p_i, p_i+1): reuse the patch's d − 2 slots, append two.
        let mut slots = [NONE; MAX_VALENCE];
        for (i, slot) in slots.iter_mut().enumerate().take(d) {
            *slot = if i < d - 2 {
                face(r.corner0[i])
            } else {
                self.conn.append_face()
            };
        }
        for i in 0..d {
            let base = 3 * slots[i];
            let (a, b) = (r.polygon[i], r.polygon[(i + 1) % d]);
            self.conn.origin[base as usize] = v;
            self.conn.origin[base as usize + 1] = a;
            self.conn.origin[base as usize + 2] = b;
            let o = outer[i];
            self.conn.twin[base as usize + 1] = o;
            if o != NONE {
                self.conn.twin[o as usize] = base + 1;
            }
            // v → p_i pairs with p_i → v, the third half-edge of the previous face.
            let prev_face = 3 * slots[(i + d - 1) % d];
            self.conn.twin[base as usize] = prev_face + 2;
            self.conn.twin[prev_face as usize + 2] = base;
            self.conn.out[a as usize] = base + 1;
        }
        self.conn.out[v as usize] = 3 * slots[0];
    }
}

struct Region {
    valence: usize,
    polygon: [u32; MAX_VALENCE],
    outer: [u32; MAX_VALENCE],
    /// The region's own half-edge on each border edge `p_i → p_i+1`.
    boundary: [u32; MAX_VALENCE],
    /// Half-edge at corner 0 of each pattern triangle.
    corner0: [u32; MAX_VALENCE - 2],
}

fn conquer(scratch: &mut Scratch, v: u32, tag: Tag) {
    let i = v as usize;
    if scratch.state[i] == FREE {
        scratch.state[i] = CONQUERED;
    }
    if scratch.tag[i] == Tag::None {
        scratch.tag[i] = tag;
    }
}

/// Gate vertices are always tagged in a well-formed pass; a hostile one
/// must still not panic, so an untagged vertex reads as `+`.
fn as_gate_tag(t: Tag) -> Tag {
    if t == Tag::None {
        Tag::Plus
    } else {
        t
    }
}
