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
    /// The points in that order (queries scan these contiguously).
    sorted: Vec<[f32; 3]>,
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
            sorted: Vec::new(),
        };
        let mut keyed: Vec<(u64, u32)> = points
            .iter()
            .enumerate()
            .map(|(i, p)| (grid.key(grid.coords(*p)), i as u32))
            .collect();
        radsort::sort_by_key(&mut keyed, |k| k.0);
        grid.order = keyed.iter().map(|k| k.1).collect();
        grid.sorted = grid.order.iter().map(|&i| points[i as usize]).collect();
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
        // Aim for 3–8 points per occupied cell, so that one ring of cells
        // usually holds the nearest few.
        for _ in 0..6 {
            let g = Grid::new(points, cell);
            let per_cell = n / g.keys.len().max(1) as f32;
            if (3.0..=8.0).contains(&per_cell) || g.keys.len() == 1 {
                return g;
            }
            // Occupied cells of a surface scale with the cell's area.
            cell *= (5.0 / per_cell).sqrt().clamp(0.25, 4.0);
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

    fn cell_coords(&self, key: u64) -> [u64; 3] {
        let x = key % self.dims[0];
        let yz = key / self.dims[0];
        [x, yz % self.dims[1], yz / self.dims[1]]
    }

    /// The ranges (into the sorted order) of the cells within `reach` cells
    /// (per axis) of cell `c`: one range per (y, z) row.
    fn rows(&self, c: [u64; 3], reach: u64, out: &mut Vec<(u32, u32)>) {
        out.clear();
        self.each_row(c, reach, |a, b| out.push((self.starts[a], self.starts[b])));
    }

    /// `f(a, b)` for the occupied cells `keys[a..b]` of each (y, z) row
    /// within `reach` cells of cell `c` (non-empty rows only).
    fn each_row(&self, c: [u64; 3], reach: u64, mut f: impl FnMut(usize, usize)) {
        let lo = c.map(|v| v.saturating_sub(reach));
        let hi = [0, 1, 2].map(|a| (c[a] + reach).min(self.dims[a] - 1));
        for z in lo[2]..=hi[2] {
            for y in lo[1]..=hi[1] {
                let first = self.key([lo[0], y, z]);
                let last = self.key([hi[0], y, z]);
                let a = self.keys.partition_point(|&key| key < first);
                let b = a + self.keys[a..].partition_point(|&key| key <= last);
                if a < b {
                    f(a, b);
                }
            }
        }
    }

    /// The occupied cells within `reach` cells (per axis) of cell `c`, each
    /// with its box widened by [`BOX_SLACK`] cells on every side (so that a
    /// point's true position lies inside its cell's box whatever the
    /// rounding of its cell index), nearest to `c` first.
    fn near_cells(&self, c: [u64; 3], reach: u64, out: &mut Vec<NearCell>) {
        out.clear();
        self.each_row(c, reach, |a, b| {
            for k in a..b {
                let cc = self.cell_coords(self.keys[k]);
                let lo = [0, 1, 2].map(|ax| self.min[ax] + (cc[ax] as f32 - BOX_SLACK) * self.cell);
                let off = [0, 1, 2].map(|ax| cc[ax].abs_diff(c[ax]));
                out.push(NearCell {
                    start: self.starts[k],
                    end: self.starts[k + 1],
                    lo,
                    ring: off[0] * off[0] + off[1] * off[1] + off[2] * off[2],
                });
            }
        });
        out.sort_unstable_by_key(|n| n.ring);
    }

    /// Calls `f(j)` for every point in the cells within `reach` cells (per
    /// axis) of the cell of `p`.
    pub fn for_each_near(&self, p: [f32; 3], reach: u64, mut f: impl FnMut(u32)) {
        let mut rows = Vec::new();
        self.rows(self.coords(p), reach, &mut rows);
        for (s, e) in rows {
            for &j in &self.order[s as usize..e as usize] {
                f(j);
            }
        }
    }

    /// Visits every point, cell by cell: `f(i, p_i, near)` where `near`
    /// yields (index, position) of every point within `reach(cell's points)`
    /// cells of the point's cell, the point included. Cell by cell, so the
    /// rows are looked up once per cell and the scans stay in cache.
    pub fn for_each_point_near(
        &self,
        reach: impl Fn(&[u32]) -> u64,
        mut f: impl FnMut(u32, [f32; 3], &Near<'_>),
    ) {
        let mut near = Near {
            grid: self,
            cells: Vec::new(),
            extent: self.cell * (1.0 + 2.0 * BOX_SLACK),
        };
        for (k, &key) in self.keys.iter().enumerate() {
            let (s, e) = (self.starts[k] as usize, self.starts[k + 1] as usize);
            let r = reach(&self.order[s..e]);
            self.near_cells(self.cell_coords(key), r, &mut near.cells);
            for t in s..e {
                f(self.order[t], self.sorted[t], &near);
            }
        }
    }

    /// Calls `f(i, neighbours)` for every point with its `k` nearest other
    /// points (ascending (squared distance, index)), cell by cell.
    pub fn knn_each(&self, k: usize, mut f: impl FnMut(usize, &[(f32, u32)])) {
        let mut best: Vec<(f32, u32)> = Vec::with_capacity(k + 1);
        let covered = self.cell * self.cell;
        self.for_each_point_near(
            |_| 1,
            |i, p, near| {
                best.clear();
                // Nearest cells first; once k are found, a cell whose box is
                // farther than the k-th cannot improve them.
                for cell in &near.cells {
                    if best.len() == k && near.box_dist2(cell, p) > best[k - 1].0 {
                        continue;
                    }
                    for (j, q) in near.points(cell) {
                        if j != i {
                            insert_best(&mut best, k, (dist2(p, q), j));
                        }
                    }
                }
                // Everything outside one ring of cells is farther than a cell.
                if best.len() < k || best[k - 1].0 > covered {
                    self.knn(i as usize, k, &mut best);
                }
                f(i as usize, &best);
            },
        );
    }

    /// The `k` nearest other points of point `i` (ascending distance; ties by
    /// index), as (squared distance, index); fewer if the cloud is smaller.
    pub fn knn(&self, i: usize, k: usize, out: &mut Vec<(f32, u32)>) {
        out.clear();
        let p = self.points[i];
        let max_reach = self.dims.iter().copied().max().unwrap_or(1);
        let mut reach = 1;
        let mut rows = Vec::new();
        loop {
            out.clear();
            self.rows(self.coords(p), reach, &mut rows);
            for &(a, b) in &rows {
                let (a, b) = (a as usize, b as usize);
                for (&j, &q) in self.order[a..b].iter().zip(&self.sorted[a..b]) {
                    if j as usize != i {
                        insert_best(out, k, (dist2(p, q), j));
                    }
                }
            }
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

/// Widening of a cell's box, in cells, for the rounding of cell indices
/// (f32 coordinates over at most 2^21 cells err by far less).
const BOX_SLACK: f32 = 0.25;

/// An occupied cell near a query's cell.
#[derive(Clone, Copy, Debug)]
pub struct NearCell {
    /// `start..end` indexes the sorted order.
    pub start: u32,
    pub end: u32,
    /// Lower corner of the cell's widened box.
    lo: [f32; 3],
    /// Squared offset in cells from the query's cell (0 for that cell).
    ring: u64,
}

/// The occupied cells around one cell (see [`Grid::for_each_point_near`]).
pub struct Near<'g> {
    grid: &'g Grid<'g>,
    pub cells: Vec<NearCell>,
    /// Side of a widened box.
    extent: f32,
}

impl Near<'_> {
    /// (index, position) of each point.
    #[inline]
    pub fn iter(&self) -> impl Iterator<Item = (u32, [f32; 3])> + '_ {
        self.cells.iter().flat_map(|c| self.points(c))
    }

    /// (index, position) of each point of `cell`.
    #[inline]
    pub fn points(&self, cell: &NearCell) -> impl Iterator<Item = (u32, [f32; 3])> + '_ {
        let (a, b) = (cell.start as usize, cell.end as usize);
        let g = self.grid;
        g.order[a..b]
            .iter()
            .copied()
            .zip(g.sorted[a..b].iter().copied())
    }

    /// A lower bound on the squared distance from `p` to any point of
    /// `cell` (0 when `p` is inside its widened box).
    #[inline]
    pub fn box_dist2(&self, cell: &NearCell, p: [f32; 3]) -> f32 {
        let mut d2 = 0.0;
        for (&lo, &x) in cell.lo.iter().zip(&p) {
            let d = (lo - x).max(x - (lo + self.extent)).max(0.0);
            d2 += d * d;
        }
        d2
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
        let random: Vec<[f32; 3]> = (0..3000)
            .map(|_| [0, 1, 2].map(|_| crate::testing::unit(&mut s) * 10.0))
            .collect();
        // A lattice: many exact ties (broken by index) and points on the
        // cells' boundaries.
        let lattice: Vec<[f32; 3]> = (0..2744)
            .map(|k| [k % 14, k / 14 % 14, k / 196].map(|c| c as f32 * 0.25))
            .collect();
        for pts in [random, lattice] {
            knn_agrees(&pts);
        }
    }

    fn knn_agrees(pts: &[[f32; 3]]) {
        let g = Grid::for_knn(pts);
        let mut out = Vec::new();
        for i in (0..pts.len()).step_by(37) {
            g.knn(i, 8, &mut out);
            let mut each = Vec::new();
            g.knn_each(8, |j, b| {
                if j == i {
                    each = b.to_vec();
                }
            });
            assert_eq!(each, out, "point {i}");
            let mut all: Vec<(f32, u32)> = (0..pts.len())
                .filter(|&j| j != i)
                .map(|j| (dist2(pts[i], pts[j]), j as u32))
                .collect();
            all.sort_by(|a, b| a.partial_cmp(b).unwrap());
            assert_eq!(out, all[..8].to_vec(), "point {i}");
        }
    }
}
