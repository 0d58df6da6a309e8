//! The 4×4×4 region of cells around a cell being coded (stream version
//! 2, `neighbourhood.rs`): the children of the 2×2×2 cells one depth up on
//! the cell's sides of its parent, one byte (a child mask) per parent, bit
//! `8u + v` for child v of parent u (both as `x | y << 1 | z << 2`). The
//! cell's 3×3×3 block lies inside it wherever the cell sits in its parent,
//! so the contexts' inputs are masks and popcounts of the region, and the
//! plane's moments sums over its bytes of per-byte tables.

use super::context::{Around, Block};

/// Per child index k (the cell's corner in its parent): where its 3×3×3
/// block lies in the 4×4×4 region (bit `8u + v`: child v of the region's
/// parent u, both as `x | y << 1 | z << 2`).
#[derive(Clone, Copy)]
struct ChildTables {
    /// The 26 neighbours.
    neighbours: u64,
    /// The region's cells but the cell itself.
    others: u64,
    /// Neighbours at −e_a − e_b, a ≠ b.
    minus_edges: u64,
    /// The region bit of the face neighbour `2a + s` (s = 0: −, 1: +).
    faces: [u32; 6],
}

const fn region_bit(r: [i32; 3]) -> u32 {
    let u = (r[0] >> 1) | (r[1] >> 1) << 1 | (r[2] >> 1) << 2;
    let v = (r[0] & 1) | (r[1] & 1) << 1 | (r[2] & 1) << 2;
    (8 * u + v) as u32
}

/// The cell's region coordinates: 2 on a low side of its parent (the
/// parent is the region's upper one), 1 on a high side.
const fn centre(k: usize) -> [i32; 3] {
    [
        2 - (k & 1) as i32,
        2 - (k >> 1 & 1) as i32,
        2 - (k >> 2 & 1) as i32,
    ]
}

const fn child_tables(k: usize) -> ChildTables {
    let mut t = ChildTables {
        neighbours: 0,
        others: 0,
        minus_edges: 0,
        faces: [0; 6],
    };
    let c = centre(k);
    t.others = !(1 << region_bit(c));
    let mut i = 0;
    while i < 27 {
        let d = [i % 3 - 1, i / 3 % 3 - 1, i / 9 - 1];
        i += 1;
        let moved = (d[0] != 0) as i32 + (d[1] != 0) as i32 + (d[2] != 0) as i32;
        if moved == 0 {
            continue;
        }
        let at = region_bit([c[0] + d[0], c[1] + d[1], c[2] + d[2]]);
        t.neighbours |= 1 << at;
        if moved == 2 && d[0] <= 0 && d[1] <= 0 && d[2] <= 0 {
            t.minus_edges |= 1 << at;
        }
        if moved == 1 {
            let a = if d[0] != 0 {
                0
            } else if d[1] != 0 {
                1
            } else {
                2
            };
            t.faces[2 * a + (d[a] > 0) as usize] = at;
        }
    }
    t
}

const TABLES: [ChildTables; 8] = {
    let mut t = [child_tables(0); 8];
    let mut k = 1;
    while k < 8 {
        t[k] = child_tables(k);
        k += 1;
    }
    t
};

/// Moments about the region's corner of the cells of one region byte
/// (parent u, child mask m), in byte lanes that cannot carry over 26
/// cells (Σ r_a ≤ 78, Σ r_a r_b ≤ 234): `[count, Σx, Σy, Σz, Σxx, Σyy,
/// Σzz, 0]` and `[Σxy, Σxz, Σyz, 0, …]`.
static MOMENTS: [[[u64; 2]; 256]; 8] = {
    let mut t = [[[0u64; 2]; 256]; 8];
    let mut u = 0;
    while u < 8 {
        let mut m = 0;
        while m < 256 {
            let mut v = 0;
            while v < 8 {
                if m >> v & 1 == 1 {
                    let r = [
                        (2 * (u & 1) + (v & 1)) as u64,
                        (2 * (u >> 1 & 1) + (v >> 1 & 1)) as u64,
                        (2 * (u >> 2) + (v >> 2)) as u64,
                    ];
                    t[u][m][0] += 1
                        + (r[0] << 8)
                        + (r[1] << 16)
                        + (r[2] << 24)
                        + ((r[0] * r[0]) << 32)
                        + ((r[1] * r[1]) << 40)
                        + ((r[2] * r[2]) << 48);
                    t[u][m][1] += r[0] * r[1] + ((r[0] * r[2]) << 8) + ((r[1] * r[2]) << 16);
                }
                v += 1;
            }
            m += 1;
        }
        u += 1;
    }
    t
};

/// Version 3 fits the plane to the whole region below this many
/// neighbours in the 3×3×3 block (lucy 300 k, 12 bits: 3 cost 0.4 % more,
/// 8 0.1 %; bunny 100 k preferred 8 by 0.15 %).
const WIDE_BELOW: u32 = 5;

/// Child `k`'s face neighbours and −e edge flag from the region, with the
/// region's cells that neighbour it.
#[inline]
fn faces_and_edges(region: u64, k: usize) -> (Around, u64) {
    let t = &TABLES[k];
    let mut r = Around::default();
    for (f, &bit) in t.faces.iter().enumerate() {
        r.faces |= ((region >> bit & 1) as u8) << f;
    }
    r.minus_edge = region & t.minus_edges != 0;
    (r, region & t.neighbours)
}

/// The contexts' inputs from the region around child `k`, but the masks of
/// its −e_a neighbours.
pub(super) fn describe(region: u64, k: usize) -> Around {
    let (mut r, occupied) = faces_and_edges(region, k);
    let two = occupied & occupied.wrapping_sub(1);
    if two & two.wrapping_sub(1) != 0 {
        // At least 3 neighbours: a plane may be fitted.
        r.plane = moments(occupied, k).plane_bins();
    }
    r
}

/// Version 3: [`describe`] but the plane classes, and the region's cells
/// the plane is fitted to (`Neighbourhood::around` adds what is known of
/// their children): the 3×3×3 block's if it holds at least `WIDE_BELOW`
/// neighbours, else the whole region's but the cell's own; none if fewer
/// than 3.
pub(super) fn describe_v3(region: u64, k: usize) -> (Around, u64) {
    let (r, occupied) = faces_and_edges(region, k);
    let fitted = if occupied.count_ones() >= WIDE_BELOW {
        occupied
    } else {
        region & TABLES[k].others
    };
    (r, if fitted.count_ones() >= 3 { fitted } else { 0 })
}

/// The offset of region bit `b` from the region's cell of child `k`.
pub(super) fn offset_in_region(b: u32, k: usize) -> [i32; 3] {
    let (u, v) = (b >> 3, b & 7);
    let c = centre(k);
    [
        (2 * (u & 1) + (v & 1)) as i32 - c[0],
        (2 * (u >> 1 & 1) + (v >> 1 & 1)) as i32 - c[1],
        (2 * (u >> 2) + (v >> 2)) as i32 - c[2],
    ]
}

/// The moments of the occupied cells in `neighbours` (a region's bits)
/// about child `k`'s centre.
pub(super) fn moments(neighbours: u64, k: usize) -> Block {
    let mut lanes = [0u64; 2];
    for (u, byte) in neighbours.to_le_bytes().into_iter().enumerate() {
        let m = &MOMENTS[u][usize::from(byte)];
        lanes[0] += m[0];
        lanes[1] += m[1];
    }
    let lane = |l: usize, i: u32| ((lanes[l] >> (8 * i)) & 0xFF) as i64;
    let count = lane(0, 0);
    let m1 = [lane(0, 1), lane(0, 2), lane(0, 3)];
    let c = centre(k).map(i64::from);
    let sum = [
        m1[0] - count * c[0],
        m1[1] - count * c[1],
        m1[2] - count * c[2],
    ];
    // Σ (r_a − c_a)(r_b − c_b) = Σ r_a r_b − c_b Σ r_a − c_a S_b.
    let product = |m2: i64, a: usize, b: usize| m2 - c[b] * m1[a] - c[a] * sum[b];
    let p01 = product(lane(1, 0), 0, 1);
    let p02 = product(lane(1, 1), 0, 2);
    let p12 = product(lane(1, 2), 1, 2);
    Block {
        count,
        sum,
        products: [
            [product(lane(0, 4), 0, 0), p01, p02],
            [p01, product(lane(0, 5), 1, 1), p12],
            [p02, p12, product(lane(0, 6), 2, 2)],
        ],
    }
}
