//! Attributes predicted from the decoded neighbourhood (header flag bit 2,
//! `FORMAT.md` "Predicted attributes"). A new point's neighbours are the
//! cells near it among the few coded just before it (its earlier siblings,
//! its parent's representative, the last children of the parents before)
//! and the next few cells of the parent depth: a window of the coding order
//! instead of a k-nearest search, so a point costs a few dozen integer
//! operations. Its normal is predicted by the nearest neighbour's, its
//! colour by the neighbours' mean weighted by 1/d² (a lifting-style
//! predictor as in MPEG G-PCC, ISO/IEC 23090-9 §10.6), and the residuals
//! are coded with the models of a class: how widely the neighbours' values
//! range.
//!
//! Measured (session 34, `docs/bench-log/2026-12-08-session-34-point-attributes.md`):
//! the mean of the neighbours' normals (re-encoded octahedrally) coded
//! estimated normals 10 % larger than the parent's normal alone; the
//! nearest neighbour's, 1–6 % smaller, and with the second residual's
//! models chosen by the first's size (`models.rs`), 2–12 % smaller. Wider
//! windows (16 behind, 8 ahead) saved 0.1 % more on normals and 1–4 % on
//! colours for up to twice the prediction's time.
//!
//! Everything is in integers: the encoder and every decoder (native,
//! WebAssembly) predict the same values.

use super::attr::Attr;

/// Cells at the child depth coded just before the new point (its earlier
/// siblings, the parent's representative's cell, the children of the
/// parents before) that are candidates.
pub(crate) const BEHIND: usize = 4;
/// Cells at the parent depth after the new point's parent that are
/// candidates (their representatives).
pub(crate) const AHEAD: usize = 2;
/// A candidate is a neighbour if it is at most this far on every axis, in
/// half child cells (2 child cells).
const REACH: i32 = 4;
/// 65536 / d² for the squared distances a neighbour can be at, in half
/// child cells (d² = 0 cannot occur: a candidate's centre is never the new
/// point's).
const WEIGHTS: [u32; 3 * (REACH * REACH) as usize + 1] = {
    let mut w = [65_536; 3 * (REACH * REACH) as usize + 1];
    let mut d2 = 1;
    while d2 < w.len() {
        w[d2] = 65_536 / d2 as u32;
        d2 += 1;
    }
    w
};
/// Residual model classes per attribute.
pub(crate) const CLASSES: usize = 8;

/// The neighbours of one new point, gathered as they are offered: the
/// nearest one's normal, the weighted colour sums and each component's
/// range.
pub(crate) struct Neighbours {
    /// The new point's cell centre, in half cells of its depth.
    at: [i32; 3],
    normals: bool,
    colours: bool,
    count: u32,
    nearest: u32,
    normal: [u16; 2],
    weights: u32,
    colour: [u32; 3],
    /// Smallest and largest normal code components.
    normal_low: [u16; 2],
    normal_high: [u16; 2],
    /// Smallest and largest colour channels.
    colour_low: [u8; 3],
    colour_high: [u8; 3],
}

/// What a new point's attributes are coded against.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Prediction {
    pub attr: Attr,
    pub normal_class: u8,
    pub colour_class: u8,
}

/// The centre of the cell `at` of the child depth, in half child cells.
pub(crate) fn child_centre(at: [u32; 3]) -> [i32; 3] {
    at.map(|v| (2 * v + 1) as i32)
}

/// The centre of the cell `at` of the parent depth, in half child cells.
pub(crate) fn parent_centre(at: [u32; 3]) -> [i32; 3] {
    at.map(|v| (4 * v + 2) as i32)
}

impl Neighbours {
    /// For the new point whose cell (at the child depth) is `at`, in a
    /// stream with normals and/or colours.
    pub fn new(at: [u32; 3], normals: bool, colours: bool) -> Self {
        Neighbours {
            at: child_centre(at),
            normals,
            colours,
            count: 0,
            nearest: 0,
            normal: [0; 2],
            weights: 0,
            colour: [0; 3],
            normal_low: [u16::MAX; 2],
            normal_high: [0; 2],
            colour_low: [u8::MAX; 3],
            colour_high: [0; 3],
        }
    }

    /// Offers the candidates: each point's centre (half child cells) and
    /// attributes. (One loop over local accumulators, so that they stay in
    /// registers.)
    #[inline(always)]
    pub fn offer(&mut self, candidates: impl Iterator<Item = ([i32; 3], Attr)>) {
        match (self.normals, self.colours) {
            (true, true) => self.gather::<true, true>(candidates),
            (true, false) => self.gather::<true, false>(candidates),
            (false, true) => self.gather::<false, true>(candidates),
            (false, false) => self.gather::<false, false>(candidates),
        }
    }

    #[inline(always)]
    fn gather<const NORMALS: bool, const COLOURS: bool>(
        &mut self,
        candidates: impl Iterator<Item = ([i32; 3], Attr)>,
    ) {
        let (mut count, mut nearest, mut normal) = (self.count, self.nearest, self.normal);
        let (mut n_low, mut n_high) = (self.normal_low, self.normal_high);
        let (mut weights, mut colour) = (self.weights, self.colour);
        let (mut c_low, mut c_high) = (self.colour_low, self.colour_high);
        let inside = |v: i32| (v + REACH) as u32 <= 2 * REACH as u32;
        for (centre, a) in candidates {
            let d = [0, 1, 2].map(|k| centre[k] - self.at[k]);
            if !(inside(d[0]) && inside(d[1]) && inside(d[2])) {
                continue;
            }
            let w = WEIGHTS[(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) as usize];
            count += 1;
            if NORMALS {
                if w > nearest {
                    nearest = w;
                    normal = a.normal;
                }
                for k in 0..2 {
                    n_low[k] = n_low[k].min(a.normal[k]);
                    n_high[k] = n_high[k].max(a.normal[k]);
                }
            }
            if COLOURS {
                weights += w;
                for k in 0..3 {
                    colour[k] += w * u32::from(a.colour[k]);
                    c_low[k] = c_low[k].min(a.colour[k]);
                    c_high[k] = c_high[k].max(a.colour[k]);
                }
            }
        }
        (self.count, self.nearest, self.normal) = (count, nearest, normal);
        (self.normal_low, self.normal_high) = (n_low, n_high);
        (self.weights, self.colour) = (weights, colour);
        (self.colour_low, self.colour_high) = (c_low, c_high);
    }

    /// The prediction: the nearest neighbour's normal, the colour mean
    /// weighted by 1/d², each with the class of the neighbours' range;
    /// `fallback` (the parent's representative) in class 0 without
    /// neighbours.
    pub fn predict(&self, fallback: Attr) -> Prediction {
        let mut p = Prediction {
            attr: fallback,
            normal_class: 0,
            colour_class: 0,
        };
        if self.count == 0 {
            return p;
        }
        if self.normals {
            let range = |k: usize| u32::from(self.normal_high[k] - self.normal_low[k]);
            p.attr.normal = self.normal;
            p.normal_class = class(range(0).max(range(1)));
        }
        if self.colours {
            let total = self.weights;
            let range = |k: usize| u32::from(self.colour_high[k] - self.colour_low[k]);
            p.attr.colour = self.colour.map(|c| ((c + total / 2) / total) as u8);
            p.colour_class = class(range(0).max(range(1)).max(range(2)));
        }
        p
    }
}

/// Class 1..CLASSES − 1 of a range, from its bit length.
fn class(range: u32) -> u8 {
    let bits = 32 - range.leading_zeros();
    1 + bits.min(CLASSES as u32 - 2) as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn agreeing_neighbours_predict_their_value_in_the_lowest_class() {
        let a = Attr {
            normal: [300, 900],
            colour: [10, 200, 30],
        };
        let mut n = Neighbours::new([5, 5, 5], true, true);
        n.offer(
            [
                (child_centre([4, 5, 5]), a),
                (parent_centre([2, 2, 2]), a),
                (child_centre([90, 5, 5]), Attr::default()), // too far
            ]
            .into_iter(),
        );
        let p = n.predict(Attr::default());
        assert_eq!(p.attr, a);
        assert_eq!((p.normal_class, p.colour_class), (1, 1));
    }

    #[test]
    fn nearest_normal_weighted_colour_and_range_classes() {
        let near = Attr {
            normal: [100, 100],
            colour: [0, 0, 0],
        };
        let far = Attr {
            normal: [110, 100],
            colour: [250, 250, 250],
        };
        let mut n = Neighbours::new([8, 8, 8], true, true);
        // d² = 4 and 16.
        n.offer(
            [
                (child_centre([9, 8, 8]), near),
                (child_centre([10, 8, 8]), far),
            ]
            .into_iter(),
        );
        let p = n.predict(Attr::default());
        assert_eq!(p.attr.normal, [100, 100]);
        // (0 · 16384 + 250 · 4096 + 10240) / 20480 = 50.5 → 50.
        assert_eq!(p.attr.colour, [50; 3]);
        // Ranges 10 (4 bits) and 250 (8 bits, capped at class 7).
        assert_eq!((p.normal_class, p.colour_class), (5, 7));
        // Nobody near: the fallback, class 0.
        let alone = Neighbours::new([0, 0, 0], true, true).predict(far);
        assert_eq!(
            (alone.attr, alone.normal_class, alone.colour_class),
            (far, 0, 0)
        );
    }
}
