//! Normals for clouds that have none: PCA over the k nearest neighbours,
//! made robust at sharp edges by letting each point take the best-fitting
//! plane among its neighbours' PCA planes (two rings) (a neighbourhood straddling a
//! crease fits no plane well; one beside it, on the point's own face, fits
//! it exactly), then one consistent orientation by propagation along a minimum spanning
//! tree of the kNN graph (weights 1 − |n_i·n_j|, Hoppe et al. 1992), seeded
//! outward at the point farthest from the centroid.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use crate::grid::Grid;

/// Neighbours used by [`estimate_normals`] (the point itself included).
pub const DEFAULT_K: usize = 12;

/// Unit normals for `points` (finite), consistently oriented per connected
/// part of the kNN graph, outward where the part is closed.
pub fn estimate_normals(points: &[[f32; 3]], k: usize) -> Vec<[f32; 3]> {
    let n = points.len();
    if n == 0 {
        return Vec::new();
    }
    let k = k.clamp(3, 64).min(n.saturating_sub(1)).max(1);
    let grid = Grid::for_knn(points);
    // Rows of k neighbours; short rows (tiny clouds) padded with the point.
    let mut nbrs: Vec<u32> = (0..n * k).map(|e| (e / k) as u32).collect();
    grid.knn_each(k, |i, best| {
        for (slot, b) in nbrs[i * k..].iter_mut().zip(best) {
            *slot = b.1;
        }
    });
    let planes: Vec<Plane> = (0..n)
        .map(|i| pca_plane(points, i, &nbrs[i * k..(i + 1) * k]))
        .collect();
    let mut normals: Vec<[f32; 3]> = (0..n)
        .map(|i| {
            // The point's own plane and those of its neighbours and theirs.
            let ring = |j: u32| nbrs[j as usize * k..(j as usize + 1) * k].iter().copied();
            let cands = std::iter::once(i as u32)
                .chain(ring(i as u32))
                .chain(ring(i as u32).flat_map(ring));
            let score = |j: u32| {
                let pl = &planes[j as usize];
                let d = [0, 1, 2].map(|a| points[i][a] - pl.centroid[a]);
                dot(pl.normal, d).abs() + pl.rms
            };
            let pick = cands
                .min_by(|&a, &b| score(a).total_cmp(&score(b)))
                .unwrap_or(i as u32);
            planes[pick as usize].normal
        })
        .collect();
    orient(points, &mut normals, &nbrs, k);
    normals
}

/// A neighbourhood's least-squares plane.
struct Plane {
    normal: [f32; 3],
    centroid: [f32; 3],
    /// RMS distance of the neighbourhood from the plane.
    rms: f32,
}

/// The plane through the centroid of point `i` and `nbrs`, normal to the
/// eigenvector of the smallest eigenvalue of their covariance.
fn pca_plane(points: &[[f32; 3]], i: usize, nbrs: &[u32]) -> Plane {
    let idx = std::iter::once(i).chain(nbrs.iter().map(|&j| j as usize));
    let m = (nbrs.len() + 1) as f64;
    let mut c = [0f64; 3];
    for j in idx.clone() {
        for a in 0..3 {
            c[a] += f64::from(points[j][a]) / m;
        }
    }
    let mut cov = [[0f64; 3]; 3];
    for j in idx {
        let d = [0, 1, 2].map(|a| f64::from(points[j][a]) - c[a]);
        for r in 0..3 {
            for s in 0..3 {
                cov[r][s] += d[r] * d[s];
            }
        }
    }
    let (normal, lambda) = smallest_eigenvector(cov);
    Plane {
        normal,
        centroid: c.map(|v| v as f32),
        rms: (lambda.max(0.0) / m).sqrt() as f32,
    }
}

/// Unit eigenvector of the smallest eigenvalue of a symmetric 3×3 matrix
/// (closed-form eigenvalues, then the widest cross product of the rows of
/// A − λI), and λ; [0, 0, 1] for a degenerate neighbourhood.
pub(crate) fn smallest_eigenvector(a: [[f64; 3]; 3]) -> ([f32; 3], f64) {
    let p1 = a[0][1].powi(2) + a[0][2].powi(2) + a[1][2].powi(2);
    let q = (a[0][0] + a[1][1] + a[2][2]) / 3.0;
    let p2 = (a[0][0] - q).powi(2) + (a[1][1] - q).powi(2) + (a[2][2] - q).powi(2) + 2.0 * p1;
    let p = (p2 / 6.0).sqrt();
    if p.is_nan() || p <= 1e-300 {
        return ([0.0, 0.0, 1.0], q);
    }
    let b: [[f64; 3]; 3] = std::array::from_fn(|r| {
        std::array::from_fn(|s| (a[r][s] - if r == s { q } else { 0.0 }) / p)
    });
    let det = b[0][0] * (b[1][1] * b[2][2] - b[1][2] * b[2][1])
        - b[0][1] * (b[1][0] * b[2][2] - b[1][2] * b[2][0])
        + b[0][2] * (b[1][0] * b[2][1] - b[1][1] * b[2][0]);
    let phi = (det / 2.0).clamp(-1.0, 1.0).acos() / 3.0;
    // Smallest of the three eigenvalues q + 2p cos(phi + 2πk/3).
    let lambda = q + 2.0 * p * (phi + 2.0 * std::f64::consts::PI / 3.0).cos();
    let m: [[f64; 3]; 3] = std::array::from_fn(|r| {
        std::array::from_fn(|s| a[r][s] - if r == s { lambda } else { 0.0 })
    });
    let cross = |u: [f64; 3], v: [f64; 3]| {
        [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ]
    };
    let cands = [cross(m[0], m[1]), cross(m[0], m[2]), cross(m[1], m[2])];
    let norm2 = |v: [f64; 3]| v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
    let best = cands
        .into_iter()
        .max_by(|x, y| norm2(*x).total_cmp(&norm2(*y)))
        .unwrap_or([0.0, 0.0, 1.0]);
    let l = norm2(best).sqrt();
    if l.is_nan() || l <= 0.0 {
        return ([0.0, 0.0, 1.0], lambda);
    }
    (best.map(|v| (v / l) as f32), lambda)
}

fn dot(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Flips normals so that neighbours along a minimum spanning tree of the
/// kNN graph (rows of `k` in `nbrs`) agree; each part starts at its point
/// farthest from the centroid, facing away from it.
fn orient(points: &[[f32; 3]], normals: &mut [[f32; 3]], nbrs: &[u32], k: usize) {
    let n = points.len();
    // The kNN relation made symmetric: the reverse edges as a CSR list.
    let mut rev_count = vec![0u32; n + 1];
    for &j in nbrs {
        rev_count[j as usize + 1] += 1;
    }
    for i in 0..n {
        rev_count[i + 1] += rev_count[i];
    }
    let mut rev = vec![0u32; nbrs.len()];
    let mut fill = rev_count.clone();
    for (e, &j) in nbrs.iter().enumerate() {
        rev[fill[j as usize] as usize] = (e / k) as u32;
        fill[j as usize] += 1;
    }
    let mut centroid = [0f64; 3];
    for p in points {
        for a in 0..3 {
            centroid[a] += f64::from(p[a]) / n as f64;
        }
    }
    let c = centroid.map(|v| v as f32);
    let mut by_distance: Vec<(f32, u32)> = points
        .iter()
        .enumerate()
        .map(|(i, p)| (-crate::grid::dist2(*p, c), i as u32))
        .collect();
    radsort::sort_by_key(&mut by_distance, |x| x.0);
    let mut done = vec![false; n];
    let mut heap: BinaryHeap<Reverse<(u32, u32, u32)>> = BinaryHeap::new();
    for &(_, seed) in &by_distance {
        let seed = seed as usize;
        if done[seed] {
            continue;
        }
        let out = [0, 1, 2].map(|a| points[seed][a] - c[a]);
        if dot(normals[seed], out) < 0.0 {
            normals[seed] = normals[seed].map(|v| -v);
        }
        done[seed] = true;
        let push = |heap: &mut BinaryHeap<_>, i: usize, done: &[bool], normals: &[[f32; 3]]| {
            let row = nbrs[i * k..(i + 1) * k].iter();
            let back = rev[rev_count[i] as usize..rev_count[i + 1] as usize].iter();
            for &j in row.chain(back) {
                if !done[j as usize] {
                    let w = 1.0 - dot(normals[i], normals[j as usize]).abs();
                    // Non-negative floats order like their bit patterns.
                    heap.push(Reverse((w.max(0.0).to_bits(), j, i as u32)));
                }
            }
        };
        push(&mut heap, seed, &done, normals);
        while let Some(Reverse((_, j, from))) = heap.pop() {
            let j = j as usize;
            if done[j] {
                continue;
            }
            done[j] = true;
            if dot(normals[j], normals[from as usize]) < 0.0 {
                normals[j] = normals[j].map(|v| -v);
            }
            push(&mut heap, j, &done, normals);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::{angle_deg, cube, sphere};

    fn share_within(est: &[[f32; 3]], truth: &[[f32; 3]], deg: f32) -> f64 {
        let ok = est
            .iter()
            .zip(truth)
            .filter(|(e, t)| angle_deg(**e, **t) <= deg)
            .count();
        ok as f64 / est.len() as f64
    }

    #[test]
    fn normals_sphere_outward_within_10_degrees() {
        let (pos, truth) = sphere(20_000, [1.0, -2.0, 0.5], 3.0, 11);
        let est = estimate_normals(&pos, DEFAULT_K);
        let share = share_within(&est, &truth, 10.0);
        assert!(share >= 0.99, "sphere: {share}");
        // Consistently outward: none points inward.
        let inward = est
            .iter()
            .zip(&truth)
            .filter(|(e, t)| dot(**e, **t) < 0.0)
            .count();
        assert_eq!(inward, 0);
    }

    #[test]
    fn normals_cube_outward_within_10_degrees() {
        let (pos, truth) = cube(30_000, 1.0, 5);
        let est = estimate_normals(&pos, DEFAULT_K);
        let share = share_within(&est, &truth, 10.0);
        assert!(share >= 0.99, "cube: {share}");
        let inward = est
            .iter()
            .zip(&truth)
            .filter(|(e, t)| dot(**e, **t) < 0.0)
            .count();
        assert!(inward as f64 <= 0.01 * est.len() as f64, "{inward} inward");
    }

    #[test]
    fn eigenvector_of_a_diagonal_matrix() {
        let (v, l) = smallest_eigenvector([[3.0, 0.0, 0.0], [0.0, 0.5, 0.0], [0.0, 0.0, 2.0]]);
        assert!((v[1].abs() - 1.0).abs() < 1e-6, "{v:?}");
        assert!((l - 0.5).abs() < 1e-9, "{l}");
    }
}
