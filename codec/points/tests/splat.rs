//! Splat preprocessing: the grid graph equals the O(n²) graph exactly, a
//! jittered cube's edge splats get clip partners (and no others do), two
//! intersecting spheres get surface ids that separate them.

use vitrine_points::splat::{
    brute_force_graph, neighbour_graph, preprocess, splat_radii, ClipMode, SplatOptions,
};
use vitrine_points::testing::{cube, next, sphere, unit};

#[test]
fn splat_grid_graph_equals_brute_force() {
    let mut s = 77u64;
    let mut total_edges = 0;
    for (case, n) in [(0, 2500), (1, 3000), (2, 2000), (3, 2500), (4, 2744)] {
        let pts: Vec<[f32; 3]> = (0..n)
            .map(|k| match case {
                // Dense in a volume.
                0 => [unit(&mut s), unit(&mut s), unit(&mut s)],
                // A thin slab (a scan's surface), far from the origin.
                1 => [
                    1e3 + unit(&mut s) * 4.0,
                    -2e3 + unit(&mut s) * 4.0,
                    unit(&mut s) * 0.01,
                ],
                // Two clusters of very different density.
                2 if k % 2 == 0 => [unit(&mut s) * 0.05, unit(&mut s) * 0.05, 0.0],
                2 => [1.0 + unit(&mut s) * 5.0, unit(&mut s) * 5.0, unit(&mut s)],
                // A lattice: distances tie exactly with r_i + r_j, and
                // points sit on the grid's cell boundaries.
                4 => [
                    (k % 14) as f32 * 0.125,
                    (k / 14 % 14) as f32 * 0.125,
                    (k / 196) as f32 * 0.125,
                ],
                // A sparse line with duplicates.
                _ => {
                    let x = (next(&mut s) % 500) as f32 * 0.01;
                    [x, 0.0, 0.0]
                }
            })
            .collect();
        let knn_radii = splat_radii(&pts);
        // Also radii that vary wildly from splat to splat.
        let wild: Vec<f32> = knn_radii
            .iter()
            .map(|r| r * (0.1 + 3.0 * unit(&mut s)))
            .collect();
        for radii in [knn_radii, wild] {
            let grid = neighbour_graph(&pts, &radii);
            let brute = brute_force_graph(&pts, &radii);
            assert!(grid.edge_count() > 0, "case {case}");
            assert_eq!(grid, brute, "case {case}");
            total_edges += grid.edge_count();
        }
    }
    assert!(total_edges > 10_000, "{total_edges}");
}

/// Distance from a point on the cube [−h, h]³'s surface to its nearest edge.
fn edge_distance(p: [f32; 3], h: f32) -> f32 {
    let mut d = [h - p[0].abs(), h - p[1].abs(), h - p[2].abs()];
    d.sort_by(f32::total_cmp);
    // The smallest is ~0 (the face the point lies on); the next is the edge.
    d[1]
}

#[test]
fn splat_cube_edges_get_clip_partners_and_nothing_else_does() {
    let (pos, nrm) = cube(60_000, 1.0, 21);
    let splats = preprocess(&pos, &nrm, &SplatOptions::default());
    let (mut near, mut near_ok, mut far_bad) = (0, 0, 0);
    for (i, &p) in pos.iter().enumerate() {
        let d = edge_distance(p, 1.0);
        let r = splats.radii[i];
        let has = !splats.clipping.partners_of(i).is_empty();
        if d <= 0.5 * r {
            near += 1;
            near_ok += usize::from(has);
        } else if d > 2.0 * r && has {
            far_bad += 1;
        }
    }
    assert!(near > 500, "{near}");
    let share = near_ok as f64 / near as f64;
    assert!(
        share >= 0.95,
        "{near_ok} of {near} edge splats have partners"
    );
    assert_eq!(far_bad, 0, "splats beyond 2 r with partners");
    // The cube is convex everywhere: partners clip as one union of
    // half-spaces that keeps the inside (a point slightly inside the cube,
    // under each splat, is not clipped by any of its planes).
    let c = &splats.clipping;
    for i in (0..pos.len()).filter(|&i| !c.partners_of(i).is_empty()) {
        assert_eq!(c.mode(i), ClipMode::Union, "splat {i}");
        let first = (c.clip[i] >> 6) as usize;
        let count = (c.clip[i] & 15) as usize;
        assert_eq!(count, c.partners_of(i).len());
        let inside = pos[i].map(|v| v * 0.999);
        for k in first..first + count {
            let p = &c.planes[k * 4..k * 4 + 4];
            let s = p[0] * inside[0] + p[1] * inside[1] + p[2] * inside[2] + p[3];
            assert!(s <= 1e-4, "splat {i}: plane {k} clips the inside ({s})");
        }
    }
}

#[test]
fn splat_intersecting_spheres_get_separate_surface_ids() {
    let (mut pos, mut nrm) = sphere(30_000, [-0.5, 0.0, 0.0], 1.0, 1);
    let (p2, n2) = sphere(30_000, [0.5, 0.0, 0.0], 1.0, 2);
    pos.extend(p2);
    nrm.extend(n2);
    let splats = preprocess(&pos, &nrm, &SplatOptions::default());
    let ids = &splats.surface_ids;
    let majority = |range: std::ops::Range<usize>| {
        let mut v: Vec<u32> = ids[range].to_vec();
        v.sort_unstable();
        let mut best = (0, v[0]);
        let mut run = (0, v[0]);
        for &x in &v {
            run = if x == run.1 { (run.0 + 1, x) } else { (1, x) };
            best = best.max(run);
        }
        best
    };
    let (count_a, id_a) = majority(0..30_000);
    let (count_b, id_b) = majority(30_000..60_000);
    assert_ne!(id_a, id_b, "the spheres share a surface id");
    assert!(
        count_a >= 29_700 && count_b >= 29_700,
        "{count_a} {count_b}"
    );
    // No splat of one sphere carries the other's id.
    assert!(ids[..30_000].iter().all(|&x| x != id_b));
    assert!(ids[30_000..].iter().all(|&x| x != id_a));
    // Crossing surfaces are mostly told from creases by the angle-gap test:
    // few splats clip, and only where the spheres cross (within 2 r of the
    // other sphere).
    let clipped: Vec<usize> = (0..pos.len())
        .filter(|&i| !splats.clipping.partners_of(i).is_empty())
        .collect();
    assert!(
        clipped.len() <= pos.len() / 50,
        "{} splats clip",
        clipped.len()
    );
    for &i in &clipped {
        let other = if i < 30_000 { 0.5 } else { -0.5 };
        let p = pos[i];
        let d = (((p[0] - other).powi(2) + p[1] * p[1] + p[2] * p[2]).sqrt() - 1.0).abs();
        assert!(
            d < 2.0 * splats.radii[i],
            "splat {i} clips {d} from the crossing"
        );
    }
}
