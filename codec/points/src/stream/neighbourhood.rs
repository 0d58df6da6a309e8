//! The occupied cells of two depths, each with the list of its occupied
//! neighbours, so that a cell's 26 neighbours cost no search (stream
//! version 2's contexts, `context.rs`).
//!
//! The 3×3×3 block around a cell `c` at depth d is made of children of the
//! 2×2×2 cells at depth d − 1 on `c`'s sides of its parent `p`: `p` and
//! those of its occupied neighbours. Their 8 child masks, all known before
//! any mask of depth d is coded, form a 4×4×4 region of depth-d cells, one
//! byte per parent; the contexts are popcounts and moments of that region
//! around `c` (`region.rs`). `c`'s own neighbour list, for its
//! children at the next depth, is the children of the same parents that
//! touch it; the list also gives the coded masks of `c − e_a`.
//!
//! Work per cell is proportional to the occupied neighbours: a few at the
//! deep levels, where a surface no longer fills its cells and most cells
//! are coded.

use super::context::Around;
use super::context::Block;
use super::region::{describe, describe_v3, moments, offset_in_region};

/// The cells of one depth, in coding order.
#[derive(Default)]
struct Level {
    /// Each cell's child mask (low 8 bits) and the coding index of its
    /// first child at the next depth (above): one load for both.
    cells: Vec<u64>,
    /// Children of the cells so far.
    children: u32,
    /// Cell i's occupied neighbours are `neighbours[start[i]..start[i + 1]]`,
    /// each its coding index (at the same depth) << 8 | its offset code
    /// (`offset_code`); only those that one of the cell's children can see.
    start: Vec<u32>,
    neighbours: Vec<u64>,
}

impl Level {
    fn mask(&self, i: usize) -> u8 {
        self.cells[i] as u8
    }

    fn first_child(&self, i: usize) -> u32 {
        (self.cells[i] >> 8) as u32
    }

    fn clear(&mut self) {
        self.cells.clear();
        self.children = 0;
        self.start.clear();
        self.start.push(0);
        self.neighbours.clear();
    }
}

fn listed_len(level: &Level, i: usize) -> usize {
    (level.start[i + 1] - level.start[i]) as usize
}

/// An offset δ ∈ {−1, 0, 1}³ as 0..27: Σ_a (δ_a + 1) · 3^a (13: none).
const fn offset_code(d: [i32; 3]) -> usize {
    ((d[0] + 1) + 3 * (d[1] + 1) + 9 * (d[2] + 1)) as usize
}

const fn offset(code: usize) -> [i32; 3] {
    [
        (code % 3) as i32 - 1,
        (code / 3 % 3) as i32 - 1,
        (code / 9) as i32 - 1,
    ]
}

/// The occupied cells of the depth being coded and of the one above.
#[derive(Default)]
pub(crate) struct Neighbourhood {
    depth: u32,
    /// Depth − 1, complete.
    parents: Level,
    /// This depth, up to the cell being coded.
    cells: Level,
    /// The parent of the cell being coded.
    parent: usize,
    /// The parent-level cells (mask and first child, offset code) on the
    /// sides of the cell last asked about, and its child index.
    sides: [(u64, u8); 9],
    side_count: usize,
    k: usize,
    /// Whether the cells' neighbour lists are kept (not at the last depth
    /// whose masks are coded: nothing reads them).
    lists: bool,
    /// Version 3: planes fitted to the 4×4×4 region and the children
    /// already coded.
    wide: bool,
}

/// What a parent-level cell at `offset_code` from child k's parent gives
/// it: the region byte it fills (`u`, unless it is not on the child's
/// sides) and its children that touch the child (`touching`).
#[derive(Clone, Copy)]
struct Reach {
    u: u8,
    /// Byte `u` if the cell fills it, else 0.
    keep: u64,
    touching: u8,
    /// The axis a if the cell is at −e_a of the child's parent and the child
    /// on its +a side (it holds the child's −e_a neighbour), else 3.
    minus: u8,
    /// Each child's offset code from child k (13 for the ninth, none).
    codes: [u8; 9],
}

const fn reach(k: usize, code: usize) -> Reach {
    let d = offset(code);
    let mut r = Reach {
        u: 0,
        keep: 0,
        touching: 0,
        minus: 3,
        codes: [13; 9],
    };
    // Region coordinates of the parent: 1 − k_a + δ_a on each axis.
    let mut u = 0;
    let mut a = 0;
    while a < 3 {
        let ua = 1 - (k >> a & 1) as i32 + d[a];
        if ua < 0 || ua > 1 {
            return r;
        }
        u |= (ua as usize) << a;
        a += 1;
    }
    r.u = u as u8;
    r.keep = 0xFF << (8 * u);
    let mut a = 0;
    while a < 3 {
        if k >> a & 1 == 0 && d[a] == -1 && d[(a + 1) % 3] == 0 && d[(a + 2) % 3] == 0 {
            r.minus = a as u8;
        }
        a += 1;
    }
    let mut v = 0;
    while v < 8 {
        // The child's offset from child k: 2δ + v − k per axis.
        let mut e = [0; 3];
        let mut near = v != k || code != 13;
        let mut a = 0;
        while a < 3 {
            e[a] = 2 * d[a] + (v >> a & 1) as i32 - (k >> a & 1) as i32;
            near &= e[a] >= -1 && e[a] <= 1;
            a += 1;
        }
        if near {
            r.touching |= 1 << v;
            r.codes[v] = offset_code(e) as u8;
        }
        v += 1;
    }
    r
}

static REACH: [[Reach; 27]; 8] = {
    let mut t = [[reach(0, 0); 27]; 8];
    let mut k = 0;
    while k < 8 {
        let mut code = 0;
        while code < 27 {
            t[k][code] = reach(k, code);
            code += 1;
        }
        k += 1;
    }
    t
};

/// `RANK[m][v]`: the set bits of mask `m` below bit `v` (v ≤ 8).
static RANK: [[u8; 9]; 256] = {
    let mut t = [[0; 9]; 256];
    let mut m = 0;
    while m < 256 {
        let mut v = 1;
        while v < 9 {
            t[m][v] = t[m][v - 1] + (m >> (v - 1) & 1) as u8;
            v += 1;
        }
        m += 1;
    }
    t
};

/// `SEEN_BY[code]`: the children (bit k) whose 3×3×3 block holds children
/// of the cell at `offset_code` from their parent.
static SEEN_BY: [u8; 27] = {
    let mut t = [0; 27];
    let mut code = 0;
    while code < 27 {
        let mut k = 0;
        while k < 8 {
            if reach(k, code).keep != 0 {
                t[code] |= 1 << k;
            }
            k += 1;
        }
        code += 1;
    }
    t
};

impl Neighbourhood {
    /// Version 3's: planes fitted to the 4×4×4 region of the cell.
    pub fn wide() -> Self {
        Neighbourhood {
            wide: true,
            ..Default::default()
        }
    }

    /// Starts coding the masks of the cells at `depth` (the masks of
    /// depth − 1 were all recorded); `last`: no depth follows.
    pub fn start_depth(&mut self, depth: u32, last: bool) {
        self.depth = depth;
        self.lists = !last;
        std::mem::swap(&mut self.parents, &mut self.cells);
        self.cells.clear();
        self.parent = 0;
    }

    /// Records the mask of the cell [`around`](Self::around) was last
    /// asked about.
    pub fn record(&mut self, mask: u8) {
        let cells = &mut self.cells;
        cells
            .cells
            .push(u64::from(cells.children) << 8 | u64::from(mask));
        cells.children += mask.count_ones();
        if self.lists && self.depth > 0 {
            // The cell's neighbours that one of its children sees: children
            // of the parent-level cells on its sides.
            let reach = &REACH[self.k];
            // Written in place without branches, the next write
            // overwriting an unused one; at most 26 and the unused one.
            let list = &mut cells.neighbours;
            let start = list.len();
            list.resize(start + 27, 0);
            let found = &mut list[start..];
            let mut n = 0;
            for &(cell, code) in &self.sides[..self.side_count] {
                let r = &reach[usize::from(code)];
                let m = cell as u8;
                let first = (cell >> 8) as u32;
                let mut touching = m & r.touching;
                while touching != 0 {
                    let v = touching.trailing_zeros() as usize;
                    touching &= touching - 1;
                    let code = r.codes[v];
                    let index = first + u32::from(RANK[usize::from(m)][v]);
                    found[n] = u64::from(index) << 8 | u64::from(code);
                    n += usize::from(SEEN_BY[usize::from(code)] & mask != 0);
                }
            }
            list.truncate(start + n);
        }
        cells.start.push(cells.neighbours.len() as u32);
    }

    /// Version 3's plane classes for the cell `i`, child `k` of its
    /// parent: the plane fitted to the region's cells `fitted` (region
    /// bits), each as its centre or, where its mask is coded (`coded`,
    /// before `i`), as the centres of its children, in quarter cells about
    /// `i`'s centre (`FORMAT.md` "Version 3").
    fn plane_v3(&self, fitted: u64, coded: u64, k: usize, i: u32) -> [u8; 8] {
        // Each region byte's parent-level cell: its first child and mask.
        let mut bytes = [(0u32, 0u8); 8];
        for &(cell, code) in &self.sides[..self.side_count] {
            bytes[usize::from(REACH[k][usize::from(code)].u)] = ((cell >> 8) as u32, cell as u8);
        }
        // The cells not coded yet from the per-byte tables, in quarters.
        let far = moments(fitted & !coded, k);
        let mut block = Block {
            count: far.count,
            sum: far.sum.map(|s| 4 * s),
            products: far.products.map(|row| row.map(|p| 16 * p)),
        };
        let mut add = |q: [i64; 3]| {
            block.count += 1;
            for a in 0..3 {
                block.sum[a] += q[a];
                for b in a..3 {
                    block.products[a][b] += q[a] * q[b];
                }
            }
        };
        let mut rest = fitted & coded;
        while rest != 0 {
            let b = rest.trailing_zeros();
            rest &= rest - 1;
            let d = offset_in_region(b, k).map(|v| 4 * i64::from(v));
            let (first, m) = bytes[(b >> 3) as usize];
            let index = first + u32::from(RANK[usize::from(m)][(b & 7) as usize]);
            debug_assert!(index < i);
            let mut children = self.cells.mask(index as usize);
            while children != 0 {
                let w = children.trailing_zeros() as i64;
                children &= children - 1;
                add([0, 1, 2].map(|a| d[a] + 2 * (w >> a & 1) - 1));
            }
        }
        for a in 0..3 {
            for b in 0..a {
                block.products[a][b] = block.products[b][a];
            }
        }
        block.plane_bins_quarters()
    }

    /// What is known around the next cell to code (coding order), at `at`
    /// (coordinates at this depth): the masks of depth − 1 and those
    /// recorded at this depth. Must be followed by its [`record`](Self::record).
    pub fn around(&mut self, at: [u32; 3]) -> Around {
        let i = self.cells.cells.len() as u32;
        if self.depth == 0 {
            return Around::default();
        }
        let parents = &self.parents;
        // Every parent has a child: the next cell's parent is this one or
        // the next.
        let mut p = self.parent;
        while p + 1 < parents.cells.len() && parents.first_child(p + 1) <= i {
            p += 1;
        }
        self.parent = p;
        let k = ((at[0] & 1) | (at[1] & 1) << 1 | (at[2] & 1) << 2) as usize;
        let reach = &REACH[k];
        let mut region = 0u64;
        // The parents at −e_a of the cell's parent where the cell is on
        // their side (entry 3 takes the others).
        let mut minus_parent = [p; 4];
        let from = parents.start[p] as usize;
        // The parent-level cells on the cell's sides, for `record`
        // (written without branches, the next write overwriting an unused
        // one).
        let mut n = 0;
        // The region's cells whose masks are coded: all children of the
        // parent-level cells before the parent, the siblings before k.
        let mut coded = ((1u64 << k) - 1) << (8 * reach[13].u);
        for e in 0..=listed_len(parents, p) {
            let (j, code) = if e == 0 {
                (p, 13)
            } else {
                let entry = parents.neighbours[from + e - 1];
                ((entry >> 8) as usize, entry as u8)
            };
            let cell = parents.cells[j];
            let r = &reach[usize::from(code)];
            region |= (cell << (8 * r.u)) & r.keep;
            coded |= r.keep & 0u64.wrapping_sub(u64::from(j < p));
            minus_parent[usize::from(r.minus)] = j;
            self.sides[n] = (cell, code);
            n += usize::from(r.keep != 0);
        }
        self.side_count = n;
        self.k = k;
        let mut r = if self.wide {
            let (mut r, fitted) = describe_v3(region, k);
            if fitted != 0 {
                r.plane = self.plane_v3(fitted, coded, k, i);
            }
            r
        } else {
            describe(region, k)
        };
        let (parents, cells) = (&self.parents, &self.cells);
        for (a, &j) in minus_parent[..3].iter().enumerate() {
            if r.faces >> (2 * a) & 1 == 1 {
                // Child k ^ 2^a of the parent, or k | 2^a of the one at −e_a.
                let v = k ^ 1 << a;
                let m = parents.mask(j);
                let index = parents.first_child(j) + u32::from(RANK[usize::from(m)][v]);
                r.minus[a] = cells.mask(index as usize);
            }
        }
        r
    }
}

#[cfg(test)]
mod tests {
    use std::collections::HashMap;

    use super::*;
    use crate::stream::context::{morton, Block};
    use crate::testing::next;

    #[test]
    fn contexts_stay_in_range_and_see_coded_neighbours() {
        // Cells (1,1,1) and its −x neighbour (0,1,1) at depth 2.
        let mut n = Neighbourhood::default();
        n.start_depth(0, false);
        n.around([0; 3]);
        n.record(1);
        n.start_depth(1, false);
        n.around([0; 3]);
        n.record(0b1100_0000); // children (0,1,1) and (1,1,1)
        n.start_depth(2, false);
        assert_eq!(n.around([0, 1, 1]).faces, 0b10);
        n.record(0b0000_0010); // child (1,0,0) of (0,1,1)
        let around = n.around([1, 1, 1]);
        assert_eq!(around.faces, 0b01);
        assert_eq!(around.minus[0], 0b10);
        // Child 0 of (1,1,1) touches child 1 of (0,1,1) on its −x side.
        let with = around.context(0, 0);
        let without = Around::default().context(0, 0);
        assert_ne!(with, without);
        for k in 0..8 {
            for so_far in 0..(1u8 << k) {
                assert!(around.context(k, so_far) < super::super::context::CONTEXTS);
            }
        }
    }

    /// The cofactors of the block's scatter matrix (times the cell count
    /// squared), in 128 bits; `None` under three cells.
    fn cofactor_rows_i128(block: &Block) -> Option<[[i128; 3]; 3]> {
        let n = block.count + 1;
        if block.count < 3 {
            return None;
        }
        let c = |a: usize, b: usize| n * block.products[a][b] - block.sum[a] * block.sum[b];
        let cof = |i: usize, j: usize| {
            let (i1, i2, j1, j2) = ((i + 1) % 3, (i + 2) % 3, (j + 1) % 3, (j + 2) % 3);
            i128::from(c(i1, j1)) * i128::from(c(i2, j2))
                - i128::from(c(i1, j2)) * i128::from(c(i2, j1))
        };
        Some([0, 1, 2].map(|i| [0, 1, 2].map(|j| cof(i, j))))
    }

    /// `FORMAT.md`'s plane classes as first written: 128-bit cofactors and
    /// the normal's shift.
    fn plane_bins_i128(block: &Block) -> [u8; 8] {
        let n = block.count + 1;
        let Some(rows) = cofactor_rows_i128(block) else {
            return [0; 8];
        };
        let norm2 = |r: &[i128; 3]| r.iter().map(|v| v * v).sum::<i128>();
        let mut normal = [0; 3];
        for r in &rows {
            if norm2(r) >= norm2(&normal) {
                normal = *r;
            }
        }
        if norm2(&normal) == 0 {
            return [0; 8];
        }
        let big = normal.iter().map(|v| v.abs()).max().unwrap_or(1);
        let shift = (128 - big.leading_zeros()).saturating_sub(24);
        let normal = normal.map(|v| v >> shift);
        let len2 = norm2(&normal).max(1);
        let n = i128::from(n);
        let mut bins = [0u8; 8];
        for (k, bin) in bins.iter_mut().enumerate() {
            let dist: i128 = (0..3)
                .map(|a| {
                    let o = if (k >> a) & 1 == 1 { 1 } else { -1 };
                    normal[a] * (o * n - 4 * i128::from(block.sum[a]))
                })
                .sum();
            let lhs = 4 * dist * dist;
            *bin = 1 + (1..=3).filter(|&e| lhs >= e * e * n * n * len2).count() as u8;
        }
        bins
    }

    /// `FORMAT.md`'s definition, cell by cell through a map of the depth.
    /// `FORMAT.md`'s version 3 plane classes (points in quarter cells):
    /// the cofactors in 128 bits, shifted below 2^30, the normal below
    /// 2^12, five thresholds.
    fn plane_bins_v3_i128(block: &Block) -> [u8; 8] {
        let n = block.count + 1;
        let Some(rows) = cofactor_rows_i128(block) else {
            return [0; 8];
        };
        let big = rows
            .iter()
            .flatten()
            .map(|v| v.unsigned_abs())
            .max()
            .unwrap();
        let shift = (128 - big.leading_zeros()).saturating_sub(30);
        let rows = rows.map(|r| r.map(|v| v >> shift));
        let norm2 = |r: &[i128; 3]| r.iter().map(|v| v * v).sum::<i128>();
        let mut normal = [0; 3];
        for r in &rows {
            if norm2(r) >= norm2(&normal) {
                normal = *r;
            }
        }
        let big = normal.iter().map(|v| v.unsigned_abs()).max().unwrap();
        let shift = (128 - big.leading_zeros()).saturating_sub(12);
        let normal = normal.map(|v| v >> shift);
        let len2 = norm2(&normal);
        if len2 == 0 {
            return [0; 8];
        }
        let n = i128::from(n);
        let mut bins = [0u8; 8];
        for (k, bin) in bins.iter_mut().enumerate() {
            let dist: i128 = (0..3)
                .map(|a| {
                    let o = if (k >> a) & 1 == 1 { 1 } else { -1 };
                    normal[a] * (o * n - i128::from(block.sum[a]))
                })
                .sum();
            let lhs = 4 * dist * dist;
            *bin = 1 + (1..=5).filter(|&e| lhs >= e * e * n * n * len2).count() as u8;
        }
        bins
    }

    /// Version 3's plane: of the 26 neighbours if at least 5 are occupied,
    /// else of the 4×4×4 block on `at`'s side of its parent; each cell
    /// as its centre or, if coded before cell `i`, its children's centres,
    /// in quarter cells.
    fn plane_v3(
        cells: &HashMap<[u32; 3], usize>,
        masks: &[u8],
        at: [u32; 3],
        i: usize,
        near: &Block,
    ) -> [u8; 8] {
        let low = at.map(|v| if v % 2 == 0 { -2 } else { -1 });
        let mut block = Block::default();
        let mut used = 0;
        for dz in low[2]..low[2] + 4 {
            for dy in low[1]..low[1] + 4 {
                for dx in low[0]..low[0] + 4 {
                    let d = [dx, dy, dz];
                    let q = [0, 1, 2].map(|a| at[a].wrapping_add_signed(d[a]));
                    let Some(&j) = cells.get(&q).filter(|_| d != [0; 3]) else {
                        continue;
                    };
                    if near.count >= 5 && d.iter().any(|v| v.abs() > 1) {
                        continue;
                    }
                    used += 1;
                    if j < i {
                        for w in 0..8 {
                            if masks[j] >> w & 1 == 1 {
                                block.add([0, 1, 2].map(|a| 4 * d[a] + 2 * (w >> a & 1) - 1));
                            }
                        }
                    } else {
                        block.add(d.map(|v| 4 * v));
                    }
                }
            }
        }
        if used < 3 {
            return [0; 8];
        }
        let bins = plane_bins_v3_i128(&block);
        assert_eq!(bins, block.plane_bins_quarters(), "64-bit plane classes");
        bins
    }

    fn reference(
        cells: &HashMap<[u32; 3], usize>,
        masks: &[u8],
        at: [u32; 3],
        i: usize,
        wide: bool,
    ) -> Around {
        let mut r = Around::default();
        let mut block = Block::default();
        for dz in -1..=1i32 {
            for dy in -1..=1i32 {
                for dx in -1..=1i32 {
                    let d = [dx, dy, dz];
                    let q = [0, 1, 2].map(|a| at[a].wrapping_add_signed(d[a]));
                    let Some(&j) = cells.get(&q).filter(|_| d != [0; 3]) else {
                        continue;
                    };
                    block.add(d);
                    let moved = d.iter().filter(|&&v| v != 0).count();
                    if moved == 1 {
                        let a = d.iter().position(|&v| v != 0).unwrap();
                        r.faces |= 1 << (2 * a + usize::from(d[a] > 0));
                        if d[a] < 0 {
                            assert!(j < i, "−e_a neighbours are coded first");
                            r.minus[a] = masks[j];
                        }
                    } else if moved == 2 && d.iter().all(|&v| v <= 0) {
                        r.minus_edge = true;
                    }
                }
            }
        }
        if wide {
            r.plane = plane_v3(cells, masks, at, i, &block);
        } else {
            r.plane = plane_bins_i128(&block);
            assert_eq!(r.plane, block.plane_bins(), "64-bit plane classes");
        }
        r
    }

    /// Builds the octree of `points` (coordinates below 2^bits) depth by
    /// depth and checks every cell's `Around` against the reference.
    fn check_cloud(points: &[[u32; 3]], bits: u32, wide: bool) {
        let mut keys: Vec<u64> = points.iter().map(|&p| morton(p)).collect();
        keys.sort_unstable();
        keys.dedup();
        let mut n = if wide {
            Neighbourhood::wide()
        } else {
            Neighbourhood::default()
        };
        let mut planes = 0;
        for depth in 0..bits {
            let shift = 3 * (bits - depth);
            let mut cells: Vec<(u64, u8)> = Vec::new();
            for &key in &keys {
                let (cell, k) = (key >> shift, (key >> (shift - 3)) & 7);
                match cells.last_mut() {
                    Some(last) if last.0 == cell => last.1 |= 1 << k,
                    _ => cells.push((cell, 1 << k)),
                }
            }
            let at: Vec<[u32; 3]> = cells.iter().map(|&(c, _)| unmorton(c)).collect();
            let map: HashMap<[u32; 3], usize> =
                at.iter().enumerate().map(|(i, &q)| (q, i)).collect();
            let masks: Vec<u8> = cells.iter().map(|c| c.1).collect();
            n.start_depth(depth, depth + 1 == bits);
            for (i, &q) in at.iter().enumerate() {
                let want = reference(&map, &masks, q, i, wide);
                assert_eq!(n.around(q), want, "depth {depth} cell {q:?}");
                planes += usize::from(want.plane != [0; 8]);
                n.record(masks[i]);
            }
        }
        assert!(planes > 0);
    }

    fn unmorton(key: u64) -> [u32; 3] {
        let mut q = [0u32; 3];
        for b in 0..21 {
            for (a, v) in q.iter_mut().enumerate() {
                *v |= (((key >> (3 * b + a)) & 1) as u32) << b;
            }
        }
        q
    }

    #[test]
    fn around_agrees_with_the_definition() {
        let mut s = 11u64;
        // A shell (the surfaces the contexts are for), a dense cube corner
        // and scattered points, at depths where blocks are full and sparse.
        let bits = 8;
        let r = 100.0f64;
        let mut points: Vec<[u32; 3]> = (0..6000)
            .map(|_| {
                let v = [0; 3].map(|_| (next(&mut s) % 2001) as f64 / 1000.0 - 1.0);
                let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt().max(1e-9);
                v.map(|c| (127.5 + c / len * r) as u32)
            })
            .collect();
        points.extend((0..400).map(|_| [0; 3].map(|_| (next(&mut s) % 8) as u32)));
        points.extend((0..300).map(|_| [0; 3].map(|_| (next(&mut s) % 256) as u32)));
        check_cloud(&points, bits, false);
        check_cloud(&points, bits, true);
    }
}
