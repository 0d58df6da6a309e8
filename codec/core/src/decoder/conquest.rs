//! The decoder's side of a conquest: the shared gate traversal over the
//! coarser mesh ([`crate::gates`]) with codes read from the stream, then the
//! removed vertices' positions and colours, then their re-insertion.

use super::Level;
use crate::contexts::DECIMATION_SYMBOLS;
use crate::entropy::{BitModel, FrequencyModel, RangeDecoder};
use crate::gates::{Border, GateCodes, PassKind, PatchSink, Region, Traversal};
use crate::halfedge::{face, Connectivity, NONE};
use crate::patch::MAX_VALENCE;
use crate::predict::{
    decode_colour, predict_colour, umbrellas, PassModels, PatchPrediction, PREDICTION_BLOCK,
};
use crate::{Error, Result};

/// Scratch state reused across passes so a pass allocates nothing per vertex.
#[derive(Default)]
pub(crate) struct Scratch {
    pub traversal: Traversal,
    decoded: Vec<([i32; 3], Option<[u8; 3]>)>,
    umbrellas: Vec<[i32; 4]>,
    valences: Vec<u8>,
    predictions: Vec<PatchPrediction>,
    /// Measures where the bits go ([`crate::bits`]); `None` when decoding.
    pub meter: Option<Box<crate::meter::Meter>>,
}

impl Scratch {
    /// Room for a level of `needed` vertices (`target` if the arrays move).
    pub(super) fn make_room(&mut self, needed: usize, target: usize) {
        crate::room::reserve(&mut self.umbrellas, needed, target);
        crate::room::reserve(&mut self.valences, needed, target);
        self.traversal.make_room(needed, target);
    }
}

pub(crate) struct PassInput<'a> {
    pub kind: PassKind,
    pub seeds: Vec<[u32; 2]>,
    pub inserted: u32,
    pub connectivity: &'a [u8],
    pub geometry: &'a [u8],
    pub colour: &'a [u8],
}

/// Gate codes read from the pass's connectivity section.
struct StreamCodes<'a>(RangeDecoder<'a>);

impl GateCodes for StreamCodes<'_> {
    fn decimation(
        &mut self,
        model: &mut FrequencyModel<DECIMATION_SYMBOLS>,
        limit: usize,
    ) -> Result<usize> {
        Ok(self.0.decode_symbol_below(model, limit))
    }

    fn cleaning(&mut self, model: &mut BitModel) -> Result<bool> {
        Ok(self.0.decode_bit(model))
    }
}

struct Streams<'a> {
    geom: RangeDecoder<'a>,
    colour: RangeDecoder<'a>,
    models: PassModels,
}

impl Level {
    /// Undoes one batch: its cleaning pass, then its decimating pass.
    ///
    /// Both passes predict from the umbrellas of the mesh they start on.
    /// The decimating pass's mesh is the cleaning pass's plus a fan of
    /// three faces in place of one face for every vertex cleaning put back,
    /// so its umbrellas are the cleaning pass's updated at those vertices
    /// rather than swept again over every face (the sweep is bound by
    /// random accesses: a sixth of a WebAssembly decode when every pass
    /// swept).
    pub(crate) fn undo_batch(
        &mut self,
        cleaning: &PassInput,
        decimating: &PassInput,
        scratch: &mut Scratch,
    ) -> Result<()> {
        umbrellas(
            &self.conn,
            &self.positions_q,
            &mut scratch.umbrellas,
            &mut scratch.valences,
        );
        let before = self.vertex_count();
        self.undo_pass(cleaning, scratch)?;
        self.add_cleaned_umbrellas(before, scratch);
        debug_assert!(
            before > 50_000 || self.umbrellas_agree(scratch),
            "umbrellas updated after cleaning differ from a sweep"
        );
        self.undo_pass(decimating, scratch)
    }

    /// Whether `scratch`'s umbrellas and valences are what a sweep of the
    /// level gives (debug builds check the update after cleaning with it).
    fn umbrellas_agree(&self, scratch: &Scratch) -> bool {
        let (mut swept, mut valences) = (Vec::new(), Vec::new());
        umbrellas(&self.conn, &self.positions_q, &mut swept, &mut valences);
        swept == scratch.umbrellas && valences == scratch.valences
    }

    /// Brings the umbrellas up to date with the vertices from `first` on,
    /// each put back by the cleaning pass into a face `a b c`: it becomes
    /// the fans `v a b`, `v b c`, `v c a`, so every corner gains one
    /// outgoing half-edge (to `v`) and keeps the others, and `v` has three.
    /// Wrapping, as the sweep: the same sums modulo 2³².
    fn add_cleaned_umbrellas(&self, first: usize, scratch: &mut Scratch) {
        let inserted = self.vertex_count() - first;
        if inserted == 0 {
            // A skipped pass leaves the last traversal's borders behind.
            return;
        }
        let Scratch {
            traversal,
            umbrellas,
            valences,
            ..
        } = scratch;
        for (i, border) in traversal.borders[..inserted].iter().enumerate() {
            debug_assert_eq!(border.valence, 3, "cleaning puts back valence-3 vertices");
            let v = self.positions_q[first + i];
            let mut own = [0i32, 0, 0, 3];
            for &p in &border.polygon[..3] {
                let p = p as usize;
                let q = self.positions_q[p];
                let u = &mut umbrellas[p];
                for c in 0..3 {
                    u[c] = u[c].wrapping_add(v[c].wrapping_sub(q[c]));
                    own[c] = own[c].wrapping_add(q[c].wrapping_sub(v[c]));
                }
                u[3] += 1;
                valences[p] = u[3].clamp(0, 255) as u8;
            }
            umbrellas.push(own);
            valences.push(3);
        }
    }

    /// Undoes one pass, predicting from `scratch`'s umbrellas and valences
    /// of the mesh as it is now.
    fn undo_pass(&mut self, pass: &PassInput, scratch: &mut Scratch) -> Result<()> {
        let n = self.vertex_count();
        if pass.seeds.is_empty() {
            // A skipped pass (the encoder found nothing worth a traversal).
            return match pass.inserted {
                0 => Ok(()),
                _ => Err(Error::stream("pass without seeds claims inserted vertices")),
            };
        }
        debug_assert_eq!(scratch.umbrellas.len(), n, "umbrellas of this mesh");
        // Phase 1: the traversal finds every patch and re-inserts its
        // vertex's fan (the vertex gets its position in phase 2).
        let mut codes = StreamCodes(RangeDecoder::new(pass.connectivity));
        let traversal = &mut scratch.traversal;
        traversal.run(
            &mut Fans(&mut self.conn),
            &scratch.valences,
            pass.kind,
            &pass.seeds,
            pass.inserted as usize,
            &mut codes,
        )?;
        codes.0.check_overrun()?;
        if traversal.borders.len() != pass.inserted as usize {
            return Err(Error::stream(format!(
                "pass inserted {} vertices, its header says {}",
                traversal.borders.len(),
                pass.inserted
            )));
        }
        let mut s = Streams {
            geom: RangeDecoder::new(pass.geometry),
            colour: RangeDecoder::new(pass.colour),
            models: PassModels::new(),
        };
        let mut decoded = std::mem::take(&mut scratch.decoded);
        decoded.clear();
        let predictions = &mut scratch.predictions;
        for block in traversal.borders.chunks(PREDICTION_BLOCK) {
            predictions.clear();
            predictions.extend(block.iter().map(|r| {
                PatchPrediction::for_border(
                    &r.polygon[..r.valence],
                    &self.positions_q,
                    &scratch.umbrellas,
                )
            }));
            for (r, prediction) in block.iter().zip(predictions.iter()) {
                decoded.push(self.decode_vertex(r, prediction, &mut s)?);
            }
        }
        debug_assert_eq!(n + decoded.len(), self.conn.out.len());
        for &(position, colour) in &decoded {
            self.push_vertex(position, colour);
        }
        scratch.decoded = decoded;
        if let Some(meter) = scratch.meter.as_mut() {
            meter.record(&crate::meter::PassView {
                kind: pass.kind,
                sections: [
                    pass.connectivity.len(),
                    pass.geometry.len(),
                    pass.colour.len(),
                ],
                borders: &scratch.traversal.borders,
                positions: &self.positions_q,
                coarse: n,
                umbrellas: &scratch.umbrellas,
                conn: &self.conn,
            });
        }
        s.geom.check_overrun()?;
        s.colour.check_overrun()
    }

    /// Phase 2: the removed vertex's position and colour from the stream,
    /// given its predicted position (from the coarse mesh's positions and
    /// umbrellas, which inserting fans does not change: exactly what the
    /// encoder saw).
    fn decode_vertex(
        &self,
        r: &Border,
        prediction: &PatchPrediction,
        s: &mut Streams,
    ) -> Result<([i32; 3], Option<[u8; 3]>)> {
        let d = r.valence;
        let position = prediction
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
}

/// The decoder's side of a traversal: each patch found becomes the fan of
/// its re-inserted vertex at once.
struct Fans<'a>(&'a mut Connectivity);

impl PatchSink for Fans<'_> {
    fn conn(&self) -> &Connectivity {
        self.0
    }

    /// Replaces the patch's faces by the fan of a new vertex (the next id).
    fn found(&mut self, r: &Region) {
        let conn = &mut *self.0;
        let d = r.valence;
        // The outer half-edges as they are now: a neighbouring patch
        // re-inserted since this one was found has re-linked them.
        let mut outer = [NONE; MAX_VALENCE];
        for (o, &h) in outer.iter_mut().zip(&r.boundary[..d]) {
            *o = conn.twin[h as usize];
        }
        let v = conn.out.len() as u32;
        conn.out.push(NONE);
        // Faces (v, p_i, p_i+1): reuse the patch's d − 2 slots, append two.
        let mut slots = [NONE; MAX_VALENCE];
        for (i, slot) in slots.iter_mut().enumerate().take(d) {
            *slot = if i < d - 2 {
                face(r.corner0[i])
            } else {
                conn.append_face()
            };
        }
        for i in 0..d {
            let base = 3 * slots[i];
            let (a, b) = (r.polygon[i], r.polygon[(i + 1) % d]);
            conn.origin[base as usize] = v;
            conn.origin[base as usize + 1] = a;
            conn.origin[base as usize + 2] = b;
            let o = outer[i];
            conn.twin[base as usize + 1] = o;
            if o != NONE {
                conn.twin[o as usize] = base + 1;
            }
            // v → p_i pairs with p_i → v, the third half-edge of the previous face.
            let prev_face = 3 * slots[(i + d - 1) % d];
            conn.twin[base as usize] = prev_face + 2;
            conn.twin[prev_face as usize + 2] = base;
            conn.out[a as usize] = base + 1;
        }
        conn.out[v as usize] = 3 * slots[0];
    }
}
