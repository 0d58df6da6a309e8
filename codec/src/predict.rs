//! Prediction of a removed vertex from its patch, and the adaptive models the
//! residuals are coded with. Encoder and decoder call the same functions.

use crate::entropy::{IntModel, RangeDecoder, RangeEncoder};
use crate::frenet::{round, Frame};
use crate::halfedge::Connectivity;
use crate::patch::Tag;

/// Context for a gate's code: the tags of its two vertices and of the
/// third vertex of its front face *as the decoder sees it* (the coarse
/// mesh). The encoder knows that vertex once it has decided the code: the
/// front vertex for a null patch, the pattern's third vertex for a patch.
/// An untagged third vertex is still free, which makes a patch likely; a
/// tagged one was conquered, which a null patch then requires.
#[inline]
pub(crate) fn gate_context(t0: Tag, t1: Tag, third: Tag) -> usize {
    (t0 as usize % 3) * 9 + (t1 as usize % 3) * 3 + (third as usize % 3)
}

pub(crate) const GATE_CONTEXTS: usize = 27;

/// Residual magnitude grows with the patch's size: code each size class
/// (≈ log2 of the mean border edge length) with its own models.
pub(crate) const SCALE_CLASSES: usize = 16;
/// Adaptive geometry and colour models of one conquest pass; reset per
/// pass so every batch decodes on its own given the previous level (AD01
/// resets per layer too). Connectivity models are in [`crate::gates`].
pub(crate) struct PassModels {
    pub tangent: Vec<IntModel>,
    pub normal: Vec<IntModel>,
    pub colour: [IntModel; 3],
}

impl PassModels {
    pub(crate) fn new() -> Self {
        PassModels {
            tangent: (0..SCALE_CLASSES).map(|_| IntModel::new()).collect(),
            normal: (0..SCALE_CLASSES).map(|_| IntModel::new()).collect(),
            colour: [IntModel::new(), IntModel::new(), IntModel::new()],
        }
    }
}

/// Barycentric prediction and Frenet frame of one patch (AD01 §4).
pub(crate) struct PatchPrediction {
    pub position: [i64; 3],
    frame: Frame,
    scale: usize,
}

/// Umbrella vectors of every vertex of the coarse mesh: the sum of
/// `neighbour − vertex` over its outgoing edges, and their count. One
/// sequential sweep over the faces; exact integers, so the encoder (after a
/// pass) and the decoder (before undoing it) get the same values whatever
/// their face order.
pub(crate) fn umbrellas(conn: &Connectivity, positions: &[[i32; 3]], out: &mut Vec<[i32; 4]>) {
    out.clear();
    out.resize(positions.len(), [0; 4]);
    for t in conn.origin.chunks_exact(3) {
        if t[0] == crate::halfedge::NONE {
            continue;
        }
        for k in 0..3 {
            let (a, b) = (t[k] as usize, t[(k + 1) % 3] as usize);
            let u = &mut out[a];
            for c in 0..3 {
                u[c] += positions[b][c] - positions[a][c];
            }
            u[3] += 1;
        }
    }
}

/// How far the fine surface bulges out of the border polygon, from the
/// coarse mesh's curvature at the border vertices (in eighths of the mean
/// umbrella vector; 3/8 measured best on the shared scans, 0.9 % smaller
/// than none). Both sides see the same coarse mesh: the encoder after
/// the pass, the decoder before undoing it.
const CURVATURE_EIGHTHS: f64 = 3.0;

impl PatchPrediction {
    /// Barycentre corrected by the coarse mesh's curvature at the border.
    pub(crate) fn with_curvature(polygon: &[[i32; 3]], umbrellas: &[[i32; 4]]) -> Self {
        let mut p = Self::new(polygon);
        let mut mean = [0.0f64; 3];
        for u in umbrellas {
            for (m, &s) in mean.iter_mut().zip(&u[..3]) {
                *m += s as f64 / u[3].max(1) as f64;
            }
        }
        let scale = CURVATURE_EIGHTHS / 8.0 / umbrellas.len() as f64;
        for (x, m) in p.position.iter_mut().zip(mean) {
            *x -= round(m * scale);
        }
        p
    }

    pub(crate) fn new(polygon: &[[i32; 3]]) -> Self {
        let d = polygon.len() as i64;
        let mut sum = [0i64; 3];
        for p in polygon {
            for k in 0..3 {
                sum[k] += p[k] as i64;
            }
        }
        let position = sum.map(|s| s.div_euclid(d) + i64::from(2 * s.rem_euclid(d) >= d));
        // Newell normal of the polygon, relative to its first vertex to keep products small.
        let o = polygon[0];
        let rel = |p: &[i32; 3]| [0, 1, 2].map(|k| (p[k] - o[k]) as i64);
        let mut normal = [0i64; 3];
        for i in 0..polygon.len() {
            let a = rel(&polygon[i]);
            let b = rel(&polygon[(i + 1) % polygon.len()]);
            normal[0] += a[1] * b[2] - a[2] * b[1];
            normal[1] += a[2] * b[0] - a[0] * b[2];
            normal[2] += a[0] * b[1] - a[1] * b[0];
        }
        let mut squared = 0u64;
        for i in 0..polygon.len() {
            let (a, b) = (polygon[i], polygon[(i + 1) % polygon.len()]);
            squared += (0..3)
                .map(|k| ((a[k] - b[k]) as i64).pow(2) as u64)
                .sum::<u64>();
        }
        let mean = squared / polygon.len() as u64;
        let scale = (((64 - mean.leading_zeros()) / 2) as usize).min(SCALE_CLASSES - 1);
        PatchPrediction {
            position,
            frame: Frame::new(normal),
            scale,
        }
    }

    pub(crate) fn encode(&self, actual: [i32; 3], m: &mut PassModels, enc: &mut RangeEncoder) {
        let r = [0, 1, 2].map(|k| actual[k] as i64 - self.position[k]);
        let l = self.frame.to_local(r);
        enc.encode_int(&mut m.tangent[self.scale], l[0] as i32);
        enc.encode_int(&mut m.tangent[self.scale], l[1] as i32);
        enc.encode_int(&mut m.normal[self.scale], l[2] as i32);
    }

    /// Returns `None` when the decoded position falls outside `[0, max]`: a corrupt stream.
    pub(crate) fn decode(
        &self,
        max: i32,
        m: &mut PassModels,
        dec: &mut RangeDecoder,
    ) -> Option<[i32; 3]> {
        let l = [
            dec.decode_int(&mut m.tangent[self.scale]) as i64,
            dec.decode_int(&mut m.tangent[self.scale]) as i64,
            dec.decode_int(&mut m.normal[self.scale]) as i64,
        ];
        let r = self.frame.to_world(l);
        let mut out = [0i32; 3];
        for k in 0..3 {
            let v = self.position[k].checked_add(r[k])?;
            if !(0..=max as i64).contains(&v) {
                return None;
            }
            out[k] = v as i32;
        }
        Some(out)
    }
}

/// Mean colour of the patch border, the predictor for the removed vertex.
pub(crate) fn predict_colour(polygon: &[[u8; 3]]) -> [u8; 3] {
    let d = polygon.len() as u32;
    std::array::from_fn(|k| {
        let s: u32 = polygon.iter().map(|c| c[k] as u32).sum();
        ((s + d / 2) / d) as u8
    })
}

/// Colour residual, green first and red/blue relative to it (decorrelates
/// luminance), all modulo 256 so the map is a bijection.
pub(crate) fn encode_colour(
    actual: [u8; 3],
    pred: [u8; 3],
    m: &mut PassModels,
    enc: &mut RangeEncoder,
) {
    let d = [0, 1, 2].map(|k| actual[k].wrapping_sub(pred[k]));
    let g = d[1] as i8;
    let r = d[0].wrapping_sub(d[1]) as i8;
    let b = d[2].wrapping_sub(d[1]) as i8;
    enc.encode_int(&mut m.colour[0], g as i32);
    enc.encode_int(&mut m.colour[1], r as i32);
    enc.encode_int(&mut m.colour[2], b as i32);
}

pub(crate) fn decode_colour(pred: [u8; 3], m: &mut PassModels, dec: &mut RangeDecoder) -> [u8; 3] {
    let g = dec.decode_int(&mut m.colour[0]) as u8;
    let r = (dec.decode_int(&mut m.colour[1]) as u8).wrapping_add(g);
    let b = (dec.decode_int(&mut m.colour[2]) as u8).wrapping_add(g);
    [
        pred[0].wrapping_add(r),
        pred[1].wrapping_add(g),
        pred[2].wrapping_add(b),
    ]
}
