//! Adaptive coding of integers of any magnitude (Elias-gamma style buckets).

use super::bit::BitModel;
use super::coder::{RangeDecoder, RangeEncoder};
use super::symbol::SymbolModel;

/// Buckets: bit length of `u + 1` for `u` in `0..=u32::MAX`, i.e. `1..=33`.
const BUCKETS: usize = 33;

/// Adaptive model for integers: first the bucket `k` (bit length of the
/// value + 1, one of 33, coded with a [`SymbolModel`]), then the `k - 1` bits
/// below the leading one: the top two with [`BitModel`]s chosen by bucket
/// (the second also by the first), the rest raw.
///
/// Signed values are zigzag-mapped first (0, -1, 1, -2, … → 0, 1, 2, 3, …),
/// so small magnitudes of either sign are cheap. The full `i32` and `u32`
/// ranges are supported.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct IntModel {
    buckets: SymbolModel,
    /// Per bucket: [first bit, second bit after a 0, second bit after a 1].
    top_bits: [[BitModel; 3]; BUCKETS],
}

impl Default for IntModel {
    fn default() -> Self {
        Self::new()
    }
}

impl IntModel {
    /// A fresh model (all buckets equally likely).
    pub fn new() -> Self {
        IntModel {
            buckets: SymbolModel::new(BUCKETS),
            top_bits: [[BitModel::new(); 3]; BUCKETS],
        }
    }
}

impl IntModel {
    /// What [`RangeEncoder::encode_int`] of `v` costs now, in bits, and the
    /// model updated as coding it would (for measurements: nothing is
    /// written).
    pub fn meter(&mut self, v: i32) -> f64 {
        let u = u64::from(zigzag(v)) + 1;
        let k = 64 - u.leading_zeros();
        let bucket = (k - 1) as usize;
        let mut bits = self.buckets.meter(bucket);
        let nb = k - 1;
        if nb == 0 {
            return bits;
        }
        let ctx = &mut self.top_bits[bucket];
        let b1 = (u >> (nb - 1)) & 1 != 0;
        bits += ctx[0].meter(b1);
        if nb == 1 {
            return bits;
        }
        let b2 = (u >> (nb - 2)) & 1 != 0;
        bits += ctx[1 + usize::from(b1)].meter(b2);
        bits + f64::from(nb.saturating_sub(2))
    }
}

#[inline(always)]
fn zigzag(v: i32) -> u32 {
    ((v << 1) ^ (v >> 31)) as u32
}

#[inline(always)]
fn unzigzag(z: u32) -> i32 {
    ((z >> 1) as i32) ^ ((z & 1) as i32).wrapping_neg()
}

impl RangeEncoder {
    /// Code a signed integer with an adaptive [`IntModel`].
    #[inline]
    pub fn encode_int(&mut self, model: &mut IntModel, v: i32) {
        self.encode_uint(model, zigzag(v));
    }

    /// Code an unsigned integer with an adaptive [`IntModel`] (no zigzag).
    #[inline]
    pub fn encode_uint(&mut self, model: &mut IntModel, v: u32) {
        let u = u64::from(v) + 1; // 1..=2^32
        let k = 64 - u.leading_zeros(); // 1..=33
        let bucket = (k - 1) as usize;
        self.encode_symbol(&mut model.buckets, bucket);
        let nb = k - 1; // bits below the leading one
        if nb == 0 {
            return;
        }
        let ctx = &mut model.top_bits[bucket];
        let b1 = (u >> (nb - 1)) & 1 != 0;
        self.encode_bit(&mut ctx[0], b1);
        if nb == 1 {
            return;
        }
        let b2 = (u >> (nb - 2)) & 1 != 0;
        self.encode_bit(&mut ctx[1 + usize::from(b1)], b2);
        if nb > 2 {
            let rest = nb - 2; // 1..=30
            self.encode_raw((u & ((1 << rest) - 1)) as u32, rest);
        }
    }
}

impl RangeDecoder<'_> {
    /// Decode a signed integer coded with [`RangeEncoder::encode_int`].
    #[inline]
    pub fn decode_int(&mut self, model: &mut IntModel) -> i32 {
        unzigzag(self.decode_uint(model))
    }

    /// Decode an unsigned integer coded with [`RangeEncoder::encode_uint`].
    /// Corrupt input yields some value, never a panic.
    #[inline]
    pub fn decode_uint(&mut self, model: &mut IntModel) -> u32 {
        let bucket = self.decode_symbol(&mut model.buckets); // < 33
        let nb = bucket as u32;
        if nb == 0 {
            return 0;
        }
        let ctx = &mut model.top_bits[bucket];
        let b1 = self.decode_bit(&mut ctx[0]);
        let mut u = 2 | u64::from(b1);
        if nb >= 2 {
            let b2 = self.decode_bit(&mut ctx[1 + usize::from(b1)]);
            u = (u << 1) | u64::from(b2);
            if nb > 2 {
                let rest = nb - 2;
                u = (u << rest) | u64::from(self.decode_raw(rest));
            }
        }
        // Only corrupt input reaches u - 1 >= 2^32; truncation is fine then.
        (u - 1) as u32
    }
}

#[cfg(test)]
mod int_tests {
    use super::*;

    #[test]
    fn entropy_zigzag_is_a_bijection_on_extremes() {
        for v in [
            0,
            -1,
            1,
            -2,
            2,
            i32::MAX,
            i32::MIN,
            i32::MIN + 1,
            i32::MAX - 1,
        ] {
            assert_eq!(unzigzag(zigzag(v)), v);
        }
        assert_eq!(zigzag(0), 0);
        assert_eq!(zigzag(-1), 1);
        assert_eq!(zigzag(1), 2);
        assert_eq!(zigzag(i32::MIN), u32::MAX);
    }

    #[test]
    fn entropy_int_extremes_round_trip() {
        let mut vals = vec![0, 1, -1, 2, -2, 3, -3, i32::MAX, i32::MIN, i32::MIN + 1];
        for s in 0..31 {
            let p = 1i32 << s;
            vals.extend([p, -p, p - 1, 1 - p, p.wrapping_add(1), -(p.wrapping_add(1))]);
        }
        let uvals = [0, 1, 2, 3, u32::MAX, u32::MAX - 1, 1 << 31, (1 << 31) - 1];
        let mut enc = RangeEncoder::new();
        let mut m = IntModel::new();
        let mut mu = IntModel::new();
        for &v in &vals {
            enc.encode_int(&mut m, v);
        }
        for &u in &uvals {
            enc.encode_uint(&mut mu, u);
        }
        let bytes = enc.finish();
        let mut dec = RangeDecoder::new(&bytes);
        let mut m = IntModel::new();
        let mut mu = IntModel::new();
        for &v in &vals {
            assert_eq!(dec.decode_int(&mut m), v);
        }
        for &u in &uvals {
            assert_eq!(dec.decode_uint(&mut mu), u);
        }
        dec.check_overrun().unwrap();
    }

    #[test]
    fn entropy_int_small_values_are_cheap() {
        // Mostly zeros and ±1: the adaptive buckets should get close to the
        // source entropy (~1.37 bits for this mix), far below a fixed code.
        let mut x = 0x0123_4567_89AB_CDEF_u64;
        let vals: Vec<i32> = (0..50_000)
            .map(|_| {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                match x % 10 {
                    0..=5 => 0,
                    6 | 7 => 1,
                    _ => -1,
                }
            })
            .collect();
        let mut enc = RangeEncoder::new();
        let mut m = IntModel::new();
        for &v in &vals {
            enc.encode_int(&mut m, v);
        }
        let bytes = enc.finish();
        let h = -(0.6f64 * 0.6f64.log2() + 2.0 * 0.2 * 0.2f64.log2());
        let coded_per = bytes.len() as f64 * 8.0 / vals.len() as f64;
        assert!(coded_per < h * 1.03, "{coded_per} bits/value vs {h}");
    }
}
