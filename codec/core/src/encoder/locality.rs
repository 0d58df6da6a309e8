//! The order the encoder keeps its mesh in.
//!
//! The conquests walk the mesh gate by gate, a breadth-first front across
//! the surface, and every step loads half-edges, vertex states and
//! positions. In the input's own order those loads can land anywhere: scans
//! come out of reconstruction and subdivision tools with vertices sorted by
//! coordinate or appended wherever they were made. Numbering vertices along
//! a Morton (Z-order) curve, and faces by their lowest-numbered corner,
//! keeps what lies close on the surface close in memory. The simplifier
//! keeps that order from layer to layer (it compacts without reordering).
//!
//! Measured on the 2 M-vertex igea (BENCHMARKS.md). The stream stays a
//! valid stream of the same mesh; only which face seeds each component,
//! and so the bytes, change.

/// Morton key bits per axis: a 1024³ grid over the bounding cube, fine
/// enough that a cell holds a handful of vertices of a 2 M-vertex scan.
const AXIS_BITS: u32 = 10;

/// Spreads the low 10 bits of `x` three bits apart, for a 30-bit Morton
/// key. Written here rather than taken from a crate: it is four shifts and
/// masks, where a dependency would bring a general n-dimensional API.
fn spread(x: u32) -> u32 {
    let mut x = x & 0x3ff;
    x = (x | x << 16) & 0x0300_00ff;
    x = (x | x << 8) & 0x0300_f00f;
    x = (x | x << 4) & 0x030c_30c3;
    x = (x | x << 2) & 0x0924_9249;
    x
}

/// A renumbering of a mesh for locality.
pub(crate) struct LocalityOrder {
    /// The faces in their new order, with new vertex ids, each entered at
    /// the same corner as in the input.
    pub triangles: Vec<[u32; 3]>,
    /// Input vertex id of each new vertex id.
    pub vertices: Vec<u32>,
}

impl LocalityOrder {
    /// `positions` are quantized to `0..=max` (at most 16 bits), and every
    /// triangle's corners must index them.
    pub(crate) fn of(positions: &[[i32; 3]], triangles: &[[u32; 3]], max: i32) -> LocalityOrder {
        let shift = (32 - max.max(1).leading_zeros()).saturating_sub(AXIS_BITS);
        let mut keyed: Vec<(u32, u32)> = positions
            .iter()
            .enumerate()
            .map(|(v, p)| {
                let [x, y, z] = p.map(|c| spread(c.clamp(0, max) as u32 >> shift));
                (x | y << 1 | z << 2, v as u32)
            })
            .collect();
        // Stable radix sorts (vertices in one cell, and faces on one lowest
        // corner, keep their input order), so the order, like the stream, is
        // deterministic; a comparison sort of a 4 M-face scan took 0.4 s.
        radsort::sort_by_key(&mut keyed, |&(key, _)| key);
        let vertices: Vec<u32> = keyed.iter().map(|&(_, v)| v).collect();
        drop(keyed);
        let mut new_id = vec![0u32; positions.len()];
        for (new, &old) in vertices.iter().enumerate() {
            new_id[old as usize] = new as u32;
        }
        let mut triangles: Vec<[u32; 3]> = triangles
            .iter()
            .map(|t| t.map(|v| new_id[v as usize]))
            .collect();
        radsort::sort_by_key(&mut triangles, |t| t[0].min(t[1]).min(t[2]));
        LocalityOrder {
            triangles,
            vertices,
        }
    }

    /// `values` (one per input vertex) in the new vertex order.
    pub(crate) fn permute<T: Copy>(&self, values: &[T]) -> Vec<T> {
        self.vertices.iter().map(|&v| values[v as usize]).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spread_interleaves_bits() {
        assert_eq!(spread(0b1), 0b1);
        assert_eq!(spread(0b11), 0b1001);
        assert_eq!(spread(0x3ff), 0x0924_9249);
        let key = |x, y, z| spread(x) | spread(y) << 1 | spread(z) << 2;
        assert_eq!(key(1, 0, 0), 1);
        assert_eq!(key(0, 1, 0), 2);
        assert_eq!(key(0, 0, 1), 4);
        assert_eq!(key(2, 0, 0), 8);
    }

    #[test]
    fn renumbering_keeps_every_face_and_its_orientation() {
        // Two far-apart triangles, the far one listed first.
        let positions = [
            [900, 900, 900],
            [901, 900, 900],
            [900, 901, 900],
            [0, 0, 0],
            [1, 0, 0],
            [0, 1, 0],
        ];
        let triangles = [[0, 1, 2], [5, 3, 4]];
        let order = LocalityOrder::of(&positions, &triangles, 4095);
        // Vertices near the origin come first, then the far cell's, each
        // cell in input order; the near face first, entered where it was.
        assert_eq!(order.vertices, vec![3, 4, 5, 0, 1, 2]);
        assert_eq!(order.triangles, vec![[2, 0, 1], [3, 4, 5]]);
        // Mapped back, the faces are the input's, corners in the same turn.
        let back: Vec<[u32; 3]> = order
            .triangles
            .iter()
            .map(|t| t.map(|v| order.vertices[v as usize]))
            .collect();
        assert_eq!(back, vec![[5, 3, 4], [0, 1, 2]]);
        assert_eq!(order.permute(&positions)[2], [0, 1, 0]);
    }

    #[test]
    fn every_vertex_is_numbered_once() {
        let positions: Vec<[i32; 3]> = (0..500)
            .map(|i| [(i * 37) % 4096, (i * 101) % 4096, (i * 7) % 4096])
            .collect();
        let triangles: Vec<[u32; 3]> = (0..498).map(|i| [i, i + 1, i + 2]).collect();
        let order = LocalityOrder::of(&positions, &triangles, 4095);
        let mut seen = order.vertices.clone();
        seen.sort_unstable();
        assert_eq!(seen, (0..500).collect::<Vec<u32>>());
        assert_eq!(order.triangles.len(), triangles.len());
        let mut back: Vec<[u32; 3]> = order
            .triangles
            .iter()
            .map(|t| t.map(|v| order.vertices[v as usize]))
            .collect();
        back.sort_unstable();
        assert_eq!(back, triangles);
    }
}
