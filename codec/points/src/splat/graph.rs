//! The splat neighbour graph E = {(i, j) : |C_i − C_j| < r_i + r_j}.
//!
//! Built on a uniform grid: every edge is found from its endpoint with the
//! larger radius (ties: the larger index), which needs only the points
//! within 2·r_i of it, so a point looks at cells within its own reach and a
//! few large splats cannot slow the rest. The edge test is the same
//! expression as the brute-force definition, so the edge sets are identical.

use crate::grid::{dist2, Grid};

/// An undirected graph as compressed rows: the neighbours of `i`, ascending,
/// are `neighbours[offsets[i]..offsets[i + 1]]`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Graph {
    pub offsets: Vec<u32>,
    pub neighbours: Vec<u32>,
}

impl Graph {
    pub fn neighbours(&self, i: usize) -> &[u32] {
        &self.neighbours[self.offsets[i] as usize..self.offsets[i + 1] as usize]
    }

    /// Undirected edges.
    pub fn edge_count(&self) -> usize {
        self.neighbours.len() / 2
    }

    /// Builds symmetric rows from edges given once each.
    pub fn from_edges(n: usize, edges: &[(u32, u32)]) -> Graph {
        let mut offsets = vec![0u32; n + 1];
        for &(a, b) in edges {
            offsets[a as usize + 1] += 1;
            offsets[b as usize + 1] += 1;
        }
        for i in 0..n {
            offsets[i + 1] += offsets[i];
        }
        let mut fill = offsets.clone();
        let mut neighbours = vec![0u32; edges.len() * 2];
        for &(a, b) in edges {
            neighbours[fill[a as usize] as usize] = b;
            fill[a as usize] += 1;
            neighbours[fill[b as usize] as usize] = a;
            fill[b as usize] += 1;
        }
        for i in 0..n {
            neighbours[offsets[i] as usize..offsets[i + 1] as usize].sort_unstable();
        }
        Graph {
            offsets,
            neighbours,
        }
    }
}

/// Whether splats i and j overlap: the one expression both builders use.
#[inline]
fn is_edge(ci: [f32; 3], cj: [f32; 3], ri: f32, rj: f32) -> bool {
    let s = ri + rj;
    dist2(ci, cj) < s * s
}

/// Margin, in cells, for the rounding of cell indices: f32 coordinates
/// relative to the grid's corner over at most 2^21 cells err by far less.
const SLACK: f32 = 0.25;

/// The graph, built on a grid (see the module comment).
pub fn neighbour_graph(positions: &[[f32; 3]], radii: &[f32]) -> Graph {
    let n = positions.len();
    assert_eq!(radii.len(), n, "one radius per splat");
    if n == 0 {
        return Graph::from_edges(0, &[]);
    }
    let mut sorted: Vec<f32> = radii.iter().copied().filter(|r| *r > 0.0).collect();
    // Cells wide enough that 90 % of the splats search one ring of cells.
    let typical = if sorted.is_empty() {
        1.0
    } else {
        let at = sorted.len() * 9 / 10;
        *sorted.select_nth_unstable_by(at, f32::total_cmp).1
    };
    let grid = Grid::new(positions, 2.0 * typical / (1.0 - SLACK));
    let cell = grid.cell();
    // `j` is found from `i` when i is the larger endpoint.
    let owns = |i: usize, j: usize| radii[j] < radii[i] || (radii[j] == radii[i] && j < i);
    let mut edges = Vec::with_capacity(n * 7);
    // |C_i − C_j| < r_i + r_j <= 2 r_i, so the cell indices of i and j
    // differ by less than 2 r_i / cell + 1 (plus rounding, below SLACK).
    let reach = |r: f32| ((2.0 * r / cell + SLACK) as u64).saturating_add(1);
    grid.for_each_point_near(
        |cell_points| {
            let r = cell_points
                .iter()
                .map(|&i| radii[i as usize])
                .fold(0.0, f32::max);
            reach(r)
        },
        |i, ci, near| {
            let (iu, ri) = (i as usize, radii[i as usize]);
            // A cell whose (widened) box lies 2 r_i away or more holds no
            // partner i owns; the margin covers the bound's own rounding.
            let bound = (2.0 * ri) * (2.0 * ri) * (1.0 + 1e-4);
            for cell in &near.cells {
                if near.box_dist2(cell, ci) >= bound {
                    continue;
                }
                for (j, cj) in near.points(cell) {
                    let ju = j as usize;
                    if ju != iu && is_edge(ci, cj, ri, radii[ju]) && owns(iu, ju) {
                        edges.push((i, j));
                    }
                }
            }
        },
    );
    Graph::from_edges(n, &edges)
}

/// The O(n²) definition, for tests.
pub fn brute_force_graph(positions: &[[f32; 3]], radii: &[f32]) -> Graph {
    let n = positions.len();
    let mut edges = Vec::new();
    for i in 0..n {
        for j in i + 1..n {
            if is_edge(positions[i], positions[j], radii[i], radii[j]) {
                edges.push((i as u32, j as u32));
            }
        }
    }
    Graph::from_edges(n, &edges)
}
