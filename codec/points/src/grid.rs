//! A uniform grid over a point set: k-nearest-neighbour and fixed-radius
//! queries for normal estimation, splat radii and the splat graph.
//!
//! # Why hand-written
//!
//! The splat graph needs a per-point fixed-radius query (`|C_i − C_j| <
//! r_i + r_j`), which a uniform grid answers without a tree walk, and the
//! whole preprocessing has to build for `wasm32-unknown-unknown`: the kd-tree
//! crate that fits (`kiddo`) pulls stack-switching and SIMD dependencies
//! meant for native builds. One sorted grid serves both queries: points are
//! sorted by cell key (z, y, x major to minor), so the cells `x−R..=x+R` of
//! one (y, z) row are one contiguous run found by a binary search.

/// Points bucketed into cubic cells of side `cell`.
pub struct Grid<'a> {
    points: &'a [[f32; 3]],
    min: [f32; 3],
    cell: f32,
    /// Cells per axis.
    dims: [u64; 3],
    /// Sorted distinct occupied cell keys.
    keys: Vec<u64>,
    /// `starts[c]..starts[c + 1]` indexes `order` for cell `keys[c]`.
    starts: Vec<u32>,
    /// Point indices sorted by cell key.
    order: Vec<u32>,
}

/// Most cells per axis (keys must fit a u64: 3 × 21 bits).
const MAX_DIM: u64 = 1 << 21;

impl<'a> Grid<'a> {
    /// A grid with cells of side `cell` (enlarged if the box would need more
    /// than 2^21 cells on an axis). `points` must be finite.
    pub fn new(points: &'a [[f32; 3]], cell: f32) -> Self {
        let (min, max) = bounds(points);
        let extent = (0..3).map(|a| max[a] - min[a]).fold(0f32, f32::max);
        let mut cell = if cell.is_finite() && cell > 0.0 {
            cell
        } else {
            1.0
        };
        cell = cell
            .max(extent / (MAX_DIM - 2) as f32)
            .max(f32::MIN_POSITIVE);
        let dims = [0, 1, 2].map(|a| ((max[a] - min[a]) / cell) as u64 + 1);
        let mut grid = Grid {
            points,
            min,
            cell,
            dims,
            keys: Vec::new(),
            starts: Vec::new(),
            order: Vec::new(),
        };
        let mut keyed: Vec<(u64, u32)> = points
            .iter()
            .enumerate()
            .map(|(i, p)| (grid.key(grid.coords(*p)), i as u32))
            .collect();
        radsort::sort_by_key(&mut keyed, |k| k.0);
        grid.order = keyed.iter().map(|k| k.1).collect();
        for (i, k) in keyed.iter().enumerate() {
            if grid.keys.last() != Some(&k.0) {
                grid.keys.push(k.0);
                grid.starts.push(i as u32);
            }
        }
        grid.starts.push(points.len() as u32);
        grid
    }

    /// A grid whose cells hold a few points each, for kNN queries.
    pub fn for_knn(points: &'a [[f32; 3]]) -> Self {
        let (min, max) = bounds(points);
        let diag = (0..3)
            .map(|a| (max[a] - min[a]).powi(2))
            .sum::<f32>()
            .sqrt();
        // Scans are surfaces: n points over an area of about diag², so
        // cells of diag / √n hold a few each; refine if they hold many.
        let n = points.len().max(1) as f32;
        let mut cell = (diag / n.sqrt()).max(f32::MIN_POSITIVE) * 2.0;
        for _ in 0..6 {
            let g = Grid::new(points, cell);
            let per_cell = n / g.keys.len().max(1) as f32;
            if per_cell <= 8.0 {
                return g;
            }
            cell *= (4.0 / per_cell).cbrt().max(0.25);
        }
        Grid::new(points, cell)
    }

    pub fn cell(&self) -> f32 {
        self.cell
    }

    fn coords(&self, p: [f32; 3]) -> [u64; 3] {
        [0, 1, 2].map(|a| {
            let c = ((p[a] - self.min[a]) / self.cell).max(0.0) as u64;
            c.min(self.dims[a] - 1)
        })
    }

    fn key(&self, c: [u64; 3]) -> u64 {
        (c[2] * self.dims[1] + c[1]) * self.dims[0] + c[0]
    }

    /// Calls `f(j)` for every point in the cells within `reach` cells (per
    /// axis) of the cell of `p`.
    #[inline]
    pub fn for_each_near(&self, p: [f32; 3], reach: u64, mut f: impl FnMut(u32)) {
        let c = self.coords(p);
        let lo = c.map(|v| v.saturating_sub(reach));
        let hi = [0, 1, 2].map(|a| (c[a] + reach).min(self.dims[a] - 1));
        for z in lo[2]..=hi[2] {
            for y in lo[1]..=hi[1] {
                let first = self.key([lo[0], y, z]);
                let last = self.key([hi[0], y, z]);
                let mut k = self.keys.partition_point(|&key| key < first);
                while k < self.keys.len() && self.keys[k] <= last {
                    let (s, e) = (self.starts[k] as usize, self.starts[k + 1] as usize);
                    for &j in &self.order[s..e] {
                        f(j);
                    }
                    k += 1;
                }
            }
        }
    }

    /// The `k` nearest other points of point `i` (ascending distance; ties by
    /// index), as (squared distance, index); fewer if the cloud is smaller.
    pub fn knn(&self, i: usize, k: usize, out: &mut Vec<(f32, u32)>) {
        out.clear();
        let p = self.points[i];
        let max_reach = self.dims.iter().copied().max().unwrap_or(1);
        let mut reach = 1;
        loop {
            out.clear();
            self.for_each_near(p, reach, |j| {
                if j as usize != i {
                    insert_best(out, k, (dist2(p, self.points[j as usize]), j));
                }
            });
            // Every point outside the searched cells is farther than this.
            let covered = reach as f32 * self.cell;
            let done = out.len() == k && out[k - 1].0 <= covered * covered;
            if done || reach >= max_reach {
                return;
            }
            reach *= 2;
        }
    }
}

/// Inserts `cand` into the ascending list `best` of at most `k` entries.
#[inline]
fn insert_best(best: &mut Vec<(f32, u32)>, k: usize, cand: (f32, u32)) {
    if best.len() == k {
        match best.last() {
            Some(&last) if cand < last => {
                best.pop();
            }
            _ => return,
        }
    }
    let at = best.partition_point(|&b| b < cand);
    best.insert(at, cand);
}

#[inline]
pub fn dist2(a: [f32; 3], b: [f32; 3]) -> f32 {
    let d = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    d[0] * d[0] + d[1] * d[1] + d[2] * d[2]
}

/// Component-wise minimum and maximum (zeros for no points).
pub fn bounds(points: &[[f32; 3]]) -> ([f32; 3], [f32; 3]) {
    if points.is_empty() {
        return ([0.0; 3], [0.0; 3]);
    }
    let mut min = [f32::INFINITY; 3];
    let mut max = [f32::NEG_INFINITY; 3];
    for p in points {
        for a in 0..3 {
            min[a] = min[a].min(p[a]);
            max[a] = max[a].max(p[a]);
        }
    }
    (min, max)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn knn_matches_brute_force() {
        let mut s = 1u64;
        let pts: Vec<[f32; 3]> = (0..3000)
            .map(|_| [0, 1, 2].map(|_| crate::testing::unit(&mut s) * 10.0))
            .collect();
        let g = Grid::for_knn(&pts);
        let mut out = Vec::new();
        for i in (0..pts.len()).step_by(37) {
            g.knn(i, 8, &mut out);
            let mut all: Vec<(f32, u32)> = (0..pts.len())
                .filter(|&j| j != i)
                .map(|j| (dist2(pts[i], pts[j]), j as u32))
                .collect();
            all.sort_by(|a, b| a.partial_cmp(b).unwrap());
            assert_eq!(out, all[..8].to_vec(), "point {i}");
        }
    }
}
