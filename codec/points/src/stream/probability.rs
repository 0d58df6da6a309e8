//! Version 3's bit probabilities: adaptive counters that learn fast while
//! a context is young, and a logistic mix of the predictions of several
//! contexts (the context mixing of PAQ-style compressors), so that a large
//! context whose models have seen little is not trusted more than a small
//! one that has seen much.
//!
//! Hand-written: the decoder in WebAssembly must agree bit for bit with the
//! native encoder, so everything is integer arithmetic on tables computed
//! here (no float `exp`/`ln`, whose last bits differ between libms), and the
//! probability reaches the shared range coder (`vitrine_codec::entropy`) as a
//! one-step `BitModel`.

use vitrine_codec::entropy::{BitModel, RangeDecoder, RangeEncoder};

/// A counter's adaptation ends at a rate of 1/(`LIMIT` + 1.5) (on lucy
/// 300 k at 12 bits: 30 cost 1 % more, 255 about the same).
const LIMIT: usize = 127;
/// Each weight starts at about 0.3.
const FIRST_WEIGHT: i32 = 20_000;
/// Weights stay within ±64.
const WEIGHT_LIMIT: i32 = 1 << 22;
/// A weight moves by stretch · error / 2^`LEARNING_SHIFT` (both 12-bit):
/// 12 and 14 cost up to 0.2 % more, 10 cost 1 %.
const LEARNING_SHIFT: u32 = 13;
/// The refinement's points move 1/2^`REFINE_SHIFT` of the way (6: +0.1 %,
/// 5: +0.3 %).
const REFINE_SHIFT: u32 = 7;

/// `RATE[n]`: 2^16 / (n + 1.5), the step of a counter that has seen n bits
/// (256 entries, so that a `u8` count needs no bounds check).
static RATE: [u32; 256] = {
    let mut t = [0; 256];
    let mut n = 0;
    while n < 256 {
        t[n] = (2 << 16) / (2 * n as u32 + 3);
        n += 1;
    }
    t
};

/// An adaptive estimate of P(bit = 1), 16-bit, whose step shrinks with the
/// bits it has seen (1/1.5, 1/2.5, … down to 1/(`LIMIT` + 1.5)).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Counter {
    p1: u16,
    seen: u8,
}

impl Default for Counter {
    fn default() -> Self {
        Counter {
            p1: 1 << 15,
            seen: 0,
        }
    }
}

impl Counter {
    /// P(bit = 1) in units of 2^-12.
    pub fn p1(self) -> u32 {
        u32::from(self.p1 >> 4)
    }

    /// Codes `bit` with this counter alone, and updates it.
    pub fn encode(&mut self, enc: &mut RangeEncoder, bit: bool) {
        let p0 = 4096 - self.p1().clamp(1, 4095);
        enc.encode_bit(&mut BitModel::with_p0_4096(p0 as u16), bit);
        self.update(bit);
    }

    /// Decodes a bit coded by [`encode`](Self::encode).
    pub fn decode(&mut self, dec: &mut RangeDecoder<'_>) -> bool {
        let p0 = 4096 - self.p1().clamp(1, 4095);
        let bit = dec.decode_bit(&mut BitModel::with_p0_4096(p0 as u16));
        self.update(bit);
        bit
    }

    pub fn update(&mut self, bit: bool) {
        let rate = RATE[usize::from(self.seen)];
        let p = i64::from(self.p1);
        let target = if bit { 65535 } else { 0 };
        self.p1 = (p + (((target - p) * i64::from(rate)) >> 16)) as u16;
        self.seen += u8::from(usize::from(self.seen) < LIMIT);
    }
}

/// `N` counters (a power of two) indexed modulo `N`, which spares the
/// bounds checks of the hot loop; callers' indices are below their
/// context counts, so no two contexts share a counter.
pub(crate) struct Counters<const N: usize>(Box<[Counter; N]>);

impl<const N: usize> Counters<N> {
    pub fn new() -> Self {
        const { assert!(N.is_power_of_two()) };
        let all: Box<[Counter]> = vec![Counter::default(); N].into_boxed_slice();
        Counters(
            all.try_into()
                .unwrap_or_else(|_| unreachable!("N counters")),
        )
    }

    pub fn get(&self, i: usize) -> Counter {
        self.0[i & (N - 1)]
    }

    pub fn at(&mut self, i: usize) -> &mut Counter {
        &mut self.0[i & (N - 1)]
    }
}

/// The logistic function at x/2 for x = −16..=16, × 4096 (rounded):
/// `squash` interpolates it, steps of 128 in its argument.
const LOGISTIC: [i32; 33] = [
    1, 2, 4, 6, 10, 17, 27, 45, 74, 120, 194, 311, 488, 747, 1102, 1546, 2048, 2550, 2994, 3349,
    3608, 3785, 3902, 3976, 4022, 4051, 4069, 4079, 4086, 4090, 4092, 4094, 4095,
];

/// 4096 / (1 + e^(−x/256)) for x in −2047..=2047 (a probability in units
/// of 2^-12), linearly interpolated.
const fn squash(x: i32) -> i32 {
    if x > 2047 {
        return 4095;
    }
    if x < -2047 {
        return 1;
    }
    let w = x & 127;
    let i = ((x >> 7) + 16) as usize;
    (LOGISTIC[i] * (128 - w) + LOGISTIC[i + 1] * w + 64) >> 7
}

/// `STRETCH[p]`: the least x with squash(x) ≥ p (ln(p/(1 − p)) × 256).
static STRETCH: [i16; 4096] = {
    let mut t = [2047i16; 4096];
    let mut p = 0;
    let mut x = -2047;
    while x <= 2047 {
        let v = squash(x);
        while p <= v && p < 4096 {
            t[p as usize] = x as i16;
            p += 1;
        }
        x += 1;
    }
    t
};

/// `SQUASH[x + 2047]` = squash(x).
static SQUASH: [i16; 4095] = {
    let mut t = [0; 4095];
    let mut x = -2047;
    while x <= 2047 {
        t[(x + 2047) as usize] = squash(x) as i16;
        x += 1;
    }
    t
};

fn stretch(p1: u32) -> i32 {
    i32::from(STRETCH[p1 as usize & 4095])
}

/// Inputs mixed per bit.
pub(crate) const INPUTS: usize = 3;

/// Weights of the mix, 16.16 fixed point, one set per mixing context.
/// Weight sets of a [`Mixer`] (indices taken modulo: the callers' are
/// below 168).
pub(crate) const SETS: usize = 256;

pub(crate) struct Mixer {
    weights: Box<[[i32; INPUTS]; SETS]>,
    /// Per set, a secondary estimate of P(bit = 1) (16-bit) at 33 points
    /// of the mix's stretched probability, interpolated.
    refine: Box<[[u16; 33]; SETS]>,
}

/// One bit's mix, kept between predicting and learning.
pub(crate) struct Mix {
    set: usize,
    stretched: [i32; INPUTS],
    /// The mix's P(bit = 1), 12-bit.
    mixed: i32,
    /// The refinement's point below the mix and the weight of the one above.
    at: usize,
    above: i32,
    /// What the bit is coded with, 12-bit.
    p1: i32,
}

impl Mixer {
    pub fn new() -> Self {
        let weights: Box<[_]> = vec![[FIRST_WEIGHT; INPUTS]; SETS].into_boxed_slice();
        let first: [u16; 33] = std::array::from_fn(|j| (squash((j as i32 - 16) * 128) * 16) as u16);
        let refine: Box<[_]> = vec![first; SETS].into_boxed_slice();
        Mixer {
            weights: weights
                .try_into()
                .unwrap_or_else(|_| unreachable!("SETS sets")),
            refine: refine
                .try_into()
                .unwrap_or_else(|_| unreachable!("SETS sets")),
        }
    }

    /// The mixed P(bit = 1) of the counters in weight set `set`.
    pub fn predict(&self, set: usize, inputs: [Counter; INPUTS]) -> Mix {
        let set = set & (SETS - 1);
        let stretched = inputs.map(|c| stretch(c.p1()));
        let w = &self.weights[set];
        let dot: i64 = (0..INPUTS)
            .map(|i| i64::from(w[i]) * i64::from(stretched[i]))
            .sum();
        let x = (dot >> 16).clamp(-2047, 2047) as i32;
        // (x is in −2047..=2047: the masks only spare bounds checks.)
        let mixed = i32::from(SQUASH[((x + 2047) as usize).min(4094)]);
        let at = ((x + 2048) >> 7) as usize & 31;
        let above = (x + 2048) & 127;
        let t = &self.refine[set];
        let refined = (i32::from(t[at]) * (128 - above) + i32::from(t[at + 1]) * above) >> 11;
        let p1 = ((mixed + 3 * refined) >> 2).clamp(1, 4095);
        Mix {
            set,
            stretched,
            mixed,
            at,
            above,
            p1,
        }
    }

    /// Moves the weights towards what would have predicted `bit` better.
    pub fn learn(&mut self, mix: &Mix, bit: bool) {
        let err = (i32::from(bit) << 12) - mix.mixed;
        let t = &mut self.refine[mix.set];
        let target = if bit { 65535 } else { 0 };
        let near = (mix.at + usize::from(mix.above >= 64)).min(32);
        let v = i32::from(t[near]);
        t[near] = (v + ((target - v) >> REFINE_SHIFT)) as u16;
        let w = &mut self.weights[mix.set];
        for (w, &s) in w.iter_mut().zip(&mix.stretched) {
            // Clamped so that no stream (a hostile one included) can
            // overflow the dot product.
            *w = (*w + ((s * err) >> LEARNING_SHIFT)).clamp(-WEIGHT_LIMIT, WEIGHT_LIMIT);
        }
    }
}

impl Mix {
    /// The bit model the range coder codes this bit with.
    fn model(&self) -> BitModel {
        BitModel::with_p0_4096((4096 - self.p1) as u16)
    }

    pub fn encode(&self, enc: &mut RangeEncoder, bit: bool) {
        enc.encode_bit(&mut self.model(), bit);
    }

    pub fn decode(&self, dec: &mut RangeDecoder<'_>) -> bool {
        dec.decode_bit(&mut self.model())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stretch_inverts_squash() {
        for x in (-2047..=2047).step_by(7) {
            let p = squash(x) as u32;
            assert!((squash(stretch(p)) - p as i32).abs() <= 1, "{x}");
        }
        assert!(stretch(2048).abs() <= 1);
        assert!(stretch(100) < 0 && stretch(4000) > 0);
    }

    #[test]
    fn counters_learn_fast_then_settle() {
        let mut c = Counter::default();
        c.update(true);
        // The first bit moves it two thirds of the way: ½ → 5/6.
        assert_eq!(c.p1(), 5 * 4096 / 6);
        for _ in 0..200 {
            c.update(false);
        }
        assert!(c.p1() < 100);
        // Settled: one surprise moves it 1/31.5 of the way.
        let before = c.p1();
        c.update(true);
        assert!(c.p1() - before < 4096 / 28);
    }

    #[test]
    fn the_mix_follows_the_input_that_predicts() {
        // Input 0 always right, input 1 always wrong, the others unsure.
        let mut mixer = Mixer::new();
        let (mut right, mut wrong) = (Counter::default(), Counter::default());
        let mut bits = 0u32;
        for i in 0..2000 {
            let bit = i % 3 != 0;
            right.p1 = if bit { 60000 } else { 5000 };
            wrong.p1 = if bit { 5000 } else { 60000 };
            let unsure = Counter::default();
            let mix = mixer.predict(0, [right, wrong, unsure]);
            if i > 1000 {
                bits += u32::from((mix.p1 > 2048) == bit);
            }
            mixer.learn(&mix, bit);
        }
        assert!(bits > 990, "{bits}");
    }
}
