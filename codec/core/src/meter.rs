//! Where a stream's bits go, pass by pass: the connectivity bytes, and the
//! information of every geometry residual split into its major tangent,
//! minor tangent and normal components (issue 47's table). Measured while
//! decoding, with shadow models that see the same values in the same order
//! as the stream's own, so the bits are what the range coder spent to
//! within its few bytes of flush per section.
//!
//! [`crate::bits::bit_budget`] runs it on a stream. The meter also prices
//! *trial* predictors on the same residuals, each with its own shadow
//! models, so a candidate's worth is known before it changes a byte of the
//! format.

use crate::frenet::round;
use crate::gates::{Border, PassKind};
use crate::halfedge::Connectivity;
use crate::patch::MAX_VALENCE;
use crate::predict::{PassModels, PatchPrediction, NORMAL_CLASSES};

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
    /// Every inserted vertex's tangential residual, for the deferred
    /// precision bound ([`Meter::price_deferral`]).
    inserted: Vec<Inserted>,
}

/// One inserted vertex as its pass coded it.
struct Inserted {
    pass: usize,
    vertex: u32,
    tangential: [i64; 2],
    classes: [usize; 2],
}

/// Tangential steps tried for deferral: 2^e, e in 0..DEFER_EXPONENTS.
const DEFER_EXPONENTS: usize = 7;

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
            self.inserted.push(Inserted {
                pass: self.passes.len(),
                vertex: (v.coarse + i) as u32,
                tangential: [l[0], l[1]],
                classes: [p.classes[0], p.classes[1]],
            });
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
impl Meter {
    /// An optimistic bound on **deferred precision** (FORMAT.md, version
    /// 6): each pass but the last batch's codes its vertices' tangential
    /// residuals divided by 2^e (e chosen per pass), and the e low bits of
    /// each come later, predicted from the vertex's ring in the final mesh
    /// (as the finest layer's vertices are), each component costing the
    /// lesser of e bits and its residual there. Optimistic: the finer
    /// layers' predictions from approximate positions are not priced, and
    /// a ring of more than 6 vertices or on a border pays the e bits.
    /// Adds the trial "deferred precision (bound)" to every pass.
    pub(crate) fn price_deferral(&mut self, conn: &Connectivity, positions: &[[i32; 3]]) {
        let last = self.batch;
        let (mut umbrellas, mut valences) = (Vec::new(), Vec::new());
        crate::predict::umbrellas(conn, positions, &mut umbrellas, &mut valences);
        let mut fine = Shadow::new();
        let mut by_pass: Vec<Vec<Deferral>> = vec![Vec::new(); self.passes.len()];
        for r in &self.inserted {
            let deferred = self.passes[r.pass].batch < last;
            let remainder = match final_ring(conn, r.vertex) {
                Some(ring) if deferred => {
                    let p = PatchPrediction::for_border(&ring.0[..ring.1], positions, &umbrellas);
                    let actual = positions[r.vertex as usize];
                    let l = p
                        .frame
                        .to_local([0, 1, 2].map(|k| actual[k] as i64 - p.position[k]));
                    let m = &mut fine.models;
                    [
                        m.tangent[p.classes[0]].meter(l[0] as i32),
                        m.tangent[p.classes[1]].meter(l[1] as i32),
                    ]
                }
                _ => [f64::INFINITY; 2],
            };
            by_pass[r.pass].push((r.tangential, r.classes, remainder));
        }
        for (pass, vertices) in self.passes.iter_mut().zip(&by_pass) {
            let exact = pass.geometry_bits[0] + pass.geometry_bits[1];
            let mut best = exact;
            let deferrable = pass.batch < last;
            for e in 1..DEFER_EXPONENTS as u32 {
                if !deferrable {
                    break;
                }
                let mut models = PassModels::new();
                let mut bits = 8.0; // the pass header's exponent byte
                for &(t, classes, remainder) in vertices {
                    for c in 0..2 {
                        bits += models.tangent[classes[c]].meter((t[c] >> e) as i32);
                        bits += remainder[c].min(e as f64);
                    }
                }
                best = best.min(bits);
            }
            pass.trials.push((
                "deferred precision (bound)".into(),
                best + pass.geometry_bits[2],
            ));
        }
    }
}

/// A vertex's tangential residual, its model classes, and what each
/// component's remainder would cost from the final ring.
type Deferral = ([i64; 2], [usize; 2], [f64; 2]);

/// The final mesh's ring of `v`, counter-clockwise, when it is closed and
/// of at most [`MAX_VALENCE`] vertices.
fn final_ring(conn: &Connectivity, v: u32) -> Option<([u32; MAX_VALENCE], usize)> {
    let start = conn.out[v as usize];
    let mut ring = [0u32; MAX_VALENCE];
    let (mut h, mut n) = (start, 0);
    loop {
        if n == MAX_VALENCE {
            return None;
        }
        ring[n] = conn.target(h);
        n += 1;
        h = conn.rotate_ccw(h);
        if h == crate::halfedge::NONE {
            return None;
        }
        if h == start {
            return Some((ring, n));
        }
    }
}

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
