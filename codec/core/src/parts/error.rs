//! The geometric error a part removes: how far the vertices it inserts lie
//! from the coarser surface they replace, in quantization steps.
//!
//! A vertex AD01 inserts opens a patch: the triangles it replaces are the
//! faces of the coarser chart around its neighbours that were there before.
//! Its distance to the nearest of those faces is the error the coarse level
//! made there. A part has two errors: the largest over its vertices (the
//! one-sided Hausdorff distance from the finer chart's new vertices to the
//! coarser chart: a bound, what occlusion needs to stay conservative), and
//! the distance its bulk lies within (a quantile: what a viewer refines
//! by). On a scan the largest is set by its noisiest vertex, so a viewer
//! refining by it spends most of its bytes on noise a few vertices show;
//! the bulk follows the surface most of the part moves (issue 41).

/// The share of a part's vertices its bulk error covers.
pub const BULK_SHARE: f64 = 0.9;

/// What a part removes, in quantization steps.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RemovedError {
    /// The largest distance of a vertex it inserts from the coarser chart.
    pub largest: f64,
    /// The distance within which [`BULK_SHARE`] of those vertices lie.
    pub bulk: f64,
}

/// The distances, in quantization steps, from the vertices of `after`
/// numbered `before_vertices` or more to the triangles of `before_faces`
/// near them (those around their neighbours present before): the largest,
/// and the one [`BULK_SHARE`] of them are within.
pub(super) fn removed_error(
    quantized: &[[i32; 3]],
    before_vertices: usize,
    before_faces: &[u32],
    after_faces: &[u32],
) -> RemovedError {
    let mut distances = vertex_distances(quantized, before_vertices, before_faces, after_faces);
    let Some(largest) = distances.iter().copied().max_by(f64::total_cmp) else {
        return RemovedError::default();
    };
    // The nearest rank: the smallest distance at least BULK_SHARE of them
    // are within.
    let rank = ((BULK_SHARE * distances.len() as f64).ceil() as usize).clamp(1, distances.len());
    let (_, bulk, _) = distances.select_nth_unstable_by(rank - 1, f64::total_cmp);
    RemovedError {
        largest,
        bulk: *bulk,
    }
}

/// Each new vertex's distance to the coarser triangles near it (none for a
/// vertex with no coarser face near it).
fn vertex_distances(
    quantized: &[[i32; 3]],
    before_vertices: usize,
    before_faces: &[u32],
    after_faces: &[u32],
) -> Vec<f64> {
    let n = quantized.len();
    if n <= before_vertices {
        return Vec::new();
    }
    let around = faces_around(before_faces, before_vertices);
    // Each new vertex's neighbours, old and new, from the finer triangles.
    let mut neighbours: Vec<(u32, u32)> = Vec::new();
    for t in after_faces.chunks_exact(3) {
        for c in 0..3 {
            let v = t[c];
            if v as usize >= before_vertices {
                neighbours.push((v, t[(c + 1) % 3]));
                neighbours.push((v, t[(c + 2) % 3]));
            }
        }
    }
    neighbours.sort_unstable();
    neighbours.dedup();
    let ring = |v: u32| {
        let from = neighbours.partition_point(|&(a, _)| a < v);
        neighbours[from..]
            .iter()
            .take_while(move |&&(a, _)| a == v)
            .map(|&(_, b)| b)
    };
    let point = |v: u32| quantized[v as usize].map(f64::from);
    let mut distances = Vec::with_capacity(n - before_vertices);
    let mut candidates: Vec<u32> = Vec::new();
    for v in before_vertices as u32..n as u32 {
        candidates.clear();
        // Old neighbours, else (a vertex of the decimating pass ringed by
        // the cleaning pass's) the old neighbours of its new ones.
        let mut olds: Vec<u32> = ring(v)
            .filter(|&w| (w as usize) < before_vertices)
            .collect();
        if olds.is_empty() {
            olds = ring(v)
                .flat_map(ring)
                .filter(|&w| (w as usize) < before_vertices)
                .collect();
        }
        for w in olds {
            candidates.extend_from_slice(around.of(w));
        }
        candidates.sort_unstable();
        candidates.dedup();
        let p = point(v);
        let nearest = candidates
            .iter()
            .map(|&f| {
                let t = &before_faces[3 * f as usize..3 * f as usize + 3];
                point_triangle_distance(p, [point(t[0]), point(t[1]), point(t[2])])
            })
            .fold(f64::INFINITY, f64::min);
        if nearest.is_finite() {
            distances.push(nearest);
        }
    }
    distances
}

/// The faces around each vertex, in compressed rows.
struct FacesAround {
    start: Vec<u32>,
    faces: Vec<u32>,
}

impl FacesAround {
    fn of(&self, v: u32) -> &[u32] {
        let v = v as usize;
        &self.faces[self.start[v] as usize..self.start[v + 1] as usize]
    }
}

fn faces_around(faces: &[u32], vertices: usize) -> FacesAround {
    let mut start = vec![0u32; vertices + 1];
    for &v in faces {
        start[v as usize + 1] += 1;
    }
    for i in 0..vertices {
        start[i + 1] += start[i];
    }
    let mut fill = start.clone();
    let mut out = vec![0u32; faces.len()];
    for (i, &v) in faces.iter().enumerate() {
        out[fill[v as usize] as usize] = (i / 3) as u32;
        fill[v as usize] += 1;
    }
    FacesAround { start, faces: out }
}

/// Distance from `p` to the triangle `t` (its closest point found by the
/// region of the triangle's plane `p` projects into: Ericson, *Real-Time
/// Collision Detection*, §5.1.5). Written here because the codec's core
/// depends on no geometry library (it builds for wasm32 with none).
pub(super) fn point_triangle_distance(p: [f64; 3], t: [[f64; 3]; 3]) -> f64 {
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let along =
        |a: [f64; 3], d: [f64; 3], s: f64| [a[0] + d[0] * s, a[1] + d[1] * s, a[2] + d[2] * s];
    let [a, b, c] = t;
    let (ab, ac, ap) = (sub(b, a), sub(c, a), sub(p, a));
    let (d1, d2) = (dot(ab, ap), dot(ac, ap));
    let closest = if d1 <= 0.0 && d2 <= 0.0 {
        a
    } else {
        let bp = sub(p, b);
        let (d3, d4) = (dot(ab, bp), dot(ac, bp));
        let cp = sub(p, c);
        let (d5, d6) = (dot(ab, cp), dot(ac, cp));
        let vc = d1 * d4 - d3 * d2;
        let vb = d5 * d2 - d1 * d6;
        let va = d3 * d6 - d5 * d4;
        if d3 >= 0.0 && d4 <= d3 {
            b
        } else if d6 >= 0.0 && d5 <= d6 {
            c
        } else if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
            along(a, ab, d1 / (d1 - d3))
        } else if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
            along(a, ac, d2 / (d2 - d6))
        } else if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
            along(b, sub(c, b), (d4 - d3) / ((d4 - d3) + (d5 - d6)))
        } else {
            let denom = va + vb + vc;
            if denom.abs() < f64::MIN_POSITIVE {
                // A degenerate triangle: its nearest corner.
                return [a, b, c]
                    .iter()
                    .map(|&q| dot(sub(p, q), sub(p, q)).sqrt())
                    .fold(f64::INFINITY, f64::min);
            }
            let (v, w) = (vb / denom, vc / denom);
            along(along(a, ab, v), ac, w)
        }
    };
    let d = sub(p, closest);
    dot(d, d).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn distance_to_a_triangle_by_region() {
        let t = [[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [0.0, 4.0, 0.0]];
        // Above the interior: the height.
        assert_eq!(point_triangle_distance([1.0, 1.0, 3.0], t), 3.0);
        // Beyond a corner.
        assert_eq!(point_triangle_distance([-3.0, -4.0, 0.0], t), 5.0);
        // Beside the hypotenuse, in the plane.
        let d = point_triangle_distance([3.0, 3.0, 0.0], t);
        assert!((d - 2.0_f64.sqrt()).abs() < 1e-12, "{d}");
        // Below an edge, out of the plane.
        assert_eq!(point_triangle_distance([2.0, -3.0, 4.0], t), 5.0);
    }

    #[test]
    fn a_vertex_raised_from_a_flat_patch_removes_its_height() {
        // A square of two triangles; a vertex inserted at its centre, 7 up.
        let q = [[0, 0, 0], [10, 0, 0], [10, 10, 0], [0, 10, 0], [5, 5, 7]];
        let before = [0, 1, 2, 0, 2, 3];
        let after = [0, 1, 4, 1, 2, 4, 2, 3, 4, 3, 0, 4];
        let one = RemovedError {
            largest: 7.0,
            bulk: 7.0,
        };
        assert_eq!(removed_error(&q, 4, &before, &after), one);
        assert_eq!(
            removed_error(&q[..4], 4, &before, &before),
            RemovedError::default()
        );
    }

    #[test]
    fn the_bulk_leaves_out_the_farthest_tenth() {
        // Twenty vertices raised from a flat strip, heights 1..=20: the
        // largest is 20, and 18 of the 20 (90 %) lie within 18.
        let mut q: Vec<[i32; 3]> = Vec::new();
        let mut before = Vec::new();
        let mut after = Vec::new();
        for k in 0..20 {
            let x = 10 * k;
            let base = q.len() as u32;
            q.extend([[x, 0, 0], [x + 10, 0, 0], [x + 10, 10, 0], [x, 10, 0]]);
            before.extend([base, base + 1, base + 2, base, base + 2, base + 3]);
        }
        let old = q.len();
        for k in 0..20u32 {
            let c = q.len() as u32;
            q.push([10 * k as i32 + 5, 5, k as i32 + 1]);
            let b = 4 * k;
            after.extend([b, b + 1, c, b + 1, b + 2, c, b + 2, b + 3, c, b + 3, b, c]);
        }
        let e = removed_error(&q, old, &before, &after);
        assert_eq!(e.largest, 20.0);
        assert_eq!(e.bulk, 18.0);
    }
}
