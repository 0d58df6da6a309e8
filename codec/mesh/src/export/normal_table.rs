//! The 162 unit directions an MD2 vertex's normal index points into.
//!
//! Quake II's own table (`anorms.h`) is part of id Software's GPL-2 source
//! release, which Vitrine (MIT OR Apache-2.0) cannot include, so this one is
//! generated here instead: the vertices of an icosahedron whose faces are
//! split at their edge midpoints twice (12 → 42 → 162 vertices), pushed onto
//! the unit sphere. It has the same size and near-uniform spread as id's
//! table (also a 162-vertex geodesic sphere), but not its order: an engine
//! using id's table lights our files with other normals. Vitrine itself
//! recomputes normals from the geometry on import and never reads them.

use std::collections::HashMap;
use std::sync::OnceLock;

/// Entries in the table.
pub const NORMAL_COUNT: usize = 162;

/// The table, in Quake's axes (any rotation would do; the icosahedron's
/// vertices sit on the golden rectangles of the coordinate planes).
pub fn normal_table() -> &'static [[f32; 3]; NORMAL_COUNT] {
    static TABLE: OnceLock<[[f32; 3]; NORMAL_COUNT]> = OnceLock::new();
    TABLE.get_or_init(build)
}

/// Index of the table entry closest to direction `n` (largest dot product,
/// lowest index on ties; 0 for a zero or non-finite vector).
pub fn nearest_normal(n: [f32; 3]) -> u8 {
    let mut best = (f32::NEG_INFINITY, 0usize);
    for (i, t) in normal_table().iter().enumerate() {
        let d = t[0] * n[0] + t[1] * n[1] + t[2] * n[2];
        if d > best.0 {
            best = (d, i);
        }
    }
    best.1 as u8
}

fn build() -> [[f32; 3]; NORMAL_COUNT] {
    let g = (1.0 + 5f64.sqrt()) / 2.0;
    let mut points: Vec<[f64; 3]> = vec![
        [-1.0, g, 0.0],
        [1.0, g, 0.0],
        [-1.0, -g, 0.0],
        [1.0, -g, 0.0],
        [0.0, -1.0, g],
        [0.0, 1.0, g],
        [0.0, -1.0, -g],
        [0.0, 1.0, -g],
        [g, 0.0, -1.0],
        [g, 0.0, 1.0],
        [-g, 0.0, -1.0],
        [-g, 0.0, 1.0],
    ];
    let mut faces: Vec<[usize; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..2 {
        let mut mid: HashMap<(usize, usize), usize> = HashMap::new();
        let mut next = Vec::with_capacity(faces.len() * 4);
        for [a, b, c] in faces {
            let mut m = |x: usize, y: usize| {
                *mid.entry((x.min(y), x.max(y))).or_insert_with(|| {
                    let (p, q) = (points[x], points[y]);
                    points.push(std::array::from_fn(|k| (p[k] + q[k]) / 2.0));
                    points.len() - 1
                })
            };
            let (ab, bc, ca) = (m(a, b), m(b, c), m(c, a));
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        faces = next;
        for p in &mut points {
            let l = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
            *p = p.map(|x| x / l);
        }
    }
    std::array::from_fn(|i| points[i].map(|x| x as f32))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_table_is_162_distinct_unit_directions_spread_evenly() {
        let t = normal_table();
        let mut closest = f32::INFINITY;
        for (i, a) in t.iter().enumerate() {
            let l = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
            assert!((l - 1.0).abs() < 1e-6);
            for b in &t[i + 1..] {
                let d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
                closest = closest.min(d.acos());
            }
            assert_eq!(nearest_normal(*a) as usize, i);
        }
        // A frequency-4 geodesic sphere: neighbours 15–19° apart.
        assert!(closest > 14f32.to_radians(), "{}", closest.to_degrees());
        assert_eq!(nearest_normal([0.0, 0.0, 0.0]), 0);
    }
}
