//! Room for a level's next vertices, reserved toward the stream's final size.
//!
//! A level's arrays (and the scratch's, sized to the level every pass) grow
//! batch by batch. Grown by doubling, each was copied every level or two,
//! and WebAssembly's allocator cannot remap a block as glibc does: igea-2m
//! decoded 0–5 % slower in WebAssembly and ended with a third more memory
//! (419 MiB against 309). The header's final count would let the decoder
//! reserve once, but the header is untrusted, so the decoder reserves
//! toward it no further than [`AHEAD`] times what the batch in hand verifies
//! (a bit of payload per vertex): a hostile header costs at most that
//! factor in memory.

/// How far past the verified size a level may reserve.
pub(crate) const AHEAD: usize = 4;

/// How big a level is expected to end: the stream's final vertex count
/// over the count now, applied to one level (the whole level or a chart).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Growth {
    pub now: usize,
    pub last: usize,
}

impl Growth {
    /// The expected final size of a level of `len` vertices now.
    /// In u64: on wasm32 a usize product of two vertex counts overflows.
    fn hint(self, len: usize) -> usize {
        if self.now == 0 {
            return len;
        }
        let hint = (len as u64).saturating_mul(self.last as u64) / self.now as u64;
        usize::try_from(hint).unwrap_or(usize::MAX)
    }

    /// Vertices to make room for in a level of `len` that a batch grows by
    /// `grow` (verified): the expected final size, held to `grow` at least
    /// and to [`AHEAD`] times the size after the batch at most.
    pub(crate) fn room(self, len: usize, grow: usize) -> (usize, usize) {
        let needed = len.saturating_add(grow);
        let target = self.hint(len).clamp(needed, needed.saturating_mul(AHEAD));
        (needed, target)
    }
}

/// Makes `v` able to hold `needed` items without moving, reserving for
/// `target` when it must move at all (`target >= needed`).
pub(crate) fn reserve<T>(v: &mut Vec<T>, needed: usize, target: usize) {
    if v.capacity() < needed {
        v.reserve_exact(target.max(needed) - v.len());
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reserves_toward_the_final_size_within_the_bound() {
        let g = Growth {
            now: 1_000,
            last: 3_000,
        };
        // A level of 1,000 vertices expected to end at 3,000.
        assert_eq!(g.room(1_000, 500), (1_500, 3_000));
        // A hostile header: a billion claimed, 100 verified.
        let hostile = Growth {
            now: 10,
            last: 1_000_000_000,
        };
        assert_eq!(hostile.room(10, 90), (100, 400));
        // A chart of a tenth of the level expects a tenth of the growth.
        assert_eq!(g.room(100, 10), (110, 300));
        // Counts whose product overflows 32 bits (a usize on wasm32).
        let big = Growth {
            now: 100_000,
            last: 2_000_000,
        };
        assert_eq!(big.room(100_000, 100_000), (200_000, 800_000));
        // Never less than the batch needs.
        let shrinking = Growth {
            now: 1_000,
            last: 10,
        };
        assert_eq!(shrinking.room(1_000, 7), (1_007, 1_007));
    }

    #[test]
    fn reserve_moves_only_when_it_must() {
        let mut v: Vec<u32> = Vec::with_capacity(8);
        v.extend([1, 2, 3]);
        reserve(&mut v, 8, 100);
        assert_eq!(v.capacity(), 8);
        reserve(&mut v, 9, 100);
        assert!(v.capacity() >= 100);
        assert_eq!(v, [1, 2, 3]);
    }
}
