//! Gaussian curvature per vertex by the angle defect over the mixed area
//! (Meyer et al. 2002; seed 001, Alg. 1), which orders the "curvature"
//! cover. The seed's Alg. 1 sums the whole one-ring into every face; here
//! each face (v, vi, vj) adds its own share only (SEEDS.md 001):
//! ⅛(|v−vi|² cot∠vj + |v−vj|² cot∠vi) when it is not obtuse, half its area
//! when obtuse at v, a quarter otherwise.

use std::f64::consts::{PI, TAU};

use glam::DVec3;
use vitrine_geodesic::{Surface, NONE};

/// K̂ = (2π − Σθ) / A_mixed at interior vertices, (π − Σθ) / A_mixed on
/// borders; 0 where the mixed area vanishes or for blocked vertices.
pub(super) fn gaussian_curvature(surface: &Surface) -> Vec<f64> {
    let n = surface.vertex_count();
    let mut angle = vec![0.0; n];
    let mut area = vec![0.0; n];
    let mut border = vec![false; n];
    for (f, t) in surface.triangles().iter().enumerate() {
        let p = t.map(|v| surface.position(v));
        let twice_area = (p[1] - p[0]).cross(p[2] - p[0]).length();
        for k in 0..3 {
            if surface.across(f as u32, k) == NONE {
                border[t[k] as usize] = true;
                border[t[(k + 1) % 3] as usize] = true;
            }
            let (v, i, j) = (p[k], p[(k + 1) % 3], p[(k + 2) % 3]);
            let at = |o: DVec3, x: DVec3, y: DVec3| (x - o).angle_between(y - o);
            let (av, ai, aj) = (at(v, i, j), at(i, j, v), at(j, v, i));
            angle[t[k] as usize] += av;
            area[t[k] as usize] += if av > PI / 2.0 {
                twice_area / 4.0
            } else if ai > PI / 2.0 || aj > PI / 2.0 {
                twice_area / 8.0
            } else {
                let cot = |a: f64| a.cos() / a.sin();
                (v.distance_squared(i) * cot(aj) + v.distance_squared(j) * cot(ai)) / 8.0
            };
        }
    }
    (0..n)
        .map(|v| {
            let full = if border[v] { PI } else { TAU };
            if area[v] > 0.0 && !surface.is_blocked(v as u32) {
                (full - angle[v]) / area[v]
            } else {
                0.0
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_unit_sphere_has_curvature_one_and_the_plane_none() {
        let sphere = Surface::new(&vitrine_samples::icosphere(4)).unwrap();
        let k = gaussian_curvature(&sphere);
        let mean = k.iter().sum::<f64>() / k.len() as f64;
        assert!((mean - 1.0).abs() < 0.02, "mean K {mean}");
        let plane = gaussian_curvature(&Surface::new(&vitrine_samples::grid(8)).unwrap());
        for j in 1..8 {
            for i in 1..8 {
                assert!(
                    plane[j * 9 + i].abs() < 1e-9,
                    "({i}, {j}): {}",
                    plane[j * 9 + i]
                );
            }
        }
    }
}
