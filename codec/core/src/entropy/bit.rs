//! Adaptive binary model and its coding step.

use super::coder::{RangeDecoder, RangeEncoder, TOP};

/// Probability precision in bits.
const PROB_BITS: u32 = 12;
const PROB_ONE: u16 = 1 << PROB_BITS;
/// Adaptation rate: each coded bit moves the estimate 1/2^ADAPT_SHIFT of the
/// way towards what was seen. 5 beat 4 on every source tried (stationary,
/// mixed contexts, and one switching its skew every 3000 bits): 4 adapts
/// faster, but its noisier estimate cost 2–6 % more.
const ADAPT_SHIFT: u32 = 5;

/// Adaptive binary model (LZMA style): a 12-bit estimate of P(bit = 0),
/// updated after every coded bit. Starts at P = 0.5.
///
/// The estimate stays within [31, 4065] / 4096, so a certain bit costs at
/// least ~0.011 bits and an "impossible" one at most ~7 bits.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BitModel {
    /// P(bit = 0) in units of 2^-12.
    p0: u16,
}

impl Default for BitModel {
    fn default() -> Self {
        Self::new()
    }
}

impl BitModel {
    /// A model with P(0) = P(1) = 0.5.
    pub const fn new() -> Self {
        BitModel { p0: PROB_ONE / 2 }
    }

    /// A model starting from a prior: P(bit = 0) = `p0` / 4096, clamped to
    /// the range an adaptive estimate can reach.
    pub const fn with_p0_4096(p0: u16) -> Self {
        let p0 = if p0 < 31 {
            31
        } else if p0 > 4065 {
            4065
        } else {
            p0
        };
        BitModel { p0 }
    }

    /// The current estimate of P(bit = 1), in units of 2^-12 (for tests and
    /// cost estimates).
    pub fn p1_4096(self) -> u32 {
        u32::from(PROB_ONE - self.p0)
    }

    /// What coding `bit` costs now, in bits, and the model updated as
    /// coding it would (for measurements: nothing is written).
    pub fn meter(&mut self, bit: bool) -> f64 {
        let p = if bit { PROB_ONE - self.p0 } else { self.p0 };
        self.update(bit);
        -(f64::from(p) / f64::from(PROB_ONE)).log2()
    }

    #[inline(always)]
    fn update(&mut self, bit: bool) {
        if bit {
            self.p0 -= self.p0 >> ADAPT_SHIFT;
        } else {
            self.p0 += (PROB_ONE - self.p0) >> ADAPT_SHIFT;
        }
    }
}

impl RangeEncoder {
    /// Code one bit with an adaptive model (and update the model).
    #[inline]
    pub fn encode_bit(&mut self, model: &mut BitModel, bit: bool) {
        let bound = (self.range >> PROB_BITS) * u32::from(model.p0);
        if bit {
            self.low += u64::from(bound);
            self.range -= bound;
        } else {
            self.range = bound;
        }
        model.update(bit);
        // Both sub-ranges are >= 2^12 * 31 > 2^16: one shift always suffices.
        if self.range < TOP {
            self.range <<= 8;
            self.shift_low();
        }
    }
}

impl RangeDecoder<'_> {
    /// Decode one bit coded with [`RangeEncoder::encode_bit`] (and update the
    /// model the same way).
    #[inline]
    pub fn decode_bit(&mut self, model: &mut BitModel) -> bool {
        let bound = (self.range >> PROB_BITS) * u32::from(model.p0);
        let bit = self.code >= bound;
        if bit {
            self.code -= bound;
            self.range -= bound;
        } else {
            self.range = bound;
        }
        model.update(bit);
        if self.range < TOP {
            self.shift_in();
        }
        bit
    }
}

#[cfg(test)]
mod bit_tests {
    use super::*;

    fn splitmix(state: &mut u64) -> u64 {
        *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = *state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    fn entropy_bits(p: f64) -> f64 {
        -(p * p.log2() + (1.0 - p) * (1.0 - p).log2())
    }

    /// Code `n` bits with P(1) = p1_millionths / 10^6; returns (bits, coded bytes).
    fn code_bernoulli(p1_millionths: u64, n: usize, seed: u64) -> (Vec<bool>, Vec<u8>) {
        let mut s = seed;
        let bits: Vec<bool> = (0..n)
            .map(|_| splitmix(&mut s) % 1_000_000 < p1_millionths)
            .collect();
        let mut enc = RangeEncoder::new();
        let mut m = BitModel::default();
        for &b in &bits {
            enc.encode_bit(&mut m, b);
        }
        (bits, enc.finish())
    }

    #[test]
    fn entropy_bit_p005_within_5_percent_of_shannon() {
        let n = 100_000;
        let (bits, bytes) = code_bernoulli(50_000, n, 7);
        let mut dec = RangeDecoder::new(&bytes);
        let mut m = BitModel::default();
        for &b in &bits {
            assert_eq!(dec.decode_bit(&mut m), b);
        }
        dec.check_overrun().unwrap();
        // Against the entropy of the sample's own frequency (a static coder
        // that knew it in advance could not do better) and of p = 0.05.
        let ones = bits.iter().filter(|&&b| b).count() as f64;
        let h_sample = entropy_bits(ones / n as f64) * n as f64;
        let h_true = entropy_bits(0.05) * n as f64;
        let coded = bytes.len() as f64 * 8.0;
        assert!(
            coded <= 1.05 * h_sample,
            "coded {coded} vs sample entropy {h_sample}"
        );
        assert!(coded <= 1.05 * h_true, "coded {coded} vs entropy {h_true}");
    }

    #[test]
    fn entropy_bit_model_tracks_skew_both_ways() {
        for (p1, seed) in [(10_000u64, 1u64), (500_000, 2), (990_000, 3), (200_000, 4)] {
            let n = 50_000;
            let (bits, bytes) = code_bernoulli(p1, n, seed);
            let h = entropy_bits(p1 as f64 / 1e6) * n as f64;
            let coded = bytes.len() as f64 * 8.0;
            // p = 0.01 / 0.99 is near the 12-bit floor; allow a bit more.
            assert!(coded <= 1.12 * h + 64.0, "p1 {p1}: coded {coded} vs {h}");
            let mut dec = RangeDecoder::new(&bytes);
            let mut m = BitModel::default();
            assert!(bits.iter().all(|&b| dec.decode_bit(&mut m) == b));
            dec.check_overrun().unwrap();
        }
    }

    #[test]
    fn entropy_bit_model_probability_stays_in_bounds() {
        let mut m = BitModel::new();
        for _ in 0..1000 {
            m.update(true);
        }
        assert_eq!(m.p1_4096(), 4096 - 31);
        for _ in 0..1000 {
            m.update(false);
        }
        assert_eq!(m.p1_4096(), 31);
    }
}
