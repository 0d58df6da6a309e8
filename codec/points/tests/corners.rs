//! Clip partners near corners (seed 002, §7.2): where a splat's partners lie
//! on a convex edge and a concave crease at once (the inner corners of an
//! L-shaped block), grouping them by surface id drops the splat from
//! clipping instead of cutting away its visible half; where every group
//! agrees (a cube's corners) the splat keeps its planes. Also the
//! concave mode (the L-block's crease) and the intersection mode (its top
//! face's reflex corner), which no other test reaches.

use vitrine_points::splat::{preprocess, ClipMode, SplatOptions, Splats, PLANE_FLOATS};
use vitrine_points::testing::{cube, faces_sample, l_block_faces, Rect, L_BLOCK_HALF_HEIGHT};

/// The viewer draws a point's disc at this multiple of its radius
/// (`POINT_RADIUS_SCALE`, web/src/splats/point-stream.js).
const DRAWN_RADIUS_SCALE: f32 = 1.5;

fn dot(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn dist(a: [f32; 3], b: [f32; 3]) -> f32 {
    let d = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    dot(d, d).sqrt()
}

/// Whether splat i's clip planes cut `p` away, as the fragment shader
/// decides (web/src/splats/shaders.js).
fn clipped(splats: &Splats, i: usize, p: [f32; 3]) -> bool {
    let c = &splats.clipping;
    let (first, count) = ((c.clip[i] >> 6) as usize, (c.clip[i] & 15) as usize);
    let cuts = |k: usize| {
        let q = &c.planes[k * PLANE_FLOATS..(k + 1) * PLANE_FLOATS];
        q[0] * p[0] + q[1] * p[1] + q[2] * p[2] + q[3] > 0.0
    };
    match c.mode(i) {
        ClipMode::Union => (first..first + count).any(cuts),
        ClipMode::Intersection => (first..first + count).all(cuts),
        ClipMode::None => false,
    }
}

/// Whether some splat in `near` lies in the plane of surface point `q`
/// (normal `n`), reaches it, and (with `clip`) is not clipped there.
fn covered(
    q: [f32; 3],
    n: [f32; 3],
    near: &[usize],
    pos: &[[f32; 3]],
    nrm: &[[f32; 3]],
    splats: &Splats,
    clip: bool,
) -> bool {
    near.iter().any(|&i| {
        let off = [q[0] - pos[i][0], q[1] - pos[i][1], q[2] - pos[i][2]];
        dot(nrm[i], n) > 0.999
            && dot(off, nrm[i]).abs() < 1e-5
            && dist(q, pos[i]) < DRAWN_RADIUS_SCALE * splats.radii[i]
            && !(clip && clipped(splats, i, q))
    })
}

#[test]
fn splat_inner_corners_of_an_l_block_keep_every_surface_point_covered() {
    let faces: Vec<Rect> = l_block_faces();
    let (pos, nrm) = faces_sample(&faces, 40_000, 7);
    let splats = preprocess(&pos, &nrm, &SplatOptions::default());
    let h = L_BLOCK_HALF_HEIGHT;
    let corners = [[0.0, 0.0, h], [0.0, 0.0, -h]];
    let to_corner = |p: [f32; 3]| corners.iter().map(|&c| dist(p, c)).fold(f32::MAX, f32::min);
    let r_max = splats.radii.iter().copied().fold(0.0, f32::max);
    let reach = 4.0 * r_max;
    // Points of the true surface around both inner corners.
    let (qs, qn) = faces_sample(&faces, 2_000_000, 8);
    let near: Vec<usize> = (0..pos.len())
        .filter(|&i| to_corner(pos[i]) < reach + DRAWN_RADIUS_SCALE * r_max)
        .collect();
    let (mut checked, mut uncovered, mut gaps) = (0, 0, 0);
    for (&q, &n) in qs.iter().zip(&qn) {
        if to_corner(q) < reach {
            checked += 1;
            // A gap of the random sample (no disc reaches the point) is not
            // clipping's doing; a point only clipping leaves bare is.
            if covered(q, n, &near, &pos, &nrm, &splats, false) {
                uncovered += usize::from(!covered(q, n, &near, &pos, &nrm, &splats, true));
            } else {
                gaps += 1;
            }
        }
    }
    let mixed: Vec<usize> = (0..pos.len())
        .filter(|&i| {
            !splats.clipping.partners_of(i).is_empty() && splats.clipping.mode(i) == ClipMode::None
        })
        .collect();
    let farthest = mixed
        .iter()
        .map(|&i| to_corner(pos[i]) / splats.radii[i])
        .fold(0.0, f32::max);
    println!(
        "L-block, 40,000 splats: {} dropped from clipping at mixed corners (farthest {farthest:.2} r from an \
         inner corner); {uncovered} of {checked} surface points within {reach:.3} of an inner corner left bare by clipping \
         ({gaps} in gaps of the sample)",
        splats.clipping.mixed_corners
    );
    assert!(checked > 10_000, "{checked}");
    assert_eq!(
        uncovered, 0,
        "surface points near the inner corners clipping leaves bare"
    );
    assert_eq!(splats.clipping.mixed_corners, mixed.len());
    assert!(
        !mixed.is_empty(),
        "no splat near an inner corner has mixed partners"
    );
    // Only splats at the inner corners mix a concave group with a convex one:
    // within reach of both the crease and an edge, so of the corner.
    assert!(
        farthest < 4.0,
        "a splat {farthest} r from the inner corners was dropped"
    );
}

#[test]
fn splat_cube_corners_keep_their_planes() {
    let (pos, nrm) = cube(40_000, 1.0, 9);
    let splats = preprocess(&pos, &nrm, &SplatOptions::default());
    let ids = &splats.surface_ids;
    // Splats whose partners lie on two other faces: at a corner.
    let at_corner: Vec<usize> = (0..pos.len())
        .filter(|&i| {
            let p = splats.clipping.partners_of(i);
            p.iter().any(|&j| ids[j as usize] != ids[p[0] as usize])
        })
        .collect();
    println!(
        "cube, 40,000 splats: {} with partners on two faces",
        at_corner.len()
    );
    assert!(at_corner.len() >= 8, "{}", at_corner.len());
    assert_eq!(
        splats.clipping.mixed_corners, 0,
        "a convex corner's groups agree"
    );
    let mut outside = 0;
    for &i in &at_corner {
        assert_eq!(splats.clipping.mode(i), ClipMode::Union, "splat {i}");
        // The drawn disc's point a radius towards the corner along both of
        // its plane's axes, where it lies outside the cube, is cut.
        let r = splats.radii[i];
        let out: [f32; 3] =
            [0, 1, 2].map(|k| pos[i][k] + (1.0 - nrm[i][k].abs()) * r * pos[i][k].signum());
        if out.iter().any(|v| v.abs() > 1.0) {
            outside += 1;
            assert!(
                clipped(&splats, i, out),
                "splat {i} at {:?} keeps {out:?}",
                pos[i]
            );
        }
    }
    assert!(
        outside * 2 >= at_corner.len(),
        "{outside} of {}",
        at_corner.len()
    );
}

#[test]
fn splat_l_block_crease_is_concave_and_the_reflex_corner_an_intersection() {
    let (pos, nrm) = faces_sample(&l_block_faces(), 40_000, 7);
    let splats = preprocess(&pos, &nrm, &SplatOptions::default());
    let c = &splats.clipping;
    // Splats on the crease's two faces (x = 0 for y > 0, y = 0 for x > 0),
    // away from the inner corners, with partners: their planes cut what
    // pokes into the solid behind the other face, and keep their own face.
    let (mut crease, mut concave_ok) = (0, 0);
    for i in 0..pos.len() {
        let (p, n, r) = (pos[i], nrm[i], splats.radii[i]);
        // Within reach of the crease, not of the far edges of these faces.
        let on_x0 = n[0] == 1.0 && p[0] == 0.0 && p[1] < 0.5;
        let on_y0 = n[1] == 1.0 && p[1] == 0.0 && p[0] < 0.5;
        if !(on_x0 || on_y0) || p[2].abs() > 0.3 || c.partners_of(i).is_empty() {
            continue;
        }
        crease += 1;
        // Along the face towards the crease, past it (inside the solid), and
        // away from it (the face itself).
        let (inside, face) = if on_x0 {
            ([0.0, -0.5 * r, p[2]], [0.0, p[1] + 0.5 * r, p[2]])
        } else {
            ([-0.5 * r, 0.0, p[2]], [p[0] + 0.5 * r, 0.0, p[2]])
        };
        concave_ok += usize::from(clipped(&splats, i, inside) && !clipped(&splats, i, face));
    }
    // The top face's splats at the reflex corner of its L (the top inner
    // corner), with partners on both crease faces (both convex to it):
    // clipped only where both planes cut (the notch), so the L's own top
    // stays. The corner split leaves them to the joint classification.
    let ids = &splats.surface_ids;
    let reflex: Vec<usize> = (0..pos.len())
        .filter(|&i| {
            let p = c.partners_of(i);
            let near_corner = dist(pos[i], [0.0, 0.0, L_BLOCK_HALF_HEIGHT]) < 3.0 * splats.radii[i];
            near_corner
                && nrm[i][2] == 1.0
                && p.iter().any(|&j| ids[j as usize] != ids[p[0] as usize])
        })
        .collect();
    let intersections = reflex
        .iter()
        .filter(|&&i| c.mode(i) == ClipMode::Intersection)
        .count();
    println!(
        "L-block crease: {concave_ok} of {crease} splats cut inside the solid and keep their face; \
         {intersections} of {} top splats with partners on both crease faces clip by intersection",
        reflex.len()
    );
    assert!(crease > 20, "{crease}");
    assert_eq!(concave_ok, crease, "crease splats clipped as convex");
    assert!(!reflex.is_empty());
    assert_eq!(
        intersections,
        reflex.len(),
        "the top's reflex corner clipped by union"
    );
}
