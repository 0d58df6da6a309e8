//! The surface plane a cell inherits (stream version 3, `FORMAT.md`
//! "Version 3").
//!
//! Below the depths where a surface fills its cells, a cell's 3×3×3 block
//! rarely holds the three neighbours a plane needs (a 300 k point scan at
//! 12 bits occupies about 6 % of the surface's cells at depth 11), so
//! version 2 codes most deep masks without knowing where the surface runs.
//! The plane fitted one or more depths up still says it: each cell keeps the
//! last plane fitted around it or an ancestor, as a unit normal and the
//! signed distance of its centre from the plane, and hands each child its
//! own distance (exact integer steps, so that the decoder in WebAssembly
//! agrees bit for bit).

use super::context::Block;

/// Fixed-point scale of distances: 2^10 per cell side.
const ONE: i32 = 1 << 10;
/// Distances are clamped to ±8 cells: a plane that far says nothing more,
/// and the clamp keeps every later depth's doubling within `i32`.
const FAR: i32 = 8 * ONE;

/// Classes of a child's distance from its cell's plane: 0 without a plane,
/// then |distance| in child sides below 1/4, 1/2, 3/4, 1, and above.
pub(crate) const CLASSES: usize = 6;

/// A cell's plane: zero `half_normal` where none is known.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct Surface {
    /// Half the unit normal, × `ONE`.
    half_normal: [i16; 3],
    /// Signed distance of the cell's centre from the plane, in cell sides
    /// × `ONE`.
    distance: i32,
}

impl Surface {
    pub fn is_known(&self) -> bool {
        self.half_normal != [0; 3]
    }

    /// The plane fitted to `block` (moments about the cell's centre), if
    /// it has one (`Block::normal`).
    pub fn fitted(block: &Block) -> Surface {
        let Some((normal, len2)) = block.normal() else {
            return Surface::default();
        };
        let len = i64::try_from((len2 as u64).isqrt())
            .unwrap_or(i64::MAX)
            .max(1);
        let half = i64::from(ONE / 2);
        let half_normal = normal.map(|v| (v * half / len) as i16);
        if half_normal == [0; 3] {
            return Surface::default();
        }
        // The centre lies at −S/n from the centroid (n: the block's cells,
        // the centre's included).
        let n = block.count + 1;
        let dot: i64 = (0..3).map(|a| normal[a] * block.sum[a]).sum();
        let distance = -(dot * i64::from(ONE)) / (n * len);
        Surface {
            half_normal,
            distance: distance.clamp(-i64::from(FAR), i64::from(FAR)) as i32,
        }
    }

    /// The plane as child `k` (corner `x | y << 1 | z << 2`) sees it, in
    /// its own sides.
    pub fn child(&self, k: usize) -> Surface {
        if !self.is_known() {
            return *self;
        }
        let mut d = 2 * self.distance;
        for a in 0..3 {
            let h = i32::from(self.half_normal[a]);
            d += if k >> a & 1 == 1 { h } else { -h };
        }
        Surface {
            half_normal: self.half_normal,
            distance: d.clamp(-FAR, FAR),
        }
    }

    /// Each child's distance class (`CLASSES`).
    pub fn classes(&self) -> [u8; 8] {
        if !self.is_known() {
            return [0; 8];
        }
        let mut out = [0; 8];
        for (k, c) in out.iter_mut().enumerate() {
            // In child sides: twice the distance in this cell's sides.
            let d = self.child(k).distance.unsigned_abs();
            *c = 1
                + u8::from(d >= ONE as u32 / 4)
                + u8::from(d >= ONE as u32 / 2)
                + u8::from(d >= 3 * ONE as u32 / 4)
                + u8::from(d >= ONE as u32);
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_layer_below_the_centre_is_inherited_down_the_tree() {
        // The cells of the layer z = −1 around a cell: the plane lies one
        // cell below the centre, parallel to z = 0.
        let mut block = Block::default();
        for dx in -1..=1 {
            for dy in -1..=1 {
                block.add([dx, dy, -1]);
            }
        }
        let s = Surface::fitted(&block);
        assert!(s.is_known());
        // With the centre counted the centroid is at z = −0.9.
        assert_eq!(s.distance.abs(), 9 * ONE / 10);
        // Children on the low side are nearer the plane than those above.
        let classes = s.classes();
        assert!((0..4).all(|k| classes[k] <= classes[k + 4]), "{classes:?}");
        let low = s.child(0);
        let high = s.child(4);
        assert!(low.distance.abs() < high.distance.abs());
        // Its distance doubles in child sides, less the quarter cell.
        assert_eq!(low.distance.abs(), 2 * s.distance.abs() - ONE / 2);
        // No plane: no classes, and children inherit none.
        assert_eq!(Surface::default().classes(), [0; 8]);
        assert!(!Surface::default().child(3).is_known());
    }
}
