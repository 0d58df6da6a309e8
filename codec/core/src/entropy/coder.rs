//! The range coder itself: encoder/decoder state, normalisation, carry
//! propagation and raw (equiprobable) bits. The model-specific steps live
//! beside their models (`bit.rs`, `symbol.rs`, `int.rs`).

use crate::{Error, Result};

/// Renormalise whenever `range` drops below this (one byte is shifted out).
pub(super) const TOP: u32 = 1 << 24;

/// Widest chunk of raw bits coded in one range-coder step.
const RAW_CHUNK: u32 = 16;

/// Range encoder: code values with the `encode_*` methods, then
/// [`finish`](Self::finish).
#[derive(Clone, Debug)]
pub struct RangeEncoder {
    /// Lower end of the interval; bit 32 is a pending carry.
    pub(super) low: u64,
    pub(super) range: u32,
    /// The last byte shifted out of `low`, not yet written (a carry may still
    /// change it).
    cache: u8,
    /// `cache` plus the number of pending `0xFF` bytes behind it.
    cache_size: u64,
    out: Vec<u8>,
    #[cfg(test)]
    pub(super) stats: CarryStats,
}

/// Test-only counters showing that carry propagation is exercised.
#[cfg(test)]
#[derive(Clone, Debug, Default)]
pub(super) struct CarryStats {
    /// How many times a carry rippled into written bytes.
    pub carries: u64,
    /// The longest run of pending bytes a carry rippled through.
    pub longest_carry_chain: u64,
    /// The longest run of pending bytes seen at all.
    pub longest_pending: u64,
}

impl Default for RangeEncoder {
    fn default() -> Self {
        Self::new()
    }
}

impl RangeEncoder {
    /// An encoder with an empty output buffer.
    pub fn new() -> Self {
        Self::with_capacity(0)
    }

    /// An encoder whose output buffer starts with room for `bytes` bytes.
    pub fn with_capacity(bytes: usize) -> Self {
        RangeEncoder {
            low: 0,
            range: u32::MAX,
            cache: 0,
            cache_size: 1,
            out: Vec::with_capacity(bytes),
            #[cfg(test)]
            stats: CarryStats::default(),
        }
    }

    /// About how many bytes [`finish`](Self::finish) would return now (an
    /// upper bound: the flush may drop a few trailing zero bytes).
    pub fn len_estimate(&self) -> usize {
        self.out
            .len()
            .saturating_add(usize::try_from(self.cache_size).unwrap_or(usize::MAX))
            .saturating_add(4)
    }

    /// Shift the top byte out of `low`, resolving or deferring the carry.
    /// Runs once per output byte; kept out of line so that the per-symbol
    /// `encode_*` steps stay small enough to inline.
    #[inline(never)]
    pub(super) fn shift_low(&mut self) {
        if self.low < 0xFF00_0000 || self.low > 0xFFFF_FFFF {
            // The byte in `cache` (and the 0xFF run behind it) is now final.
            let carry = (self.low >> 32) as u8;
            #[cfg(test)]
            if carry != 0 {
                self.stats.carries += 1;
                self.stats.longest_carry_chain =
                    self.stats.longest_carry_chain.max(self.cache_size);
            }
            let mut byte = self.cache;
            loop {
                self.out.push(byte.wrapping_add(carry));
                byte = 0xFF;
                self.cache_size -= 1;
                if self.cache_size == 0 {
                    break;
                }
            }
            self.cache = (self.low >> 24) as u8;
        }
        self.cache_size += 1;
        #[cfg(test)]
        {
            self.stats.longest_pending = self.stats.longest_pending.max(self.cache_size);
        }
        self.low = (self.low & 0x00FF_FFFF) << 8;
    }

    /// Renormalise after a step that may have shrunk `range` by more than
    /// one byte.
    #[inline]
    pub(super) fn normalize(&mut self) {
        while self.range < TOP {
            self.range <<= 8;
            self.shift_low();
        }
    }

    /// Code `nbits` (0..=32) equiprobable bits: the low `nbits` of `value`.
    #[inline]
    pub fn encode_raw(&mut self, value: u32, nbits: u32) {
        assert!(nbits <= 32, "encode_raw: at most 32 bits at once");
        if nbits > RAW_CHUNK {
            self.encode_raw_chunk(value >> RAW_CHUNK, nbits - RAW_CHUNK);
            self.encode_raw_chunk(value & 0xFFFF, RAW_CHUNK);
        } else if nbits > 0 {
            self.encode_raw_chunk(value, nbits);
        }
    }

    #[inline]
    fn encode_raw_chunk(&mut self, value: u32, nbits: u32) {
        debug_assert!((1..=RAW_CHUNK).contains(&nbits));
        let value = value & ((1 << nbits) - 1);
        self.range >>= nbits;
        self.low += u64::from(self.range) * u64::from(value);
        self.normalize();
    }

    /// Flush the coder and return the coded bytes.
    pub fn finish(mut self) -> Vec<u8> {
        // Any value in [low, low + range) decodes the same; take the one with
        // the most trailing zero bits (range >= 2^24, so at least 24 of them).
        let end = self.low + u64::from(self.range);
        for shift in (0..=32).rev() {
            let mask = (1u64 << shift) - 1;
            let v = (self.low + mask) & !mask;
            if v < end {
                self.low = v;
                break;
            }
        }
        for _ in 0..5 {
            self.shift_low();
        }
        // The first byte is LZMA's initial cache byte, always 0 (the coded
        // value is below 1, so no carry reaches it): the decoder implies it.
        debug_assert_eq!(self.out.first(), Some(&0));
        self.out.remove(0);
        // The decoder reads missing bytes as zeros and tolerates 4 of them.
        for _ in 0..4 {
            if self.out.last() == Some(&0) {
                self.out.pop();
            } else {
                break;
            }
        }
        self.out
    }
}

/// Range decoder over a byte slice. Reading past the end yields zero bytes;
/// [`check_overrun`](Self::check_overrun) tells whether that went further
/// than a well-formed stream ever needs.
#[derive(Clone, Debug)]
pub struct RangeDecoder<'a> {
    bytes: &'a [u8],
    /// Index of the next byte to read; may exceed `bytes.len()`.
    pos: usize,
    pub(super) range: u32,
    pub(super) code: u32,
}

impl<'a> RangeDecoder<'a> {
    /// Start decoding `bytes` (as returned by [`RangeEncoder::finish`]; an
    /// empty slice is the empty stream).
    pub fn new(bytes: &'a [u8]) -> Self {
        let mut dec = RangeDecoder {
            bytes,
            pos: 0,
            range: u32::MAX,
            code: 0,
        };
        for _ in 0..4 {
            dec.code = (dec.code << 8) | u32::from(dec.next_byte());
        }
        dec
    }

    /// Err if more than 4 bytes past the end of the input were needed, i.e.
    /// the payload was truncated (or decoded with the wrong models).
    pub fn check_overrun(&self) -> Result<()> {
        if self.pos.saturating_sub(self.bytes.len()) > 4 {
            Err(Error::stream("truncated entropy-coded payload"))
        } else {
            Ok(())
        }
    }

    #[inline(always)]
    fn next_byte(&mut self) -> u8 {
        let b = self.bytes.get(self.pos).copied().unwrap_or(0);
        self.pos = self.pos.saturating_add(1);
        b
    }

    /// Shift one byte into `code`.
    #[inline(always)]
    pub(super) fn shift_in(&mut self) {
        self.range <<= 8;
        self.code = (self.code << 8) | u32::from(self.next_byte());
    }

    #[inline]
    pub(super) fn normalize(&mut self) {
        while self.range < TOP {
            self.shift_in();
        }
    }

    /// Decode `nbits` (0..=32) equiprobable bits.
    #[inline]
    pub fn decode_raw(&mut self, nbits: u32) -> u32 {
        assert!(nbits <= 32, "decode_raw: at most 32 bits at once");
        if nbits > RAW_CHUNK {
            let hi = self.decode_raw_chunk(nbits - RAW_CHUNK);
            (hi << RAW_CHUNK) | self.decode_raw_chunk(RAW_CHUNK)
        } else if nbits > 0 {
            self.decode_raw_chunk(nbits)
        } else {
            0
        }
    }

    #[inline]
    fn decode_raw_chunk(&mut self, nbits: u32) -> u32 {
        debug_assert!((1..=RAW_CHUNK).contains(&nbits));
        self.range >>= nbits;
        // `min` only matters for corrupt input, where code >= range.
        let v = (self.code / self.range).min((1 << nbits) - 1);
        self.code -= v * self.range;
        self.normalize();
        v
    }
}

#[cfg(test)]
mod coder_tests {
    use super::*;

    #[test]
    fn entropy_empty_stream_is_empty() {
        let bytes = RangeEncoder::new().finish();
        assert_eq!(bytes, Vec::<u8>::new());
        let dec = RangeDecoder::new(&bytes);
        dec.check_overrun().unwrap();
    }

    #[test]
    fn entropy_leading_zero_byte_is_implied() {
        // The same symbols decode from the stream whatever its first byte
        // was: nothing is written for LZMA's initial cache byte.
        let mut enc = RangeEncoder::new();
        enc.encode_raw(0xABCD, 16);
        let bytes = enc.finish();
        assert_eq!(bytes[0], 0xAB, "{bytes:?}");
        let mut dec = RangeDecoder::new(&bytes);
        assert_eq!(dec.decode_raw(16), 0xABCD);
        dec.check_overrun().unwrap();
    }

    #[test]
    fn entropy_raw_bits_round_trip_all_widths() {
        let mut enc = RangeEncoder::new();
        let mut expect = Vec::new();
        let mut x = 0x1234_5678_9abc_def0_u64;
        for i in 0..20_000u32 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let n = i % 33;
            let v = (x as u32) & if n == 32 { u32::MAX } else { (1 << n) - 1 };
            enc.encode_raw(v, n);
            expect.push((v, n));
        }
        let bytes = enc.finish();
        let mut dec = RangeDecoder::new(&bytes);
        for &(v, n) in &expect {
            assert_eq!(dec.decode_raw(n), v, "width {n}");
        }
        dec.check_overrun().unwrap();
        // Raw bits cost (almost) exactly their width.
        let total_bits: u64 = expect.iter().map(|&(_, n)| u64::from(n)).sum();
        assert!((bytes.len() as u64 * 8) < total_bits + total_bits / 200 + 64);
    }

    #[test]
    fn entropy_raw_masks_excess_value_bits() {
        let mut enc = RangeEncoder::new();
        enc.encode_raw(0xFFFF_FFFF, 3);
        enc.encode_raw(0x1_0005, 16);
        let bytes = enc.finish();
        let mut dec = RangeDecoder::new(&bytes);
        assert_eq!(dec.decode_raw(3), 7);
        assert_eq!(dec.decode_raw(16), 5);
    }

    #[test]
    fn entropy_len_estimate_bounds_output() {
        let mut enc = RangeEncoder::new();
        for i in 0..5000u32 {
            enc.encode_raw(i.wrapping_mul(2_654_435_761), 13);
        }
        let est = enc.len_estimate();
        let len = enc.finish().len();
        assert!(len <= est && est <= len + 8, "{len} vs {est}");
    }
}
