//! The axis-aligned grid of cubes over the model, and the exact
//! triangle–cube overlap test that decides which cubes are cells.

use glam::{DVec3, IVec3};

/// Cubes of edge `cell_size` from `origin`, `dims` per axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grid {
    pub origin: DVec3,
    pub cell_size: f64,
    pub dims: IVec3,
}

/// Most cubes a grid may have: cube numbers are 24-bit in the cell texture.
pub const MAX_CUBES: u64 = 1 << 24;

impl Grid {
    /// A grid over the bounding cube `[min, max]` with about `cubes_on_longest`
    /// cubes along the longest axis; the model sits inside with half a cube to spare.
    /// Dimensions are clamped to 2²⁰ cubes per axis; check [`Grid::cube_count`].
    pub fn around(min: DVec3, max: DVec3, cell_size: f64) -> Grid {
        let extent = (max - min).max(DVec3::splat(0.0));
        let dims = ((extent / cell_size).floor() + DVec3::ONE)
            .clamp(DVec3::ONE, DVec3::splat(1048576.0))
            .as_ivec3();
        let slack = DVec3::splat(cell_size) * dims.as_dvec3() - extent;
        Grid {
            origin: min - slack * 0.5,
            cell_size,
            dims,
        }
    }

    pub fn cube_count(&self) -> u64 {
        // At most 2⁶⁰ after the clamp in `around`: no overflow.
        self.dims.x as u64 * self.dims.y as u64 * self.dims.z as u64
    }

    /// Linear number of cube `c` (x fastest), as in the cell texture.
    #[inline]
    pub fn index(&self, c: IVec3) -> usize {
        c.x as usize + self.dims.x as usize * (c.y as usize + self.dims.y as usize * c.z as usize)
    }

    #[inline]
    pub fn contains(&self, c: IVec3) -> bool {
        c.cmpge(IVec3::ZERO).all() && c.cmplt(self.dims).all()
    }

    /// The cube containing `p` (possibly outside the grid).
    #[inline]
    pub fn cube_of(&self, p: DVec3) -> IVec3 {
        ((p - self.origin) / self.cell_size).floor().as_ivec3()
    }

    #[inline]
    pub fn cube_min(&self, c: IVec3) -> DVec3 {
        self.origin + c.as_dvec3() * self.cell_size
    }

    /// Cubes whose (closed) box, grown by `margin` on every side, may touch
    /// the box `[lo, hi]`; clamped to the grid.
    pub fn cube_range(&self, lo: DVec3, hi: DVec3, margin: f64) -> (IVec3, IVec3) {
        let a = self.cube_of(lo - DVec3::splat(margin)).max(IVec3::ZERO);
        let b = self
            .cube_of(hi + DVec3::splat(margin))
            .min(self.dims - IVec3::ONE);
        (a, b)
    }
}

/// Exact separating-axis test (Akenine-Möller 2001) between a triangle and
/// the closed box centred at `centre` with half-extent `half`. Touching
/// counts as overlapping, so a face along a cube's side belongs to both cubes.
pub fn triangle_overlaps_box(tri: [DVec3; 3], centre: DVec3, half: DVec3) -> bool {
    let v = tri.map(|p| p - centre);
    // The box's own axes.
    for k in 0..3 {
        let lo = v[0][k].min(v[1][k]).min(v[2][k]);
        let hi = v[0][k].max(v[1][k]).max(v[2][k]);
        if lo > half[k] || hi < -half[k] {
            return false;
        }
    }
    let e = [v[1] - v[0], v[2] - v[1], v[0] - v[2]];
    // The triangle's plane.
    let n = e[0].cross(e[1]);
    let r = half.dot(n.abs());
    let s = n.dot(v[0]);
    if s.abs() > r {
        return false;
    }
    // Cross products of edges with the box axes.
    for edge in e {
        for axis in [DVec3::X, DVec3::Y, DVec3::Z] {
            let a = axis.cross(edge);
            if a == DVec3::ZERO {
                continue;
            }
            let p = [a.dot(v[0]), a.dot(v[1]), a.dot(v[2])];
            let lo = p[0].min(p[1]).min(p[2]);
            let hi = p[0].max(p[1]).max(p[2]);
            let r = half.dot(a.abs());
            if lo > r || hi < -r {
                return false;
            }
        }
    }
    true
}

/// Calls `f` for every grid cube the triangle overlaps (grown by `margin`).
pub fn for_each_overlapped_cube(
    grid: &Grid,
    tri: [DVec3; 3],
    margin: f64,
    mut f: impl FnMut(IVec3),
) {
    let half = DVec3::splat(grid.cell_size * 0.5 + margin);
    for (c, centre) in cubes_near(grid, tri, margin) {
        if triangle_overlaps_box(tri, centre, half) {
            f(c);
        }
    }
}

/// Whether the triangle overlaps a cube whose index satisfies `wanted`.
/// `wanted` is asked first, so the exact test runs on those cubes alone,
/// and the search stops at the first overlap: the guard asks this of every
/// new face of every candidate patch, and usually every cube near a face is
/// a cell.
pub fn overlaps_a_cube(grid: &Grid, tri: [DVec3; 3], wanted: impl Fn(usize) -> bool) -> bool {
    let half = DVec3::splat(grid.cell_size * 0.5);
    cubes_near(grid, tri, 0.0)
        .any(|(c, centre)| wanted(grid.index(c)) && triangle_overlaps_box(tri, centre, half))
}

/// The cubes of the grid the triangle's bounding box (grown by `margin`)
/// touches, with their centres.
fn cubes_near(
    grid: &Grid,
    tri: [DVec3; 3],
    margin: f64,
) -> impl Iterator<Item = (IVec3, DVec3)> + '_ {
    let lo = tri[0].min(tri[1]).min(tri[2]);
    let hi = tri[0].max(tri[1]).max(tri[2]);
    let (a, b) = grid.cube_range(lo, hi, margin);
    (a.z..=b.z).flat_map(move |z| {
        (a.y..=b.y).flat_map(move |y| {
            (a.x..=b.x).map(move |x| {
                let c = IVec3::new(x, y, z);
                (c, grid.cube_min(c) + DVec3::splat(grid.cell_size * 0.5))
            })
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn d(x: f64, y: f64, z: f64) -> DVec3 {
        DVec3::new(x, y, z)
    }

    #[test]
    fn overlap_test_separates_and_touches() {
        let half = DVec3::splat(0.5);
        // Inside.
        assert!(triangle_overlaps_box(
            [d(0., 0., 0.), d(0.1, 0., 0.), d(0., 0.1, 0.)],
            DVec3::ZERO,
            half
        ));
        // Far away on x.
        assert!(!triangle_overlaps_box(
            [d(2., 0., 0.), d(3., 0., 0.), d(2., 1., 0.)],
            DVec3::ZERO,
            half
        ));
        // A big triangle whose plane cuts the box though no vertex is inside.
        assert!(triangle_overlaps_box(
            [d(-5., -5., 0.), d(5., -5., 0.), d(0., 5., 0.)],
            DVec3::ZERO,
            half
        ));
        // Plane misses the box: all vertices at z = 0.6.
        assert!(!triangle_overlaps_box(
            [d(-5., -5., 0.6), d(5., -5., 0.6), d(0., 5., 0.6)],
            DVec3::ZERO,
            half
        ));
        // Diagonal triangle passing near a corner: bounding boxes overlap, the triangle does not.
        assert!(!triangle_overlaps_box(
            [d(0.9, 0.9, -1.), d(2., 0.6, -1.), d(0.6, 2., 3.)],
            DVec3::ZERO,
            half
        ));
        // Touching a face counts.
        assert!(triangle_overlaps_box(
            [d(0.5, 0., 0.), d(1., 0., 0.), d(1., 1., 0.)],
            DVec3::ZERO,
            half
        ));
    }

    #[test]
    fn a_wanted_cube_is_met_exactly_when_the_sweep_meets_one() {
        let g = Grid::around(d(0., 0., 0.), d(6., 6., 6.), 1.0);
        // Every third cube is wanted.
        let wanted = |i: usize| i.is_multiple_of(3);
        let mut seed = 11u64;
        let mut coordinate = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 40) as f64 / (1u64 << 24) as f64 * 6.0
        };
        let (mut met, mut missed) = (0, 0);
        for _ in 0..5_000 {
            let a = d(coordinate(), coordinate(), coordinate());
            // Small triangles, as a patch's faces are, near a cube's size.
            let mut near = || a + (d(coordinate(), coordinate(), coordinate()) - 3.0) * 0.3;
            let tri = [a, near(), near()];
            let mut swept = false;
            for_each_overlapped_cube(&g, tri, 0.0, |c| swept |= wanted(g.index(c)));
            assert_eq!(overlaps_a_cube(&g, tri, wanted), swept, "{tri:?}");
            if swept {
                met += 1;
            } else {
                missed += 1;
            }
        }
        // Both answers were exercised.
        assert!(met > 500 && missed > 500, "{met} {missed}");
    }

    #[test]
    fn grid_covers_the_box_with_slack() {
        let g = Grid::around(d(0., 0., 0.), d(10., 4., 1.), 1.0);
        assert_eq!(g.dims, IVec3::new(11, 5, 2));
        assert!(g.contains(g.cube_of(d(0., 0., 0.))));
        assert!(g.contains(g.cube_of(d(10., 4., 1.))));
        let mut hit = Vec::new();
        for_each_overlapped_cube(
            &g,
            [d(0.2, 0.2, 0.5), d(0.3, 0.2, 0.5), d(0.2, 0.3, 0.5)],
            0.0,
            |c| hit.push(c),
        );
        assert_eq!(hit.len(), 1);
    }
}
