//! Where a stream's bits go, pass by pass: the connectivity bytes, and the
//! information of every geometry residual split into its major tangent,
//! minor tangent and normal components (issue 47's table). Measured while
//! decoding, with shadow models that see the same values in the same order
//! as the stream's own, so the bits are what the range coder spent to
//! within its few bytes of flush per section.
//!
//! The meter also prices *trial* predictors on the same residuals, each
//! with its own shadow models, so a candidate's worth is known before it
//! changes a byte of the format.

use crate::decoder::Decoder;
use crate::frenet::round;
use crate::gates::{Border, PassKind};
use crate::halfedge::Connectivity;
use crate::patch::MAX_VALENCE;
use crate::predict::{PassModels, PatchPrediction, NORMAL_CLASSES};
use crate::{Error, Limits, Result, StreamIndex};

/// One pass of one batch.
#[derive(Clone, Debug, Default)]
pub struct PassBits {
    /// The level the pass's batch produces (1 = the first batch).
    pub batch: u32,
    pub cleaning: bool,
    pub inserted: u32,
    pub connectivity_bytes: u32,
    pub geometry_bytes: u32,
    pub colour_bytes: u32,
    /// Information of the residuals in bits: major tangent, minor tangent, normal.
    pub geometry_bits: [f64; 3],
    /// Trial predictors: a name and the bits of all three components.
    pub trials: Vec<(String, f64)>,
}

/// The shadow models of one way of predicting.
struct Shadow {
    models: PassModels,
    bits: [f64; 3],
}

impl Shadow {
    fn new() -> Self {
        Shadow {
            models: PassModels::new(),
            bits: [0.0; 3],
        }
    }

    fn add(&mut self, classes: [usize; 3], l: [i64; 3]) {
        let m = &mut self.models;
        self.bits[0] += m.tangent[classes[0]].meter(l[0] as i32);
        self.bits[1] += m.tangent[classes[1]].meter(l[1] as i32);
        self.bits[2] += m.normal[classes[2]].meter(l[2] as i32);
    }

    fn total(&self) -> f64 {
        self.bits.iter().sum()
    }
}

/// Collects [`PassBits`] while a [`Decoder`] applies batches.
#[derive(Default)]
pub(crate) struct Meter {
    pub batch: u32,
    pub passes: Vec<PassBits>,
}

/// What the decoder hands the meter after a pass: the level with the
/// pass's vertices appended (ids `coarse..`), in the borders' order.
pub(crate) struct PassView<'a> {
    pub kind: PassKind,
    pub sections: [usize; 3],
    pub borders: &'a [Border],
    pub positions: &'a [[i32; 3]],
    pub coarse: usize,
    pub umbrellas: &'a [[i32; 4]],
    pub conn: &'a Connectivity,
}

/// Curvature corrections tried, in eighths of the mean umbrella vector.
const EIGHTHS: [i64; 5] = [0, 2, 3, 4, 6];

impl Meter {
    pub(crate) fn record(&mut self, v: &PassView<'_>) {
        let mut baseline = Shadow::new();
        let mut eighths: Vec<Shadow> = EIGHTHS.iter().map(|_| Shadow::new()).collect();
        let mut quadric_centre = Shadow::new();
        let mut quadric_tangent = Shadow::new();
        let mut quadric_rough = Shadow::new();
        for (i, b) in v.borders.iter().enumerate() {
            let border = &b.polygon[..b.valence];
            let actual = v.positions[v.coarse + i];
            let p = PatchPrediction::for_border(border, v.positions, v.umbrellas);
            let local = |pos: [i64; 3], frame: crate::frenet::Frame| {
                frame.to_local([0, 1, 2].map(|k| actual[k] as i64 - pos[k]))
            };
            let l = local(p.position, p.frame);
            baseline.add(p.classes, l);
            // The curvature term alone, by how much of it is applied.
            let mut polygon = [[0i32; 3]; MAX_VALENCE];
            for (q, &u) in polygon.iter_mut().zip(border) {
                *q = v.positions[u as usize];
            }
            let plain = PatchPrediction::new(&polygon[..border.len()]);
            let sum = umbrella_sum(border, v.umbrellas);
            for (shadow, &k) in eighths.iter_mut().zip(&EIGHTHS) {
                // The same operations as the predictor's, so 3/8 is it to the bit.
                let scale = k as f64 / 8.0 / border.len() as f64;
                let pos = [0, 1, 2].map(|c| plain.position[c] - round(sum[c] * scale));
                shadow.add(p.classes, local(pos, p.frame));
            }
            // A quadric height field over the coarse 2-ring, in the frame.
            let fit = QuadricFit::around(border, v, p.position, p.frame);
            match fit {
                Some(q) => {
                    let at_centre = round(q.height(0.0, 0.0));
                    quadric_centre.add(p.classes, [l[0], l[1], l[2] - at_centre]);
                    let at = round(q.height(l[0] as f64, l[1] as f64));
                    quadric_tangent.add(p.classes, [l[0], l[1], l[2] - at]);
                    let mut classes = p.classes;
                    classes[2] = rough_class(q.rms);
                    quadric_rough.add(classes, [l[0], l[1], l[2] - at]);
                }
                None => {
                    quadric_centre.add(p.classes, l);
                    quadric_tangent.add(p.classes, l);
                    quadric_rough.add(p.classes, l);
                }
            }
        }
        let mut trials: Vec<(String, f64)> = EIGHTHS
            .iter()
            .zip(&eighths)
            .map(|(k, s)| (format!("curvature {k}/8"), s.total()))
            .collect();
        let best = eighths
            .iter()
            .map(Shadow::total)
            .fold(f64::INFINITY, f64::min);
        // The factor chosen per pass would travel in a byte.
        trials.push(("curvature, best per pass".into(), best + 8.0));
        trials.push(("quadric at centre".into(), quadric_centre.total()));
        trials.push(("quadric at tangent".into(), quadric_tangent.total()));
        trials.push(("quadric, rough class".into(), quadric_rough.total()));
        self.passes.push(PassBits {
            batch: self.batch,
            cleaning: v.kind == PassKind::Cleaning,
            inserted: v.borders.len() as u32,
            connectivity_bytes: v.sections[0] as u32,
            geometry_bytes: v.sections[1] as u32,
            colour_bytes: v.sections[2] as u32,
            geometry_bits: baseline.bits,
            trials,
        });
    }
}

/// Σ of the border's umbrella vectors, each over its valence.
fn umbrella_sum(border: &[u32], umbrellas: &[[i32; 4]]) -> [f64; 3] {
    let mut mean = [0.0f64; 3];
    for &u in border {
        let u = umbrellas[u as usize];
        let inverse = 1.0 / u[3].max(1) as f64;
        for (m, &s) in mean.iter_mut().zip(&u[..3]) {
            *m += s as f64 * inverse;
        }
    }
    mean
}

fn rough_class(rms: f64) -> usize {
    // Half-octaves of the fit's residual, in steps.
    let x = (rms * rms * 4.0) as u64;
    ((64 - x.leading_zeros()) as usize).min(NORMAL_CLASSES - 1)
}

/// `z = a x² + b xy + c y² + d x + e y + f` fitted by least squares.
struct QuadricFit {
    coefficients: [f64; 6],
    rms: f64,
}

impl QuadricFit {
    fn around(
        border: &[u32],
        v: &PassView<'_>,
        origin: [i64; 3],
        frame: crate::frenet::Frame,
    ) -> Option<QuadricFit> {
        let mut ids: Vec<u32> = border.to_vec();
        for &b in border {
            v.conn.for_each_outgoing(b, |h| {
                let t = v.conn.target(h);
                if (t as usize) < v.coarse && !ids.contains(&t) {
                    ids.push(t);
                }
            });
        }
        if ids.len() < 8 {
            return None;
        }
        let mut ata = [[0.0f64; 6]; 6];
        let mut atz = [0.0f64; 6];
        let points: Vec<[f64; 3]> = ids
            .iter()
            .map(|&u| {
                let p = v.positions[u as usize];
                frame.aligned_f64([0, 1, 2].map(|k| (p[k] as i64 - origin[k]) as f64))
            })
            .collect();
        for q in &points {
            let row = [q[0] * q[0], q[0] * q[1], q[1] * q[1], q[0], q[1], 1.0];
            for i in 0..6 {
                for j in 0..6 {
                    ata[i][j] += row[i] * row[j];
                }
                atz[i] += row[i] * q[2];
            }
        }
        let coefficients = solve6(ata, atz)?;
        let fit = QuadricFit {
            coefficients,
            rms: 0.0,
        };
        let sq: f64 = points
            .iter()
            .map(|q| (q[2] - fit.height(q[0], q[1])).powi(2))
            .sum();
        Some(QuadricFit {
            rms: (sq / points.len() as f64).sqrt(),
            ..fit
        })
    }

    fn height(&self, x: f64, y: f64) -> f64 {
        let c = &self.coefficients;
        c[0] * x * x + c[1] * x * y + c[2] * y * y + c[3] * x + c[4] * y + c[5]
    }
}

/// Gaussian elimination with partial pivoting; `None` when singular.
fn solve6(mut a: [[f64; 6]; 6], mut b: [f64; 6]) -> Option<[f64; 6]> {
    for col in 0..6 {
        let pivot = (col..6).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
        if a[pivot][col].abs() < 1e-9 {
            return None;
        }
        a.swap(col, pivot);
        b.swap(col, pivot);
        let pivot_row = a[col];
        for row in col + 1..6 {
            let f = a[row][col] / pivot_row[col];
            for (x, p) in a[row][col..].iter_mut().zip(&pivot_row[col..]) {
                *x -= f * p;
            }
            b[row] -= f * b[col];
        }
    }
    let mut x = [0.0; 6];
    for row in (0..6).rev() {
        let s: f64 = (row + 1..6).map(|k| a[row][k] * x[k]).sum();
        x[row] = (b[row] - s) / a[row][row];
    }
    Some(x)
}

/// Measures a plain (version 4) stream pass by pass.
pub fn bit_budget(stream: &[u8]) -> Result<Vec<PassBits>> {
    let index = StreamIndex::parse(stream)?;
    if index.header.version != crate::VERSION {
        return Err(Error::Unsupported(
            "bit budget of a charted stream: encode it without charts".into(),
        ));
    }
    let mut decoder = Decoder::new(&stream[index.base.clone()], Limits::default())?;
    decoder.meter(Some(Box::default()));
    for (k, range) in index.batches.iter().enumerate() {
        decoder.meter_batch(k as u32 + 1);
        decoder.apply_batch(&stream[range.clone()])?;
    }
    Ok(decoder.meter(None).map(|m| m.passes).unwrap_or_default())
}
