//! Neighbour-dependent occupancy contexts (stream version 2, `FORMAT.md`
//! "Version 2"), after the octree occupancy coding of MPEG G-PCC (ISO/IEC
//! 23090-9), whose contexts depend on occupied neighbours: a child's bit is
//! coded with a model chosen by what the decoder already knows around it —
//! the occupied cells of the 3×3×3 block around the parent at the parent's
//! depth (all cells of a depth are known before any of their children),
//! through the plane fitted to them and the face neighbours on the child's
//! sides, and the child's neighbours on its −x, −y, −z sides (earlier bits
//! of the same mask, or children of cells earlier in Morton order, which
//! decrementing a coordinate always gives).
//!
//! The plane matters most: below the depths where the surface fills its
//! cells, a cell usually holds one point, and which child holds it is
//! predictable only across the surface, from where the neighbours put it.

/// Context classes where a cell has a known neighbour: the child's index
/// (8) × bits set so far in the mask (0, 1, 2+) × the child's distance
/// class from the neighbourhood's plane (5) × the child's coded face
/// neighbours (8) × occupied parent neighbours on the child's sides (0..=3).
pub(crate) const CONTEXTS: usize = 8 * 3 * 5 * 8 * 4;

/// Version 3's plane classes: 0 (no plane), then 1 + the thresholds e/8,
/// e = 1..=5, that the child's distance reaches.
pub(crate) const PLANES_V3: usize = 7;

/// Version 3's context classes: version 2's with `PLANES_V3` plane classes.
pub(crate) const CONTEXTS_V3: usize = 8 * 3 * PLANES_V3 * 8 * 4;

/// What is known around one cell when its children are coded
/// (`Neighbourhood::around` in `neighbourhood.rs`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct Around {
    /// Bit `2a + s`: the face neighbour on axis `a`, side `s` (0: −, 1: +)
    /// is occupied.
    pub faces: u8,
    /// Child masks of the cells at −e_a (a = x, y, z).
    pub minus: [u8; 3],
    /// A cell at −e_a − e_b (for some a ≠ b) is occupied.
    pub minus_edge: bool,
    /// Each child's distance class from the block's plane (`Block`).
    pub plane: [u8; 8],
}

/// The occupied cells of a 3×3×3 block (version 3: the points of
/// `plane_bins_quarters`): count and moments of their offsets
/// (the centre cell counted, at offset 0).
#[derive(Debug, Default, PartialEq, Eq)]
pub(crate) struct Block {
    /// Occupied cells other than the centre.
    pub count: i64,
    /// Σ δ_a over them.
    pub sum: [i64; 3],
    /// Σ δ_a δ_b over them.
    pub products: [[i64; 3]; 3],
}

impl Block {
    #[cfg(test)]
    pub fn add(&mut self, d: [i32; 3]) {
        self.count += 1;
        for a in 0..3 {
            self.sum[a] += i64::from(d[a]);
            for b in 0..3 {
                self.products[a][b] += i64::from(d[a] * d[b]);
            }
        }
    }

    /// For each child, how far its centre lies from the plane fitted to
    /// the block's cells: 0 without a plane (fewer than 3 other cells, or
    /// collinear), else 1..=4 for |distance| in parent cells below 1/8,
    /// 2/8, 3/8, above. Integer arithmetic only (the decoder in WebAssembly
    /// must agree bit for bit).
    ///
    /// `FORMAT.md` states the computation in 64- and 128-bit integers; with
    /// offsets in {−1, 0, 1} and at most 27 cells nothing here leaves 64
    /// bits: |C_ab| ≤ 27 · 18 = 486, a cofactor is below 2 · 486² < 2^19
    /// (so the normal is never shifted: 2^24 is its threshold), Σ F_ij² <
    /// 2^40, |t| < 3 · 2^19 · 63 < 2^27 and 4t² < 2^56.
    pub fn plane_bins(&self) -> [u8; 8] {
        let Some((normal, len2)) = self.normal() else {
            return [0; 8];
        };
        debug_assert!(normal.iter().all(|v| v.abs() < 1 << 24), "never shifted");
        self.bins::<3, 4>(normal, len2)
    }

    /// Version 3: [`plane_bins`](Self::plane_bins) of points given in
    /// quarters of a cell (up to 504 besides the centre, coordinates in
    /// −9..=9: |C_ab| < 2^26, so the cofactors stay below 2^53 before
    /// `normal`'s shift), the normal shifted below 2^12 first: then
    /// |t| < 3 · 2^12 · (505 + 4545) < 2^26 and 4t² < 2^54.
    pub fn plane_bins_quarters(&self) -> [u8; 8] {
        let Some((normal, _)) = self.normal() else {
            return [0; 8];
        };
        let big = normal.iter().fold(0u64, |m, v| m.max(v.unsigned_abs()));
        let shift = (64 - big.leading_zeros()).saturating_sub(12);
        let normal = normal.map(|v| v >> shift);
        let len2 = normal.iter().map(|v| v * v).sum::<i64>();
        if len2 == 0 {
            return [0; 8];
        }
        self.bins::<{ PLANES_V3 - 2 }, 1>(normal, len2)
    }

    /// Classes 1 + the thresholds e/8 (e = 1..=`T`) that the child's
    /// distance reaches; offsets in cells (`SCALE` 4) or quarters (1).
    fn bins<const T: usize, const SCALE: i64>(&self, normal: [i64; 3], len2: i64) -> [u8; 8] {
        let n = self.count + 1;
        let [s0, s1, s2] = self.sum;
        // 4n × (child centre − centroid) · normal, in parent cells (child
        // centres at ±1/4, ±1 quarter): Σ_a normal_a (±n − SCALE · S_a);
        // child 7 − k has the opposite signs.
        let [q0, q1, q2] = normal.map(|v| v * n);
        let centroid = SCALE * (normal[0] * s0 + normal[1] * s1 + normal[2] * s2);
        // |dist| / (4n |normal|) against e/8: 4 dist² vs e² n² |normal|².
        let unit = n * n * len2;
        let limits: [i64; T] = std::array::from_fn(|e| (e as i64 + 1).pow(2) * unit);
        let class = |dist: i64| {
            let lhs = 4 * dist * dist;
            1 + limits.iter().map(|&l| u8::from(lhs >= l)).sum::<u8>()
        };
        let mut bins = [0u8; 8];
        for (k, side) in [-q0 - q1 - q2, q0 - q1 - q2, -q0 + q1 - q2, q0 + q1 - q2]
            .into_iter()
            .enumerate()
        {
            bins[k] = class(side - centroid);
            bins[7 - k] = class(-side - centroid);
        }
        bins
    }

    /// The normal of the plane fitted to the block's cells (the centre's
    /// included) and its squared length, unnormalized (components below
    /// 2^19, see [`plane_bins`](Self::plane_bins)); `None` with fewer
    /// than 3 other cells or all of them on one line.
    pub fn normal(&self) -> Option<([i64; 3], i64)> {
        let n = self.count + 1;
        if self.count < 3 {
            return None;
        }
        debug_assert!(self.count <= 504);
        let [s0, s1, s2] = self.sum;
        let p = &self.products;
        // n² × the covariance; its adjugate's largest row is along the
        // normal of a planar set.
        let c00 = n * p[0][0] - s0 * s0;
        let c11 = n * p[1][1] - s1 * s1;
        let c22 = n * p[2][2] - s2 * s2;
        let c01 = n * p[0][1] - s0 * s1;
        let c02 = n * p[0][2] - s0 * s2;
        let c12 = n * p[1][2] - s1 * s2;
        // The adjugate (symmetric): F_ij = C_{i+1,j+1} C_{i+2,j+2} −
        // C_{i+1,j+2} C_{i+2,j+1}.
        let f00 = c11 * c22 - c12 * c12;
        let f11 = c00 * c22 - c02 * c02;
        let f22 = c00 * c11 - c01 * c01;
        let f01 = c12 * c02 - c01 * c22;
        let f02 = c01 * c12 - c11 * c02;
        let f12 = c02 * c01 - c12 * c00;
        // Version 3's points (`plane_bins_quarters`) bring a cofactor up
        // to 2^53: shifted below 2^30 so that the rows' norms stay within
        // 64 bits (never for version 2's 26 cells, below 2^19).
        let big = [f00, f11, f22, f01, f02, f12]
            .iter()
            .fold(0u64, |m, v| m.max(v.unsigned_abs()));
        let shift = (64 - big.leading_zeros()).saturating_sub(30);
        let [f00, f11, f22, f01, f02, f12] = [f00, f11, f22, f01, f02, f12].map(|v| v >> shift);
        // The row with the largest norm, of equal ones the last.
        let (l0, l1, l2) = (
            f00 * f00 + f01 * f01 + f02 * f02,
            f01 * f01 + f11 * f11 + f12 * f12,
            f02 * f02 + f12 * f12 + f22 * f22,
        );
        let (normal, len2) = if l2 >= l1 && l2 >= l0 {
            ([f02, f12, f22], l2)
        } else if l1 >= l0 {
            ([f01, f11, f12], l1)
        } else {
            ([f00, f01, f02], l0)
        };
        (len2 != 0).then_some((normal, len2))
    }
}

impl Around {
    /// Whether no neighbour the context looks at is occupied (then the
    /// stream falls back to version 1's contexts).
    pub fn is_empty(&self) -> bool {
        self.faces == 0 && !self.minus_edge && self.plane == [0; 8]
    }

    /// The context of child `k` when the mask's bits below `k` are
    /// `so_far` (`FORMAT.md`); what [`contexts`](Self::contexts) and
    /// `CODED` compute in parts.
    #[cfg(test)]
    pub fn context(&self, k: u32, so_far: u8) -> usize {
        let mut near = 0;
        let mut face = 0usize;
        for a in 0..3u32 {
            let side = (k >> a) & 1;
            near += usize::from((self.faces >> (2 * a + side)) & 1);
            let f = if side == 1 {
                so_far >> (k ^ (1 << a))
            } else {
                self.minus[a as usize] >> (k | (1 << a))
            };
            face |= usize::from(f & 1) << a;
        }
        let set = (so_far.count_ones() as usize).min(2);
        let plane = usize::from(self.plane[k as usize]);
        (((k as usize * 3 + set) * 5 + plane) * 8 + face) * 4 + near
    }

    /// Per child k, the part of its context that the mask's earlier bits do
    /// not change: child index, plane class, near faces and the face bits
    /// on its low sides (from the −e_a neighbours' masks). Child k's
    /// context is `contexts()[k] + CODED[k][so_far]`.
    pub fn contexts(&self) -> [u16; 8] {
        self.contexts_with(self.plane, 5)
    }

    /// Version 3's [`contexts`](Self::contexts) (`PLANES_V3` plane
    /// classes); child k's context is `contexts_v3()[k] +
    /// CODED_V3[k][so_far]`.
    pub fn contexts_v3(&self) -> [u16; 8] {
        self.contexts_with(self.plane, PLANES_V3 as u16)
    }

    fn contexts_with(&self, plane: [u8; 8], planes: u16) -> [u16; 8] {
        // Byte k: child k's near faces; its face bits from the −e_a
        // neighbours' masks (for the k on the low side of axis a: bit
        // k + 2^a of minus[a]).
        let near = NEAR[usize::from(self.faces)];
        let low = |a: usize| BYTES[usize::from((self.minus[a] >> (1 << a)) & !HIGH[a])] << a;
        let face = low(0) | low(1) | low(2);
        let mut c = [0u16; 8];
        for (k, c) in c.iter_mut().enumerate() {
            let (near, face) = (
                (near >> (8 * k)) as u16 & 0xFF,
                (face >> (8 * k)) as u16 & 0xFF,
            );
            *c = (k as u16 * 3 * planes + u16::from(plane[k])) * 32 + face * 4 + near;
        }
        c
    }
}

/// `BYTES[m]`: byte k is bit k of m.
static BYTES: [u64; 256] = {
    let mut t = [0; 256];
    let mut m = 0;
    while m < 256 {
        let mut k = 0;
        while k < 8 {
            t[m] |= ((m as u64 >> k) & 1) << (8 * k);
            k += 1;
        }
        m += 1;
    }
    t
};

/// `NEAR[faces]`: byte k is the number of occupied face neighbours on
/// child k's sides.
static NEAR: [u64; 64] = {
    let mut t = [0; 64];
    let mut faces = 0;
    while faces < 64 {
        let mut k = 0;
        while k < 8 {
            let mut a = 0;
            while a < 3 {
                t[faces] += ((faces as u64 >> (2 * a + (k >> a & 1))) & 1) << (8 * k);
                a += 1;
            }
            k += 1;
        }
        faces += 1;
    }
    t
};

/// The children on the high side of each axis (bit k: child k).
const HIGH: [u8; 3] = [0xAA, 0xCC, 0xF0];

/// The part of child k's context that the mask's bits below k
/// (`so_far`) give: the bits set (0, 1, 2+) and the face bits on its high
/// sides (its siblings at −e_a).
pub(crate) static CODED: [[u16; 256]; 8] = coded(5);

/// `CODED` for version 3's `PLANES_V3` plane classes.
pub(crate) static CODED_V3: [[u16; 256]; 8] = coded(PLANES_V3);

const fn coded(planes: usize) -> [[u16; 256]; 8] {
    let mut t = [[0; 256]; 8];
    let mut k = 0;
    while k < 8 {
        let mut so_far = 0usize;
        while so_far < 256 {
            let set = if so_far.count_ones() > 2 {
                2
            } else {
                so_far.count_ones()
            };
            let mut face = 0;
            let mut a = 0;
            while a < 3 {
                if k >> a & 1 == 1 {
                    face |= (so_far >> (k ^ (1 << a)) & 1) << a;
                }
                a += 1;
            }
            t[k][so_far] = (set as usize * planes * 32 + face * 4) as u16;
            so_far += 1;
        }
        k += 1;
    }
    t
}

/// Morton key: x, y, z bits interleaved, x lowest.
pub(crate) fn morton(q: [u32; 3]) -> u64 {
    fn spread(v: u32) -> u64 {
        let mut x = u64::from(v) & 0x1F_FFFF;
        x = (x | x << 32) & 0x1F_0000_0000_FFFF;
        x = (x | x << 16) & 0x1F_0000_FF00_00FF;
        x = (x | x << 8) & 0x100F_00F0_0F00_F00F;
        x = (x | x << 4) & 0x10C3_0C30_C30C_30C3;
        x = (x | x << 2) & 0x1249_2492_4924_9249;
        x
    }
    spread(q[0]) | spread(q[1]) << 1 | spread(q[2]) << 2
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn contexts_in_parts_are_the_context() {
        let mut s = 3u64;
        for _ in 0..2000 {
            let r = crate::testing::next(&mut s);
            let around = Around {
                faces: (r & 63) as u8,
                minus: [(r >> 8) as u8, (r >> 16) as u8, (r >> 24) as u8],
                minus_edge: r >> 32 & 1 == 1,
                plane: [0; 8].map(|_| (crate::testing::next(&mut s) % 5) as u8),
            };
            let parts = around.contexts();
            for k in 0..8u32 {
                for so_far in 0..(1u16 << k) {
                    let whole = parts[k as usize] + CODED[k as usize][usize::from(so_far)];
                    assert_eq!(usize::from(whole), around.context(k, so_far as u8));
                    assert!(usize::from(whole) < CONTEXTS);
                }
            }
        }
    }

    #[test]
    fn plane_bins_measure_the_distance_from_the_fitted_plane() {
        // The layer z = 0: every child centre is a quarter cell from it.
        let mut layer = Block::default();
        for (dx, dy) in [
            (-1, -1),
            (0, -1),
            (1, -1),
            (-1, 0),
            (1, 0),
            (-1, 1),
            (0, 1),
            (1, 1),
        ] {
            layer.add([dx, dy, 0]);
        }
        assert_eq!(layer.plane_bins(), [3; 8]);
        // The same layer and one cell below it: the plane's centroid moves
        // down a tenth of a cell, nearer the lower children (k < 4).
        let mut low = Block::default();
        for (dx, dy) in [
            (-1, -1),
            (0, -1),
            (1, -1),
            (-1, 0),
            (1, 0),
            (-1, 1),
            (0, 1),
            (1, 1),
        ] {
            low.add([dx, dy, 0]);
        }
        low.add([0, 0, -1]);
        let bins = low.plane_bins();
        assert!((0..4).all(|k| bins[k] < bins[k + 4]), "{bins:?}");
        // Fewer than three neighbours, or all on one line: no plane.
        let mut line = Block::default();
        line.add([-1, 0, 0]);
        line.add([1, 0, 0]);
        assert_eq!(line.plane_bins(), [0; 8]);
        line.add([0, 0, 0]);
        assert_eq!(line.plane_bins(), [0; 8]);
    }
}
