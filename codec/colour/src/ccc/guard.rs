//! The data-driven decimation guard (thesis §5.3.1, Algorithm 2): a patch
//! is decimated only if every face of its retriangulation stays in cells.

use glam::DVec3;

use super::grid::{overlaps_a_cube, Grid};
use vitrine_codec::{CandidatePatch, PatchGuard, Quantization};

/// Refuses retriangulations with a face that crosses an empty cube.
#[derive(Clone, Debug)]
pub struct CellGuard {
    grid: Grid,
    occupied: Vec<bool>,
    quantization: Quantization,
}

impl CellGuard {
    pub(crate) fn new(grid: Grid, cell_of_cube: &[u32], quantization: Quantization) -> Self {
        CellGuard {
            grid,
            occupied: cell_of_cube.iter().map(|&c| c != u32::MAX).collect(),
            quantization,
        }
    }

    /// Whether the triangle (quantized corners) overlaps cells only.
    pub fn triangle_in_cells(&self, tri: [[i32; 3]; 3]) -> bool {
        let tri = tri.map(|q| DVec3::from(self.quantization.dequantize(q).map(f64::from)));
        let lo = tri[0].min(tri[1]).min(tri[2]);
        let hi = tri[0].max(tri[1]).max(tri[2]);
        if !self.grid.contains(self.grid.cube_of(lo)) || !self.grid.contains(self.grid.cube_of(hi))
        {
            return false;
        }
        // Inside the cells unless it meets a cube that is not one.
        !overlaps_a_cube(&self.grid, tri, |i| !self.occupied[i])
    }
}

impl PatchGuard for CellGuard {
    fn allows(&self, patch: &CandidatePatch<'_>) -> bool {
        patch
            .triangles
            .iter()
            .all(|t| self.triangle_in_cells(t.map(|i| patch.polygon[i as usize])))
    }
}
