//! Splat radii: the mean distance to the nearest neighbours.

use crate::grid::Grid;

/// Neighbours averaged for a radius (seed 002, §2).
pub const RADIUS_NEIGHBOURS: usize = 5;

/// r_i = mean distance from point i to its 5 nearest other points (0 for a
/// lone point).
pub fn splat_radii(positions: &[[f32; 3]]) -> Vec<f32> {
    let grid = Grid::for_knn(positions);
    let mut radii = vec![0f32; positions.len()];
    grid.knn_each(RADIUS_NEIGHBOURS, |i, best| {
        if !best.is_empty() {
            radii[i] = best.iter().map(|b| b.0.sqrt()).sum::<f32>() / best.len() as f32;
        }
    });
    radii
}

/// The factor that scales radii computed on all `total` points of a surface
/// for a prefix of `prefix` of them (an even subsample): spacing grows as
/// √(total / prefix).
pub fn prefix_radius_scale(total: usize, prefix: usize) -> f32 {
    if prefix == 0 {
        return 1.0;
    }
    (total as f32 / prefix as f32).sqrt().max(1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn radii_on_a_lattice_are_the_spacing() {
        // A 20 × 20 square lattice of spacing 0.5: an inner point's 5 nearest
        // are 4 at 0.5 and one diagonal at 0.5·√2.
        let pts: Vec<[f32; 3]> = (0..400)
            .map(|k| [(k % 20) as f32 * 0.5, (k / 20) as f32 * 0.5, 0.0])
            .collect();
        let r = splat_radii(&pts);
        let want = (4.0 * 0.5 + 0.5 * 2f32.sqrt()) / 5.0;
        assert!((r[10 * 20 + 10] - want).abs() < 1e-6, "{}", r[210]);
        assert!((prefix_radius_scale(400, 100) - 2.0).abs() < 1e-6);
    }
}
