//! Prediction of a removed vertex from its patch, and the adaptive models the
//! residuals are coded with. Encoder and decoder call the same functions.

use crate::entropy::{IntModel, RangeDecoder, RangeEncoder};
use crate::frenet::{round, Frame};
use crate::halfedge::Connectivity;
use crate::patch::{Tag, MAX_VALENCE};

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

/// Residual magnitude grows with the patch's size. Tangential components
/// are coded by the spread of the border polygon along their own axis
/// (⌊log₂⌋ of its variance there: half-octave classes of a length), the
/// normal one by ⌊log₂⌋ of the root mean squared border edge length (octave
/// classes: finer ones cost more in learning than they gain). Both cover
/// 16-bit quantization.
pub(crate) const TANGENT_CLASSES: usize = 36;
pub(crate) const NORMAL_CLASSES: usize = 18;
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
            tangent: (0..TANGENT_CLASSES).map(|_| IntModel::new()).collect(),
            normal: (0..NORMAL_CLASSES).map(|_| IntModel::new()).collect(),
            colour: [IntModel::new(), IntModel::new(), IntModel::new()],
        }
    }
}

/// ⌊log₂ x⌋ + 1 of a non-negative value (0 below 1).
fn bit_length(x: f64) -> usize {
    // `as` saturates: NaN gives 0, huge values u64::MAX.
    64 - (x as u64).leading_zeros() as usize
}

/// Prediction and local frame of one patch (AD01 §4, refined).
pub(crate) struct PatchPrediction {
    pub position: [i64; 3],
    pub(crate) frame: Frame,
    /// Model classes of the (major tangent, minor tangent, normal) components.
    pub(crate) classes: [usize; 3],
}

/// Umbrella vectors of every vertex of the coarse mesh: the sum of
/// `neighbour − vertex` over its outgoing edges, and their count. One
/// sequential sweep over the faces; exact integers, so the encoder (after a
/// pass) and the decoder (before undoing it) get the same values whatever
/// their face order.
///
/// `valences` gets the counts again, saturated to a byte: the gate
/// traversal's contexts read only those, and at a byte a vertex they stay
/// in cache where the 16-byte umbrellas missed it.
pub(crate) fn umbrellas(
    conn: &Connectivity,
    positions: &[[i32; 3]],
    out: &mut Vec<[i32; 4]>,
    valences: &mut Vec<u8>,
) {
    out.clear();
    out.resize(positions.len(), [0; 4]);
    // Σ (neighbour − vertex) = Σ neighbour − count × vertex: the sweep adds
    // only the neighbours (one position load per half-edge, not two; it is
    // bound by the random accesses to `out`), a sequential pass subtracts.
    // Wrapping, so the result is the exact sum modulo 2³² either way.
    for t in conn.origin.chunks_exact(3) {
        if t[0] == crate::halfedge::NONE {
            continue;
        }
        let corners = [t[0], t[1], t[2]].map(|v| positions[v as usize]);
        for k in 0..3 {
            let b = corners[(k + 1) % 3];
            let u = &mut out[t[k] as usize];
            for c in 0..3 {
                u[c] = u[c].wrapping_add(b[c]);
            }
            u[3] += 1;
        }
    }
    valences.clear();
    valences.reserve(out.len());
    for (u, p) in out.iter_mut().zip(positions) {
        for c in 0..3 {
            u[c] = u[c].wrapping_sub(u[3].wrapping_mul(p[c]));
        }
        valences.push(u[3].clamp(0, 255) as u8);
    }
}

/// How far the fine surface bulges out of the border polygon, from the
/// coarse mesh's curvature at the border vertices (in eighths of the mean
/// umbrella vector; 3/8 measured best on the shared scans, 0.9 % smaller
/// than none). Both sides see the same coarse mesh: the encoder after
/// the pass, the decoder before undoing it.
const CURVATURE_EIGHTHS: f64 = 3.0;

/// Encoder and decoder predict positions a block of patches at a time, apart
/// from the range coding. Each prediction is a long chain of dependent `f64`
/// square roots and divisions but independent of the others, so with
/// nothing in between the CPU overlaps several chains; interleaved with the
/// (serial) range coder it waited on each in turn (decoding 9 % faster).
pub(crate) const PREDICTION_BLOCK: usize = 32;

impl PatchPrediction {
    /// The prediction for a removed vertex whose border polygon is `border`
    /// (ids into the coarse mesh's `positions` and `umbrellas`).
    pub(crate) fn for_border(
        border: &[u32],
        positions: &[[i32; 3]],
        umbrellas: &[[i32; 4]],
    ) -> Self {
        let d = border.len();
        let mut polygon = [[0i32; 3]; MAX_VALENCE];
        let mut around = [[0i32; 4]; MAX_VALENCE];
        for i in 0..d {
            polygon[i] = positions[border[i] as usize];
            around[i] = umbrellas[border[i] as usize];
        }
        Self::with_curvature(&polygon[..d], &around[..d])
    }

    /// Barycentre corrected by the coarse mesh's curvature at the border.
    pub(crate) fn with_curvature(polygon: &[[i32; 3]], umbrellas: &[[i32; 4]]) -> Self {
        let mut p = Self::new(polygon);
        let mut mean = [0.0f64; 3];
        for u in umbrellas {
            // One division per border vertex, not three.
            let inverse = 1.0 / u[3].max(1) as f64;
            for (m, &s) in mean.iter_mut().zip(&u[..3]) {
                *m += s as f64 * inverse;
            }
        }
        let scale = CURVATURE_EIGHTHS / 8.0 / umbrellas.len() as f64;
        for (x, m) in p.position.iter_mut().zip(mean) {
            *x -= round(m * scale);
        }
        p
    }

    /// The area centroid of the border polygon (the vertex mean when the
    /// polygon folds over as seen along its normal), with a frame whose
    /// first tangent follows the polygon's longer extent.
    ///
    /// Scanned surfaces are sampled irregularly: the removed vertex sits
    /// nearer the area centroid than the vertex mean, and its tangential
    /// offset spreads along the polygon's longer axis. On the shared scans
    /// this codes geometry about 4 % smaller than the vertex mean in an
    /// arbitrarily oriented frame (BENCHMARKS.md).
    pub(crate) fn new(polygon: &[[i32; 3]]) -> Self {
        let d = polygon.len() as i64;
        let mut sum = [0i64; 3];
        for p in polygon {
            for k in 0..3 {
                sum[k] += p[k] as i64;
            }
        }
        let mean = sum.map(|s| s.div_euclid(d) + i64::from(2 * s.rem_euclid(d) >= d));
        let mean_squared = mean_squared_edge(polygon);
        let edge_class = ((64 - mean_squared.leading_zeros() as usize) / 2).min(NORMAL_CLASSES - 1);
        let mut frame = Frame::new(newell_normal(polygon));
        // The polygon in the tangent plane, relative to its vertex mean.
        let centre = sum.map(|s| s as f64 / d as f64);
        let mut plane = [(0.0f64, 0.0f64); MAX_VALENCE];
        for (q, p) in plane.iter_mut().zip(polygon) {
            *q = frame.tangent_f64([0, 1, 2].map(|k| p[k] as f64 - centre[k]));
        }
        let plane = &plane[..polygon.len()];
        let (major, minor) = principal_axes(plane, &mut frame);
        let position = area_centroid(plane, polygon, centre).unwrap_or(mean);
        PatchPrediction {
            position,
            frame,
            classes: [
                bit_length(major).min(TANGENT_CLASSES - 1),
                bit_length(minor).min(TANGENT_CLASSES - 1),
                edge_class,
            ],
        }
    }

    pub(crate) fn encode(&self, actual: [i32; 3], m: &mut PassModels, enc: &mut RangeEncoder) {
        let r = [0, 1, 2].map(|k| actual[k] as i64 - self.position[k]);
        let l = self.frame.to_local(r);
        let [major, minor, normal] = self.classes;
        enc.encode_int(&mut m.tangent[major], l[0] as i32);
        enc.encode_int(&mut m.tangent[minor], l[1] as i32);
        enc.encode_int(&mut m.normal[normal], l[2] as i32);
    }

    /// Returns `None` when the decoded position falls outside `[0, max]`: a corrupt stream.
    pub(crate) fn decode(
        &self,
        max: i32,
        m: &mut PassModels,
        dec: &mut RangeDecoder,
    ) -> Option<[i32; 3]> {
        let [major, minor, normal] = self.classes;
        let l = [
            dec.decode_int(&mut m.tangent[major]) as i64,
            dec.decode_int(&mut m.tangent[minor]) as i64,
            dec.decode_int(&mut m.normal[normal]) as i64,
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

/// Newell normal of the polygon, relative to its first vertex to keep
/// products small (exact in i64).
fn newell_normal(polygon: &[[i32; 3]]) -> [i64; 3] {
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
    normal
}

/// Mean squared length of the polygon's edges (integer, rounded down).
fn mean_squared_edge(polygon: &[[i32; 3]]) -> u64 {
    let mut squared = 0u64;
    for i in 0..polygon.len() {
        let (a, b) = (polygon[i], polygon[(i + 1) % polygon.len()]);
        squared += (0..3)
            .map(|k| ((a[k] - b[k]) as i64).pow(2) as u64)
            .sum::<u64>();
    }
    squared / polygon.len() as u64
}

/// Turns `frame`'s first tangent onto the polygon's major axis (from the
/// 2×2 covariance of its tangent-plane coordinates `plane`, centred) and
/// returns the variances along the major and minor axes. Closed form with
/// `+ − × / sqrt` only, so every platform gets the same bits.
fn principal_axes(plane: &[(f64, f64)], frame: &mut Frame) -> (f64, f64) {
    // Sums, not means: the direction does not depend on the scale.
    let (mut a, mut b, mut c) = (0.0, 0.0, 0.0);
    for &(x, y) in plane {
        a += x * x;
        b += x * y;
        c += y * y;
    }
    let h = (a - c) / 2.0;
    let r = (h * h + b * b).sqrt();
    // An eigenvector of the larger eigenvalue, from whichever form is well conditioned.
    if h >= 0.0 {
        frame.align_tangent(h + r, b);
    } else {
        frame.align_tangent(b, r - h);
    }
    let mid = (a + c) / 2.0;
    let n = plane.len() as f64;
    ((mid + r) / n, (mid - r).max(0.0) / n)
}

/// The area centroid of the polygon fanned from `centre` (its vertex mean),
/// with `plane` its tangent-plane coordinates about `centre`; `None` when a
/// fan triangle folds over (the polygon is not star-shaped from its mean).
fn area_centroid(plane: &[(f64, f64)], polygon: &[[i32; 3]], centre: [f64; 3]) -> Option<[i64; 3]> {
    let d = polygon.len();
    let mut weighted = [0.0f64; 3];
    let mut total = 0.0;
    for i in 0..d {
        let j = (i + 1) % d;
        let ((ax, ay), (bx, by)) = (plane[i], plane[j]);
        let w = ax * by - ay * bx;
        if w.is_nan() || w <= 0.0 {
            return None;
        }
        total += w;
        for k in 0..3 {
            // Three times the fan triangle's centroid, relative to `centre`.
            let (pa, pb) = (
                polygon[i][k] as f64 - centre[k],
                polygon[j][k] as f64 - centre[k],
            );
            weighted[k] += w * (pa + pb);
        }
    }
    let scale = 1.0 / (3.0 * total);
    Some([0, 1, 2].map(|k| round(centre[k] + weighted[k] * scale)))
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn area_centroid_of_an_uneven_polygon_differs_from_its_vertex_mean() {
        // A square with an extra vertex close to one corner: the vertex mean
        // is pulled towards that corner, the area centroid is not.
        let square = [[0, 0, 7], [90, 0, 7], [90, 80, 7], [0, 80, 7]];
        let p = PatchPrediction::new(&square);
        assert_eq!(p.position, [45, 40, 7]);
        let crowded = [[0, 0, 7], [90, 0, 7], [90, 80, 7], [10, 80, 7], [0, 80, 7]];
        let p = PatchPrediction::new(&crowded);
        assert_eq!(p.position, [45, 40, 7]);
        assert_eq!(crowded.iter().map(|v| v[0]).sum::<i32>() / 5, 38);
    }

    #[test]
    fn a_polygon_folding_over_its_mean_falls_back_to_the_mean() {
        // An L whose vertex mean (36.7, 36.7) lies outside it: fanned from
        // there, triangles fold over. Its area centroid would be (28.7, 28.7).
        let l_shape = [
            [0, 0, 0],
            [100, 0, 0],
            [100, 10, 0],
            [10, 10, 0],
            [10, 100, 0],
            [0, 100, 0],
        ];
        let p = PatchPrediction::new(&l_shape);
        assert_eq!(p.position, [37, 37, 0]);
    }

    #[test]
    fn the_first_tangent_follows_the_polygon_s_longer_extent() {
        // Long along y, short along x, in the z = 0 plane.
        let long = [[0, 0, 0], [20, 0, 0], [20, 200, 0], [0, 200, 0]];
        let p = PatchPrediction::new(&long);
        let [major, minor, _] = p.classes;
        assert!(major > minor + 4, "{major} {minor}");
        // A residual along y comes out on the first (major) tangent.
        let l = p.frame.to_local([0, 50, 0]);
        assert_eq!((l[0].abs(), l[1], l[2]), (50, 0, 0), "{l:?}");
        // And it decodes back exactly.
        assert_eq!(p.frame.to_world(l), [0, 50, 0]);
    }
}
