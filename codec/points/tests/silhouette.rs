//! Clip partners do what they are for: a jittered cube drawn as splats, with
//! and without clipping, against a ray-cast truth of the cube, over 24
//! views at 512² (issue 21's "must show"). Each splat is a disc (centre,
//! normal, radius) intersected with every pixel's ray; a clipped splat drops
//! the hits its partner planes clip, as the viewer's fragment shader does
//! (`web/src/splats/`): union mode clips where any plane does, intersection
//! mode where all do.

use vitrine_points::splat::{preprocess, SplatOptions};
use vitrine_points::testing::cube;
use vitrine_points::testing::raycast::{coverage, inside, truth, View, SIZE};

#[test]
fn clipped_splats_halve_the_silhouette_error_of_a_cube_without_holes() {
    let (pos, nrm) = cube(60_000, 1.0, 5);
    let splats = preprocess(&pos, &nrm, &SplatOptions::default());
    let (mut err_clipped, mut err_plain, mut holes, mut truth_px) =
        (0usize, 0usize, 0usize, 0usize);
    let mut plain_holes = 0usize;
    for view in View::all() {
        let truth = truth(&view);
        let clipped = coverage(&view, &pos, &nrm, &splats, &splats.radii, true);
        let plain = coverage(&view, &pos, &nrm, &splats, &splats.radii, false);
        let inside = |i: usize| inside(&truth, i);
        for i in 0..SIZE * SIZE {
            truth_px += usize::from(truth[i]);
            err_clipped += usize::from(truth[i] != clipped[i]);
            err_plain += usize::from(truth[i] != plain[i]);
            holes += usize::from(!clipped[i] && inside(i));
            plain_holes += usize::from(!plain[i] && inside(i));
        }
    }
    println!(
        "24 views at {SIZE}²: silhouette XOR {err_clipped} px clipped, {err_plain} px unclipped \
         ({:.1} % less), {holes} hole pixels ({plain_holes} unclipped), {truth_px} cube pixels",
        100.0 * (1.0 - err_clipped as f64 / err_plain as f64)
    );
    assert!(
        err_plain > 1000,
        "unclipped splats barely stick out: {err_plain}"
    );
    assert!(
        err_clipped * 2 <= err_plain,
        "clipping removes too little: {err_clipped} against {err_plain}"
    );
    assert_eq!(holes, 0, "pixels of the cube no clipped splat covers");
}
